// FoamNeighbourCount: the foam classification of FoamClassify.glsl (fcClassify, Reichl et al.
// 2014 §3.5) for a whole resident brick at once, as the fast CPU device runs it: the same foam
// bits, found faster. The brick's stored cells are spread into a byte grid, zero-padded by the
// reach, so a neighbour is one load at a fixed offset with no bounds test; each set cell counts
// its neighbours (the offsets within the sphere radius, nearest first) and stops as soon as it has
// the count that makes it no foam, which in a liquid body is after a few. Eight cells of a row
// count at once, a byte each of a 64-bit word, one load an offset for all eight.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec4.hpp>

#include "raycast/FoamTypes.h"

namespace flipscope {

/// The byte grid and offsets one thread reuses from brick to brick.
struct FoamNeighbourScratch {
  std::vector<std::uint8_t> cells;     ///< the stored cells, zero-padded
  std::vector<std::uint8_t> setCells;  ///< the cells to classify (every set bit)
  std::vector<std::int32_t> offsets;
};

/// fcClassify of every sub-brick of one brick: `subBricks` are its bits (params.subBricksPerSlot of them),
/// `foam` its foam bits as uploaded, replaced by the classified ones. Equal to the reference's
/// fcClassify bit for bit (tests/raycast/FoamNeighbourCountTest.cpp).
void classifyBrickFoam(const glm::uvec4* subBricks, glm::uvec4* foam, const FoamClassifyParams& params,
                       FoamNeighbourScratch& scratch);

}  // namespace flipscope
