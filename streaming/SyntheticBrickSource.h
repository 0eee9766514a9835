// A deterministic synthetic fluid for tests and benchmarks of the Streamer: a wavy water surface
// over a grid of bricks that moves with the frame number. Cells below the surface are occupied
// with probability `fill` (1..2 particles, 16-bit speeds), cells above it are empty, so bricks
// come full, empty and cut by the surface, as in the paper's FLIP data.
#pragma once

#include "streaming/BrickSource.h"

namespace flipscope {

class SyntheticBrickSource : public BrickSource {
 public:
  /// Frames [0, frames); bricks in [0, grid) per axis; z is up.
  SyntheticBrickSource(std::uint32_t brickSize, glm::uvec3 grid, int frames, double fill);
  std::uint32_t brickSize() const override { return mBrickSize; }
  std::shared_ptr<const DecodedBrick> read(const BrickKey& key) override;
  /// Non-empty bricks of a frame.
  std::vector<glm::uvec3> bricks(int frame) const;
  /// Surface height at global cell column (x, y), in cells.
  double surfaceHeight(int frame, double x, double y) const;

 private:
  std::uint32_t mBrickSize;
  glm::uvec3 mGrid;
  int mFrames;
  double mFill;
};

}  // namespace flipscope
