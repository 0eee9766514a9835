// ClearDistance: the Chebyshev distance transform of a grid of blocks (see the header).
#include "raycast/ClearDistance.h"

#include <algorithm>
#include <vector>

#include <glm/common.hpp>

namespace flipscope {

void buildClearDistances(const std::uint32_t* setBlocks, glm::uvec3 dims, std::uint8_t* distances) {
  const int nx = int(dims.x), ny = int(dims.y), nz = int(dims.z);
  const int cap = kMaxClearDistance;
  auto at = [&](int x, int y, int z) { return std::size_t(x) + std::size_t(nx) * (std::size_t(y) + std::size_t(ny) * z); };
  // The Chebyshev distance is separable: d(b) = min over a set q of max_a |b_a - q_a|. First the
  // distance along x within each row (two scans), then along y over those, then along z.
  std::vector<std::uint8_t> alongX(std::size_t(nx) * ny * nz), alongXY(alongX.size());
  for (int z = 0; z < nz; z++)
    for (int y = 0; y < ny; y++) {
      int d = cap;
      for (int x = 0; x < nx; x++) {
        const std::size_t i = at(x, y, z);
        d = ((setBlocks[i >> 5] >> (i & 31)) & 1u) != 0u ? 0 : std::min(d + 1, cap);
        alongX[i] = std::uint8_t(d);
      }
      d = cap;
      for (int x = nx - 1; x >= 0; x--) {
        const std::size_t i = at(x, y, z);
        d = std::min<int>(std::min(d + 1, cap), alongX[i]);
        alongX[i] = std::uint8_t(d);
      }
    }
  // One more axis (1: y, 2: z): out[b] = min over offsets j of max(|j|, in[b + j along it]).
  auto combine = [&](const std::uint8_t* in, std::uint8_t* out, int axis) {
    const int n = axis == 1 ? ny : nz;
    const std::size_t stride = axis == 1 ? std::size_t(nx) : std::size_t(nx) * ny;
    for (int z = 0; z < nz; z++)
      for (int y = 0; y < ny; y++)
        for (int x = 0; x < nx; x++) {
          const std::size_t i = at(x, y, z);
          const int c = axis == 1 ? y : z;
          int d = in[i];
          for (int j = 1; j < d; j++) {
            if (c - j >= 0) d = std::min(d, std::max<int>(j, in[i - j * stride]));
            if (c + j < n) d = std::min(d, std::max<int>(j, in[i + j * stride]));
          }
          out[i] = std::uint8_t(d);
        }
  };
  combine(alongX.data(), alongXY.data(), 1);
  combine(alongXY.data(), distances, 2);
}

SetBlockBounds setBlockBounds(const std::uint32_t* setBlocks, glm::uvec3 dims) {
  SetBlockBounds bounds;
  bounds.lo = glm::ivec3(dims);
  bounds.hi = glm::ivec3(0);
  std::size_t i = 0;
  for (int z = 0; z < int(dims.z); z++)
    for (int y = 0; y < int(dims.y); y++)
      for (int x = 0; x < int(dims.x); x++, i++) {
        if (((setBlocks[i >> 5] >> (i & 31)) & 1u) == 0u) continue;
        bounds.lo = glm::min(bounds.lo, glm::ivec3(x, y, z));
        bounds.hi = glm::max(bounds.hi, glm::ivec3(x, y, z) + 1);
      }
  if (bounds.hi.x == 0) return SetBlockBounds{};
  return bounds;
}

}  // namespace flipscope
