// Lets one source file compile as C++ and as GLSL (the PNanoVDB way): code in core/glsl/,
// streaming/glsl/ and raycast/glsl/ that both sides need is written in the common subset of
// GLSL 4.50 and C++20, with GLM standing in for GLSL's vector types on the C++ side.
//
// Rules for shared .glsl files:
//  - functions are declared `FS_FUNC uint f(uint x)`; FS_FUNC is `inline` in C++, empty in GLSL;
//  - only uint/int/float/bool and GLM/GLSL vector types; unsigned literals carry a `u`;
//  - no GLSL-only built-ins except those mirrored below (bitCount, ...);
//  - C++ includes them inside `namespace flipscope::glsl` through this header.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#define FS_FUNC inline

namespace flipscope::glsl {
using uint = std::uint32_t;
using glm::abs;
using glm::clamp;
using glm::dot;
using glm::floor;
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
using std::floor;
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

inline int bitCount(uint v) { return std::popcount(v); }
inline int findLSB(uint v) { return v == 0 ? -1 : std::countr_zero(v); }
inline int findMSB(uint v) { return v == 0 ? -1 : 31 - std::countl_zero(v); }
inline float uintBitsToFloat(uint v) { return std::bit_cast<float>(v); }
inline uint floatBitsToUint(float v) { return std::bit_cast<uint>(v); }
}  // namespace flipscope::glsl
