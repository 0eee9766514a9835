// A deterministic synthetic fluid for tests and benchmarks of the Streamer, the frame renderer
// and the frame pipeline: a wavy water surface over a grid of bricks that moves with the frame
// number. Cells below the surface are occupied with probability `fill` (1..2 particles, 16-bit
// speeds), cells above it are empty, so bricks come full, empty and cut by the surface, as in
// the paper's FLIP data.
//
// Its domain (header()): cells of kCellSize world units; z is up; the tank is centred on the
// world's z axis with its floor at z = 0, i.e. origin = (-gridX * brickSize * kCellSize / 2,
// -gridY * brickSize * kCellSize / 2, 0). Attribute: speed. Particle spacing: 0 (unknown).
// Frames are 0 .. frames - 1. A frame's index (frame()) is computed from the analytic surface
// on first use, decoding every brick the surface may reach, and cached.
#pragma once

#include <map>
#include <mutex>

#include "streaming/BrickSource.h"

namespace flipscope {

class SyntheticBrickSource : public BrickSource {
 public:
  /// World units per cell.
  static constexpr double kCellSize = 0.01;

  /// Frames [0, frames); bricks of brickSize (32, 64 or 128) cells in [0, grid) per axis (each
  /// below kMortonAxisLimit); z is up. fill: probability in [0, 1] that a cell below the surface
  /// holds particles.
  SyntheticBrickSource(std::uint32_t brickSize, glm::uvec3 grid, int frames, double fill);

  const StoreHeader& header() const override { return mHeader; }
  std::vector<int> frames() const override;
  bool hasFrame(int frame) const override { return frame >= 0 && frame < mFrames; }
  std::shared_ptr<const FrameIndex> frame(int frame) const override;
  std::shared_ptr<const DecodedBrick> read(const BrickKey& key) override { return decode(key); }
  std::string name() const override;

  /// Bricks of a frame the surface reaches (a superset of frame(f)->bricks: a brick the surface
  /// barely cuts may draw no particle), in x-fastest order.
  std::vector<glm::uvec3> bricks(int frame) const;
  /// Surface height at global cell column (x, y), in cells above the floor.
  double surfaceHeight(int frame, double x, double y) const;

 private:
  std::shared_ptr<const DecodedBrick> decode(const BrickKey& key) const;

  std::uint32_t mBrickSize;
  glm::uvec3 mGrid;
  int mFrames;
  double mFill;
  StoreHeader mHeader;
  mutable std::mutex mMutex;
  mutable std::map<int, std::shared_ptr<const FrameIndex>> mIndices;
};

}  // namespace flipscope
