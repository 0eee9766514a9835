// Random DecodedBricks for the streaming tests (seeded; clustered so that borders and whole
// sub-bricks are both full and empty).
#pragma once

#include <random>

#include "preprocess/store/BrickStore.h"

namespace flipscope::testing {

/// A brick of brickSize^3 cells with about `fill` of its cells occupied (1..3 particles each,
/// random 16-bit attributes), denser in a random half-space so that empty sub-bricks occur.
inline DecodedBrick randomBrick(std::mt19937& rng, std::uint32_t brickSize, double fill) {
  DecodedBrick brick;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int axis = int(rng() % 3);
  double cut = unit(rng);
  std::uint32_t cells = brickSize * brickSize * brickSize;
  for (std::uint32_t cell = 0; cell < cells; ++cell) {
    std::uint32_t coord[3] = {cell % brickSize, cell / brickSize % brickSize, cell / brickSize / brickSize};
    double p = coord[axis] < cut * brickSize ? 2.0 * fill : 0.1 * fill;
    if (unit(rng) >= p) continue;
    std::uint32_t count = 1 + rng() % 3;
    brick.cells.push_back(cell);
    brick.counts.push_back(count);
    for (std::uint32_t i = 0; i < count; ++i) brick.attributes.push_back(std::uint16_t(rng()));
  }
  return brick;
}

}  // namespace flipscope::testing
