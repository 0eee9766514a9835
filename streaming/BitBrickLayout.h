// C++ side of streaming/glsl/BitBrick.glsl: sub-brick addressing, attribute offsets and the
// mip level layout of bit-bricks (Reichl et al. 2014 §3.1, §3.2, §4.2).
#pragma once

#include "core/GlslShared.h"

namespace flipscope::glsl {
#include "streaming/glsl/BitBrick.glsl"
}  // namespace flipscope::glsl

namespace flipscope {
using glsl::bitBrickAttributeOffset;
using glsl::bitBrickBitIndex;
using glsl::bitBrickBitSet;
using glsl::bitBrickHalfCount;
using glsl::bitBrickMipBitIndex;
using glsl::bitBrickMipDims;
using glsl::bitBrickMipLevelCount;
using glsl::bitBrickMipLevelWords;
using glsl::bitBrickMipWordOffset;
using glsl::bitBrickSubBrickDims;
using glsl::bitBrickSubBrickCoord;
using glsl::bitBrickSubBrickIndex;
using glsl::bitBrickSubBrickLinear;

/// Cells per sub-brick axis and bits per sub-brick.
inline constexpr glm::uvec3 kSubBrickCells{4, 4, 8};
inline constexpr std::uint32_t kSubBrickBits = 128;
/// Largest overlap border a bit-brick stores, in cells.
inline constexpr std::uint32_t kMaxOverlap = 8;
}  // namespace flipscope
