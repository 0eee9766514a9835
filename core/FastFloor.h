// fastFloor: std::floor, exact, without a call. Built for x86-64-v2 (the default: CMakeLists.txt)
// std::floor is one SSE4.1 rounding instruction; x86-64's baseline has none, and std::floor is a
// call into libm there. The binning floors every particle, the ray-casters (core/GlslShared.h)
// every sample.
#pragma once

#include <cmath>
#include <cstdint>

#include <glm/vec3.hpp>

namespace flipscope {

/// std::floor(v) for every float and double, but that -0 may give +0 (equal as numbers): beyond
/// 2^23 (2^52) a float (double) is an integer already; NaN and infinities come back as they are.
inline float fastFloor(float v) {
#ifdef __SSE4_1__
  return std::floor(v);
#else
  if (!(std::abs(v) < 8388608.0f)) return v;
  const float truncated = float(std::int32_t(v));
  return truncated > v ? truncated - 1.0f : truncated;
#endif
}
inline double fastFloor(double v) {
#ifdef __SSE4_1__
  return std::floor(v);
#else
  if (!(std::abs(v) < 4503599627370496.0)) return v;
  const double truncated = double(std::int64_t(v));
  return truncated > v ? truncated - 1.0 : truncated;
#endif
}
inline glm::dvec3 fastFloor(const glm::dvec3& v) { return {fastFloor(v.x), fastFloor(v.y), fastFloor(v.z)}; }

}  // namespace flipscope
