#include "preprocess/FiniteBounds.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

namespace flipscope {
namespace {

/// finiteBounds() of a range whose positions are all finite or not: four positions (twelve
/// floats, three vectors) at a time, each lane keeping the min and max of the coordinate it sees;
/// a group of four with a NaN or Inf goes one position at a time. The min and max of floats are
/// floats: nothing is rounded.
FiniteBounds rangeBounds(const glm::vec3* p, std::size_t n) {
  using Lanes = float __attribute__((vector_size(16)));
  using LaneBits = std::uint32_t __attribute__((vector_size(16)));
  constexpr float kInf = std::numeric_limits<float>::infinity();
  const Lanes inf = {kInf, kInf, kInf, kInf};
  Lanes lo[3] = {inf, inf, inf}, hi[3] = {-inf, -inf, -inf};
  float scalarLo[3] = {kInf, kInf, kInf}, scalarHi[3] = {-kInf, -kInf, -kInf};
  std::uint64_t finite = 0;
  const auto one = [&](const glm::vec3& q) {
    if (!(std::abs(q.x) < kInf && std::abs(q.y) < kInf && std::abs(q.z) < kInf)) return;
    ++finite;
    for (int a = 0; a < 3; ++a) scalarLo[a] = std::min(scalarLo[a], q[a]), scalarHi[a] = std::max(scalarHi[a], q[a]);
  };
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    Lanes v[3];
    std::memcpy(v, &p[i], sizeof v);
    bool allFinite = true;
    for (int k = 0; k < 3; ++k) {
      const Lanes magnitude = (Lanes)((LaneBits)v[k] & 0x7fffffffu);
      const auto below = magnitude < inf;
      allFinite = allFinite && below[0] && below[1] && below[2] && below[3];
    }
    if (!allFinite) {
      for (std::size_t j = i; j < i + 4; ++j) one(p[j]);
      continue;
    }
    finite += 4;
    for (int k = 0; k < 3; ++k) {
      lo[k] = v[k] < lo[k] ? v[k] : lo[k];
      hi[k] = v[k] > hi[k] ? v[k] : hi[k];
    }
  }
  for (; i < n; ++i) one(p[i]);
  // Lane l of vector k holds coordinate (4 k + l) % 3.
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 4; ++l) {
      const int a = (4 * k + l) % 3;
      scalarLo[a] = std::min(scalarLo[a], lo[k][l]);
      scalarHi[a] = std::max(scalarHi[a], hi[k][l]);
    }
  FiniteBounds t;
  t.finite = finite;
  if (finite)
    t.bounds =
        Box{glm::dvec3(scalarLo[0], scalarLo[1], scalarLo[2]), glm::dvec3(scalarHi[0], scalarHi[1], scalarHi[2])};
  return t;
}

}  // namespace

FiniteBounds finiteBounds(std::span<const glm::vec3> positions) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, positions.size(), 1 << 14), FiniteBounds{},
      [&](const auto& range, FiniteBounds t) {
        const FiniteBounds r = rangeBounds(positions.data() + range.begin(), range.size());
        t.finite += r.finite;
        t.bounds.extend(r.bounds);
        return t;
      },
      [](FiniteBounds a, const FiniteBounds& b) {
        a.finite += b.finite;
        a.bounds.extend(b.bounds);
        return a;
      });
}

}  // namespace flipscope
