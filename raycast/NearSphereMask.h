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

/// Cells per edge of a near-sphere group: the mask's cells in cubes of 4^3.
inline constexpr std::uint32_t kNearGroupCells = 4;

/// Groups of one brick, (brickSize / 4)^3.
std::size_t nearSphereGroupCount(std::uint32_t brickSize);

/// Per group of 4^3 cells of a brick's `mask`, whether any of its cells is set: bit i of
/// `groups` (nearSphereGroupCount / 32 words, rounded up), i = gx + G * (gy + G * gz) for
/// G = brickSize / 4. Needs brickSize a multiple of 4.
void nearSphereGroups(const std::uint64_t* mask, std::uint32_t brickSize, std::uint32_t* groups);

}  // namespace flipscope
