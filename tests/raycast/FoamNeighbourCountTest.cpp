// FoamNeighbourCount (the fast CPU device's foam classification) against the reference's
// fcClassify (FoamClassify.glsl compiled as C++), sub-brick by sub-brick, bit for bit: random
// bricks from sparse to dense, sphere radii below, at and above whole cells, thresholds from 0
// to a half, with and without foam bits uploaded, and with the classification off.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "raycast/CpuRaycastKernel.h"
#include "raycast/FoamNeighbourCount.h"

namespace flipscope {
namespace {

TEST(FoamNeighbourCount, EqualsTheReferenceClassification) {
  const std::uint32_t brickSize = 32, overlap = 3;
  const glm::uvec3 dims = glsl::bitBrickSubBrickDims(brickSize, overlap);
  const std::uint32_t subBricks = dims.x * dims.y * dims.z;
  std::mt19937 rng(7);
  FoamNeighbourScratch scratch;
  int foamCells = 0, liquidCells = 0;
  for (float radius : {0.9f, 1.0f, 1.5f, 2.2f, 3.0f, 3.3f}) {  // from 3.3, over 128 neighbours: no byte lanes
    for (float threshold : {0.0f, 0.2f, 0.5f}) {
      for (float density : {0.03f, 0.3f, 0.85f}) {
        for (bool uploaded : {false, true}) {
          for (std::uint32_t classify : {1u, 0u}) {
            SCOPED_TRACE(::testing::Message() << "radius " << radius << " threshold " << threshold << " density "
                                              << density << " uploaded foam " << uploaded << " classify " << classify);
            CpuRaycaster::Pool pool;
            pool.subBricks.resize(subBricks);
            pool.foamBits.resize(subBricks);
            // Sub-bricks of their own density around the brick's, some empty: sparse spray and
            // dense liquid side by side.
            std::uniform_real_distribution<float> unit(0.0f, 1.0f);
            for (std::uint32_t s = 0; s < subBricks; ++s) {
              const float p = unit(rng) < 0.2f ? 0.0f : std::min(1.0f, density * 2.0f * unit(rng));
              glm::uvec4 bits(0), foam(0);
              for (int bit = 0; bit < 128; ++bit) {
                if (unit(rng) < p) bits[bit >> 5] |= 1u << (bit & 31);
                if (uploaded && unit(rng) < 0.05f) foam[bit >> 5] |= 1u << (bit & 31);
              }
              pool.subBricks[s] = bits;
              pool.foamBits[s] = foam & bits;
            }
            FoamClassifyParams params{};
            params.brickSize = brickSize;
            params.overlap = overlap;
            params.subBricksPerSlot = subBricks;
            params.batchSubBricks = subBricks;
            params.radius = radius;
            params.threshold = threshold;
            params.classify = classify;
            glsl::FoamKernel reference{params, &pool};
            std::vector<glm::uvec4> fast(pool.foamBits.begin(), pool.foamBits.end());
            classifyBrickFoam(pool.subBricks.data(), fast.data(), params, scratch);
            int differing = 0;
            for (std::uint32_t s = 0; s < subBricks; ++s) {
              const glm::uvec4 expected = reference.fcClassify(0, s);
              differing += expected != fast[s];
              for (int w = 0; w < 4; ++w) {
                foamCells += std::popcount(expected[w]);
                liquidCells += std::popcount(pool.subBricks[s][w] & ~expected[w]);
              }
            }
            EXPECT_EQ(differing, 0);
          }
        }
      }
    }
  }
  // Both kinds of cell were met, many times.
  EXPECT_GT(foamCells, 10000);
  EXPECT_GT(liquidCells, 10000);
}

}  // namespace
}  // namespace flipscope
