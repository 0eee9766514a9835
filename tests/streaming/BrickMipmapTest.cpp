// Brick mipmaps against a brute-force scan of each block's dilated box.
#include <gtest/gtest.h>

#include <random>

#include "streaming/BrickMipmap.h"
#include "streaming/RandomBricks.h"

namespace flipscope {
namespace {

void checkMipmap(std::uint32_t brickSize, std::uint32_t overlap, std::uint32_t dilation, double fill,
                 std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::array<DecodedBrick, 27> storage;
  Neighbourhood<DecodedBrick> bricks{};
  for (int i = 0; i < 27; ++i) {
    if (i != kCentre && rng() % 3 == 0) continue;
    storage[i] = testing::randomBrick(rng, brickSize, fill);
    bricks[i] = &storage[i];
  }
  BitBrick brick = convertBrick(bricks, {brickSize, overlap, AttributeReduction::None});
  std::vector<std::uint32_t> mip = buildBrickMipmap(brick, dilation);
  const std::uint32_t levels = bitBrickMipLevelCount(brickSize, overlap);
  ASSERT_EQ(mip.size(), bitBrickMipWordOffset(levels + 1, brickSize, overlap));
  const int stored = int(brickSize + 2 * overlap), d = int(dilation);
  std::uint32_t setBlocks = 0, clearBlocks = 0;
  for (std::uint32_t level = 1; level <= levels; ++level) {
    glm::uvec3 dims = bitBrickMipDims(level, brickSize, overlap);
    glm::ivec3 blockCells(4 << (level - 1), 4 << (level - 1), 8 << (level - 1));
    for (std::uint32_t z = 0; z < dims.z; ++z)
      for (std::uint32_t y = 0; y < dims.y; ++y)
        for (std::uint32_t x = 0; x < dims.x; ++x) {
          glm::ivec3 lo = glm::ivec3(x, y, z) * blockCells - d, hi = glm::ivec3(x + 1, y + 1, z + 1) * blockCells + d;
          lo = glm::max(lo, glm::ivec3(0));
          hi = glm::min(hi, glm::ivec3(stored));
          bool expected = false;
          for (int sz = lo.z; sz < hi.z && !expected; ++sz)
            for (int sy = lo.y; sy < hi.y && !expected; ++sy)
              for (int sx = lo.x; sx < hi.x && !expected; ++sx)
                expected = brick.isSet(glm::ivec3(sx, sy, sz) - int(overlap));
          std::uint32_t bit = bitBrickMipBitIndex({x, y, z}, level, brickSize, overlap);
          std::uint32_t word = mip[bitBrickMipWordOffset(level, brickSize, overlap) + (bit >> 5)];
          ASSERT_EQ((word >> (bit & 31) & 1u) != 0, expected)
              << "level " << level << " block " << x << "," << y << "," << z << " dilation " << dilation;
          (expected ? setBlocks : clearBlocks)++;
        }
  }
  // The random bricks leave both kinds, so the comparison tests something.
  EXPECT_GT(setBlocks, 0u);
  EXPECT_GT(clearBlocks, 0u);
}

TEST(BrickMipmap, MatchesBruteForceWithoutDilation) { checkMipmap(32, 2, 0, 0.01, 1); }

TEST(BrickMipmap, MatchesBruteForceWithDilation) {
  for (std::uint32_t dilation : {1u, 3u, 5u, 8u}) checkMipmap(32, 3, dilation, 0.002, 10 + dilation);
}

TEST(BrickMipmap, MatchesBruteForce64) { checkMipmap(64, 4, 2, 0.001, 3); }

}  // namespace
}  // namespace flipscope
