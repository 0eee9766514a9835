// Bricks and a brute force for the foam tests (Reichl et al. 2014 §3.5): pools filled with
// hand-made bit-bricks, classified on a device and checked against counting neighbours cell by
// cell.
#pragma once

#include <cmath>
#include <functional>
#include <random>

#include <gtest/gtest.h>

#include "raycast/RaycastDevice.h"
#include "streaming/BrickMipmap.h"

namespace flipscope::testing {

/// The brick size, border and sphere radius of the foam tests' bricks.
struct FoamBrickShape {
  std::uint32_t brickSize = 32;
  std::uint32_t overlap = 4;
  float radius = 1.5f;
  std::uint32_t stored() const { return brickSize + 2 * overlap; }
};

/// A converted brick whose stored cell s (brick-local cell + overlap, each axis in [0, stored))
/// is set where `set(s)` says.
inline ConvertedBrick foamTestBrick(const FoamBrickShape& shape, const std::function<bool(glm::ivec3)>& set) {
  ConvertedBrick brick;
  brick.bits.brickSize = shape.brickSize;
  brick.bits.overlap = shape.overlap;
  const glm::uvec3 dims = bitBrickSubBrickDims(shape.brickSize, shape.overlap);
  brick.bits.subBricks.assign(std::size_t(dims.x) * dims.y * dims.z, glm::uvec4(0));
  const int n = int(shape.overlap), stored = int(shape.stored());
  for (int z = 0; z < stored; ++z)
    for (int y = 0; y < stored; ++y)
      for (int x = 0; x < stored; ++x) {
        if (!set({x, y, z})) continue;
        const glm::ivec3 cell = glm::ivec3(x, y, z) - n;
        const std::uint32_t bit = bitBrickBitIndex(cell, shape.overlap);
        brick.bits.subBricks[bitBrickSubBrickIndex(cell, shape.brickSize, shape.overlap)][int(bit >> 5)] |=
            1u << (bit & 31);
      }
  brick.mipmap = buildBrickMipmap(brick.bits, 1);
  return brick;
}

/// A pool of `slots` slots without attributes, with foam bit-bricks, for `shape`.
inline PoolLayout foamTestLayout(const FoamBrickShape& shape, std::uint32_t slots) {
  PoolLayout layout = PoolLayout::forBudget(shape.brickSize, shape.overlap, false, 64ull << 20, true);
  layout.slots = slots;
  return layout;
}

inline FoamClassifyParams foamTestParams(const FoamBrickShape& shape, std::size_t slots, float threshold,
                                         std::uint32_t subBricksPerSlot) {
  FoamClassifyParams p{};
  p.brickSize = shape.brickSize;
  p.overlap = shape.overlap;
  p.subBricksPerSlot = subBricksPerSlot;
  p.batchSubBricks = std::uint32_t(slots) * subBricksPerSlot;
  p.radius = shape.radius;
  p.threshold = threshold;
  p.classify = 1u;
  return p;
}

/// Whether stored cell s is set in `brick`.
inline bool storedSet(const ConvertedBrick& brick, const FoamBrickShape& shape, glm::ivec3 s) {
  const int stored = int(shape.stored());
  if (glm::any(glm::lessThan(s, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(s, glm::ivec3(stored)))) return false;
  return brick.bits.isSet(s - int(shape.overlap));
}

/// The foam cells by brute force: every set stored cell with fewer than threshold * N set cells
/// among the N cells d != 0, |d| <= radius around it (beyond the stored cells: empty).
inline std::vector<glm::uvec4> bruteForceFoam(const ConvertedBrick& brick, const FoamBrickShape& shape,
                                              float threshold) {
  std::vector<glm::ivec3> offsets;
  const int reach = int(std::floor(shape.radius));
  for (int z = -reach; z <= reach; ++z)
    for (int y = -reach; y <= reach; ++y)
      for (int x = -reach; x <= reach; ++x)
        if ((x || y || z) && float(x * x + y * y + z * z) <= shape.radius * shape.radius) offsets.emplace_back(x, y, z);
  std::vector<glm::uvec4> foam(brick.bits.subBricks.size(), glm::uvec4(0));
  const int stored = int(shape.stored());
  for (int z = 0; z < stored; ++z)
    for (int y = 0; y < stored; ++y)
      for (int x = 0; x < stored; ++x) {
        const glm::ivec3 s(x, y, z);
        if (!storedSet(brick, shape, s)) continue;
        int count = 0;
        for (const glm::ivec3& d : offsets) count += storedSet(brick, shape, s + d);
        if (float(count) < threshold * float(offsets.size())) {
          const glm::ivec3 cell = s - int(shape.overlap);
          const std::uint32_t bit = bitBrickBitIndex(cell, shape.overlap);
          foam[bitBrickSubBrickIndex(cell, shape.brickSize, shape.overlap)][int(bit >> 5)] |= 1u << (bit & 31);
        }
      }
  return foam;
}

/// Random bricks with a mix of fill rates (clusters of dense liquid, thin spray), on a device
/// with a foam pool: uploads them, classifies them in one batch, and returns each slot's foam.
inline std::vector<std::vector<glm::uvec4>> classifyRandomBricks(RaycastDevice& device, const FoamBrickShape& shape,
                                                                 float threshold, std::uint32_t seed,
                                                                 std::vector<ConvertedBrick>& bricks) {
  std::mt19937 rng(seed);
  const PoolLayout layout = foamTestLayout(shape, 4);
  device.allocatePool(layout);
  bricks.clear();
  for (int b = 0; b < 4; ++b) {
    std::uniform_real_distribution<float> unit(0, 1);
    const float dense = 0.3f + 0.6f * unit(rng), sparse = 0.02f + 0.1f * unit(rng);
    const glm::vec3 centre(unit(rng) * shape.stored(), unit(rng) * shape.stored(), unit(rng) * shape.stored());
    const float blob = 6 + 10 * unit(rng);
    bricks.push_back(foamTestBrick(shape, [&](glm::ivec3 s) {
      const float fill = glm::length(glm::vec3(s) - centre) < blob ? dense : sparse;
      return unit(rng) < fill;
    }));
    device.uploadBrick(std::uint32_t(b), 0, bricks.back());
  }
  const std::vector<std::uint32_t> batch{2, 0, 3, 1};  // any order
  device.classifyFoam(batch, foamTestParams(shape, batch.size(), threshold, layout.subBricksPerSlot));
  std::vector<std::vector<glm::uvec4>> foam;
  for (std::uint32_t b = 0; b < 4; ++b) foam.push_back(device.readFoam(b));
  return foam;
}

/// Particles at every cell centre with all-even coordinates in [lo, hi): a foam slab (no cell
/// has a set neighbour within 1.5 cells) whose 4^3 blocks on the lattice of 2 mod 4 hold 8 cells
/// each, density 1/8.
inline std::vector<glm::vec3> foamSlab(glm::ivec3 lo, glm::ivec3 hi) {
  std::vector<glm::vec3> out;
  for (int z = lo.z; z < hi.z; ++z)
    for (int y = lo.y; y < hi.y; ++y)
      for (int x = lo.x; x < hi.x; ++x)
        if (x % 2 == 0 && y % 2 == 0 && z % 2 == 0) out.emplace_back(x + 0.5f, y + 0.5f, z + 0.5f);
  return out;
}

/// Isolated spray: one particle every 6 cells on the plane z = `z` over [lo, hi) in x and y.
inline std::vector<glm::vec3> sprayPlane(int lo, int hi, int z) {
  std::vector<glm::vec3> out;
  for (int y = lo; y < hi; y += 6)
    for (int x = lo; x < hi; x += 6) out.emplace_back(x + 0.5f, y + 0.5f, z + 0.5f);
  return out;
}

}  // namespace flipscope::testing
