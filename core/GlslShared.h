// Lets one source file compile as C++ and as GLSL (the PNanoVDB way): code in core/glsl/,
// streaming/glsl/ and raycast/glsl/ that both sides need is written in the common subset of
// GLSL 4.50 and C++20, with GLM standing in for GLSL's vector types on the C++ side.
//
// Rules for shared .glsl files:
//  - functions are declared `FS_FUNC uint f(uint x)`; FS_FUNC is `inline` in C++, empty in GLSL;
//  - a parameter the function updates in place is `FS_INOUT(T) name`: `inout T` in GLSL, `T&` in
//    C++ (GLSL copies it in and out, C++ updates the caller's; the same when nothing else aliases it);
//  - only uint/int/float/bool and GLM/GLSL vector types; unsigned literals carry a `u`;
//  - no GLSL-only built-ins except those mirrored below (bitCount, ...);
//  - C++ includes them inside `namespace flipscope::glsl` through this header.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "core/FastFloor.h"

#define FS_FUNC inline
#define FS_INOUT(T) T&

namespace flipscope::glsl {
using uint = std::uint32_t;
using glm::abs;
using glm::clamp;
using glm::dot;
using glm::ivec2;
using glm::ivec3;
using glm::ivec4;
using glm::max;
using glm::min;
using glm::normalize;
using glm::uvec2;
using glm::uvec3;
using glm::uvec4;
using glm::vec2;
using glm::vec3;
using glm::vec4;
using std::abs;
using std::sqrt;
using glm::cross;
using glm::exp;
using glm::mix;
using glm::pow;
using glm::reflect;
using glm::sign;
using glm::acos;
using glm::atan;
using std::exp;
using std::pow;

/// GLSL's floor, exact and inline (core/FastFloor.h): the ray-casters floor every sample.
inline float floor(float v) { return fastFloor(v); }
inline vec2 floor(vec2 v) { return vec2(floor(v.x), floor(v.y)); }
inline vec3 floor(vec3 v) { return vec3(floor(v.x), floor(v.y), floor(v.z)); }
inline vec4 floor(vec4 v) { return vec4(floor(v.x), floor(v.y), floor(v.z), floor(v.w)); }

/// GLSL's bitCount. Without the POPCNT instruction (x86-64's baseline; the default build has it,
/// CMakeLists.txt) std::popcount is a call into libgcc; the same bit trick inline is about twice
/// as fast.
inline int bitCount(uint v) {
#if defined(__POPCNT__) || !defined(__x86_64__)
  return std::popcount(v);
#else
  v = v - ((v >> 1u) & 0x55555555u);
  v = (v & 0x33333333u) + ((v >> 2u) & 0x33333333u);
  return int((((v + (v >> 4u)) & 0x0f0f0f0fu) * 0x01010101u) >> 24u);
#endif
}
inline int findLSB(uint v) { return v == 0 ? -1 : std::countr_zero(v); }
inline int findMSB(uint v) { return v == 0 ? -1 : 31 - std::countl_zero(v); }
inline float uintBitsToFloat(uint v) { return std::bit_cast<float>(v); }
inline uint floatBitsToUint(float v) { return std::bit_cast<uint>(v); }
}  // namespace flipscope::glsl
