// NearSphereMask: per cell of a brick, whether a sphere cell lies within `reach` cells of it
// (Chebyshev distance): the neighbourhood the brick march of §3.3.1 tests for spheres. The fast
// CPU device (TiledCpuRaycaster) keeps one per resident brick and skips the slab tests of a cell
// with no sphere near; the result is the same, since every cell of such a slab is empty.
#pragma once

#include <cstddef>
#include <cstdint>

#include <glm/vec4.hpp>

namespace flipscope {

/// 64-bit words of one brick's mask: per (y, z), z-major, a row of brickSize bits (x in the
/// lowest bit of the first word), rounded up to whole words.
std::size_t nearSphereMaskWords(std::uint32_t brickSize);

/// Fills `mask` (nearSphereMaskWords words) for the brick-local cells [0, brickSize)^3 from the
/// slot's sub-bricks `bits` (bitBrickSubBrickDims(brickSize, overlap) of them, the border
/// included), leaving out the cells set in `foam` (as many sub-bricks) when it is not null.
/// Needs reach <= overlap <= kMaxOverlap and brickSize <= 128.
void buildNearSphereMask(const glm::uvec4* bits, const glm::uvec4* foam, std::uint32_t brickSize,
                         std::uint32_t overlap, std::uint32_t reach, std::uint64_t* mask);

}  // namespace flipscope
