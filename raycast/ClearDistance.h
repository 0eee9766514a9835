// ClearDistance: per level-1 mip block of a brick (a 4x4x8 sub-brick, §4.2), how far the
// nearest set block lies, in blocks (Chebyshev distance; 0 for a set block). A block's mip bit
// is set when a stored cell lies within the mip dilation of it (buildBrickMipmap), so distance
// d >= 1 says that the cube of blocks within d - 1 of this one holds no stored cell within the
// dilation: a ray may cross that whole cube without a sphere test. The fast CPU device
// (TiledCpuRaycaster) keeps one per resident brick and skips such cubes, centred on the ray's
// block, instead of walking up the mip levels to an aligned clear block.
#pragma once

#include <cstdint>

#include <glm/vec3.hpp>

namespace flipscope {

/// Largest distance kept; farther set blocks (or none) read as this.
inline constexpr std::uint8_t kMaxClearDistance = 15;

/// Fills `distances` (dims.x * dims.y * dims.z bytes, x fastest) from the level-1 mip bits
/// `level1` of one brick (bit x + dims.x * (y + dims.y * z), as bitBrickMipBitIndex). Blocks
/// outside the brick count as clear: the march ends at the brick's face anyway.
void buildClearDistances(const std::uint32_t* level1, glm::uvec3 dims, std::uint8_t* distances);

}  // namespace flipscope
