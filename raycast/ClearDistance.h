// ClearDistance: per block of a grid of blocks, how far the nearest set block lies, in blocks
// (Chebyshev distance; 0 for a set block). Distance d >= 1 says that the cube of blocks within
// d - 1 of this one holds no set block, so a ray may cross that whole cube at once. The fast CPU
// device (TiledCpuRaycaster) keeps two per resident brick, and skips such cubes centred on the
// ray's block instead of walking up the mip levels to an aligned clear block (§4.2):
//  - of its level-1 mip blocks (4x4x8 stored cells): a block's bit is set when a stored cell lies
//    within the mip dilation, the reach, of it (buildBrickMipmap);
//  - of its groups of 4^3 cells (nearSphereGroups): set when a cell of the group has a sphere
//    within the reach (NearSphereMask). Finer, but blind to the foam cells the mask leaves out.
#pragma once

#include <cstdint>

#include <glm/vec3.hpp>

namespace flipscope {

/// Largest distance kept; farther set blocks (or none) read as this.
inline constexpr std::uint8_t kMaxClearDistance = 15;

/// Fills `distances` (dims.x * dims.y * dims.z bytes, x fastest) from the bits `setBlocks` of the
/// grid's set blocks (bit x + dims.x * (y + dims.y * z), as bitBrickMipBitIndex). Blocks outside
/// the grid count as clear: the march ends at the brick's face anyway.
void buildClearDistances(const std::uint32_t* setBlocks, glm::uvec3 dims, std::uint8_t* distances);

/// The blocks [lo, hi) of a grid that hold all its set blocks; lo = hi = 0 when none is set.
/// Outside them a brick's march has nothing to test, so it starts and ends at their box.
struct SetBlockBounds {
  glm::ivec3 lo{0}, hi{0};
  bool empty() const { return hi.x <= lo.x; }
};

/// The bounds of the set blocks `setBlocks` (as buildClearDistances) of a grid of `dims`.
SetBlockBounds setBlockBounds(const std::uint32_t* setBlocks, glm::uvec3 dims);

/// What a march tests around the first cell it meets after crossing a cube of clear blocks.
struct SlabAfterClearCube {
  int axis = -1;  ///< -1: the whole neighbourhood; else the slab at cell[axis] + side * k
  int side = 0;   ///< -1 or 1
};

/// For `cell` met just after crossing the clear cube [lo, hi) (cells, per axis): no sphere lies
/// within the reach k of a cell of a clear block (the blocks' dilation is the reach), so when
/// `cell` lies beside the cube across one face, its neighbourhood but for the far slab is within
/// k of the cube's cell next to it and holds none: only that slab is tested, as after a DDA
/// step. Across an edge or a corner of the cube, or farther from it, the whole neighbourhood is.
inline SlabAfterClearCube slabAfterClearCube(const int cell[3], const int lo[3], const int hi[3]) {
  SlabAfterClearCube slab;
  int outside = 0;  // axes on which the cell lies beside the cube, and 2 for one farther away
  for (int a = 0; a < 3; a++) {
    const int side = cell[a] < lo[a] ? -1 : cell[a] >= hi[a] ? 1 : 0;
    if (side == 0) continue;
    const int gap = side < 0 ? lo[a] - cell[a] : cell[a] - hi[a] + 1;
    outside += gap == 1 ? 1 : 2;
    slab.axis = a;
    slab.side = side;
  }
  if (outside != 1) slab = SlabAfterClearCube{};
  return slab;
}

}  // namespace flipscope
