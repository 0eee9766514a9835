// Where the Streamer gets decoded bricks from: an interface, so tests and benchmarks need no
// store, and its adapter over the preprocess BrickStore (Reichl et al. 2014 §3.1: the CPU
// converts bricks on request from the binned particles).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>

#include <glm/vec3.hpp>

#include "preprocess/BrickStore.h"

namespace flipscope {

/// A brick of one frame, by brick-grid coordinates.
struct BrickKey {
  int frame = 0;
  glm::uvec3 coord{0};
  bool operator==(const BrickKey&) const = default;
};

struct BrickKeyHash {
  std::size_t operator()(const BrickKey& key) const {
    std::uint64_t h = std::uint64_t(std::uint32_t(key.frame)) * 0x9e3779b97f4a7c15ull;
    h ^= (std::uint64_t(key.coord.x) | std::uint64_t(key.coord.y) << 21 | std::uint64_t(key.coord.z) << 42) +
         0x632be59bd9b4e019ull + (h << 6) + (h >> 2);
    return std::size_t(h);
  }
};

/// Thread safety: read() is called concurrently from the Streamer's workers.
class BrickSource {
 public:
  virtual ~BrickSource() = default;
  virtual std::uint32_t brickSize() const = 0;
  /// The brick's particles, or nullptr when the brick is empty, outside the grid, or the frame
  /// does not exist. Throws FileError on a corrupted store.
  virtual std::shared_ptr<const DecodedBrick> read(const BrickKey& key) = 0;
};

/// Reads bricks from a BrickStore through each frame's presence octree.
class StoreBrickSource : public BrickSource {
 public:
  explicit StoreBrickSource(BrickStore store) : mStore(std::move(store)) {}
  std::uint32_t brickSize() const override { return mStore.header().brickSize; }
  std::shared_ptr<const DecodedBrick> read(const BrickKey& key) override;

 private:
  BrickStore mStore;
};

}  // namespace flipscope
