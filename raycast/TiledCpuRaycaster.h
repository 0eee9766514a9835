// TiledCpuRaycaster: the fast CPU ray-caster, the one `--device cpu` runs. It shares
// CpuRaycaster's pool, uploads and foam classification, and gives its images within the
// tolerance tests/raycast/TiledCpuRaycasterTest.cpp states: hit or miss differ for at most 1 in
// 500 pixels (a ray grazing a sphere or a cell edge), and 99.5% of the pixels hit on both sides
// agree to 1e-4 relative in t and depth, 1e-3 in the normal and foam opacity, exactly in the
// attribute, and to 1% of the saturation in thickness. A step into the next cell resumes just
// past its face (rcStepPast), as the reference's point location does, so that the foam's fixed
// samples fall into the same cells.
//
// What makes it faster than the reference, which runs Raycast.glsl per pixel:
//  - the image is cut into tiles of 16x16 pixels, spread over every core;
//  - each thread keeps the jittered centres of the cells its rays tested (a direct-mapped cache
//    by global cell): neighbouring rays test mostly the same cells, and the jitter's TEA hashes
//    (§3.2.2) were most of the reference's time;
//  - the march through a brick (§3.3.1) is a 3D DDA that keeps its state from cell to cell: a
//    step tests only the slab of (2k+1)^2 cells entering the neighbourhood, read straight from
//    the slot's sub-bricks, and the cell's exit comes from the DDA instead of a box test;
//  - the pool keeps march tables (PoolLayout::marchTables, built at upload and after foam
//    classification): per brick cell, whether a sphere cell lies within the reach k
//    (NearSphereMask), so that a step into a cell with none skips its slab tests (most steps
//    near a surface); per sub-brick, the sphere and foam cells of each half, which the
//    thickness trace (§3.6) and the foam volume (§3.5) read instead of counting bits at every
//    sample; and two ClearDistance tables: per level-1 mip block, and per 4^3 cells of the
//    NearSphereMask, the distance to the nearest set one;
//  - empty space (§4.2) is skipped by the cube of clear blocks centred on the ray's block
//    (ClearDistance), one table read, instead of the reference's walk up the mip levels to an
//    aligned block. The cubes are of 4^3-cell groups with no sphere near, or of level-1 mip
//    blocks under the foam volume (whose cells the mask leaves out but the ray gathers). The
//    cell met on leaving a cube through a face tests only its far slab, since no sphere lies
//    within the reach of the cube. A brick's march starts and ends at the box of the set
//    blocks (SetBlockBounds): a ray that passes over the liquid in a brick tests nothing.
//  - the foam classification (§3.5) counts a cell's neighbours in a byte grid of the brick and
//    stops once it has enough not to be foam (FoamNeighbourCount): the reference's bits.
// The rest of the pass (octree descent, requests, foam, attributes, thickness) is
// Raycast.glsl itself, compiled once more around the new brick march (rcMarchBrick).
#pragma once

#include "raycast/CpuRaycaster.h"

namespace flipscope {

class TiledCpuRaycaster : public CpuRaycaster {
 public:
  std::string name() const override;
  bool keepsMarchTables() const override { return true; }
  void uploadBrick(std::uint32_t slot, std::uint64_t attributeOffset, const ConvertedBrick& brick) override;
  void classifyFoam(std::span<const std::uint32_t> slots, const FoamClassifyParams& params) override;
  std::vector<std::uint32_t> trace(const RaycastParams& params) override;

 private:
  /// Fills the pool's half counts and NearSphereMask of `slot` from its bits (and foam bits).
  void buildMarchTables(std::uint32_t slot);
};

}  // namespace flipscope
