// Occupancy mipmaps of a bit-brick for empty-space skipping (Reichl et al. 2014 §4.2). CPU
// reference for the GPU pass to come; the level layout is defined in streaming/glsl/BitBrick.glsl
// (level 1: one bit per 4x4x8 sub-brick, each further level halves the dims, rounding up).
#pragma once

#include <cstdint>
#include <vector>

#include "streaming/BitBrick.h"

namespace flipscope {

/// Largest dilation buildBrickMipmap() accepts, in cells.
inline constexpr std::uint32_t kMaxMipDilation = 8;

/// All mip levels of `brick`, concatenated as bitBrickMipWordOffset() describes (the result has
/// bitBrickMipWordOffset(levelCount + 1, ...) words). A block's bit is set when a set stored
/// cell lies within `dilation` cells of the block along every axis (Chebyshev distance), so a
/// ray crossing a clear block meets no sphere of radius + jitter <= dilation centred in this
/// brick's stored cells. dilation <= kMaxMipDilation (FLIPSCOPE_CHECK).
std::vector<std::uint32_t> buildBrickMipmap(const BitBrick& brick, std::uint32_t dilation);

}  // namespace flipscope
