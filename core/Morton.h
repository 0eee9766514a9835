// C++ side of core/glsl/Morton.glsl (10 bits per axis, 30-bit codes).
#pragma once

#include "core/GlslShared.h"

namespace flipscope::glsl {
#include "core/glsl/Morton.glsl"
}  // namespace flipscope::glsl

namespace flipscope {
using glsl::mortonDecode3;
using glsl::mortonEncode3;
/// Largest coordinate a 30-bit Morton code holds, per axis.
inline constexpr std::uint32_t kMortonAxisLimit = 1024;
}  // namespace flipscope
