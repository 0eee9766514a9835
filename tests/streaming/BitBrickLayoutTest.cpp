// Pins the bit-brick layout of streaming/glsl/BitBrick.glsl (shared with the GPU) against
// brute-force enumerations of the stored cells.
#include <gtest/gtest.h>

#include <random>
#include <set>
#include <vector>

#include "streaming/BitBrickLayout.h"

namespace flipscope {
namespace {

TEST(BitBrickLayout, SubBrickDimsOfThePaper) {
  EXPECT_EQ(bitBrickSubBrickDims(64, 0), glm::uvec3(16, 16, 8));  // §3.1: 16x16x8 for 64^3
  EXPECT_EQ(bitBrickSubBrickDims(64, 4), glm::uvec3(18, 18, 9));
  EXPECT_EQ(bitBrickSubBrickDims(32, 3), glm::uvec3(10, 10, 5));  // 38 cells: padded
  EXPECT_EQ(bitBrickSubBrickDims(128, 8), glm::uvec3(36, 36, 18));
}

TEST(BitBrickLayout, EveryStoredCellHasItsOwnBit) {
  for (std::uint32_t brickSize : {32u, 64u}) {
    for (std::uint32_t overlap : {0u, 1u, 3u, 8u}) {
      glm::uvec3 dims = bitBrickSubBrickDims(brickSize, overlap);
      std::uint32_t subBricks = dims.x * dims.y * dims.z;
      std::vector<std::uint8_t> seen(std::size_t(subBricks) * 128, 0);
      int lo = -int(overlap), hi = int(brickSize + overlap);
      for (int z = lo; z < hi; ++z)
        for (int y = lo; y < hi; ++y)
          for (int x = lo; x < hi; ++x) {
            glm::ivec3 cell(x, y, z);
            std::uint32_t sub = bitBrickSubBrickIndex(cell, brickSize, overlap);
            std::uint32_t bit = bitBrickBitIndex(cell, overlap);
            ASSERT_LT(sub, subBricks);
            ASSERT_LT(bit, 128u);
            glm::ivec3 s = cell + int(overlap);
            ASSERT_EQ(sub, std::uint32_t(s.x / 4 + dims.x * (s.y / 4 + dims.y * (s.z / 8))));
            ASSERT_EQ(bit, std::uint32_t(s.x % 4 + 4 * (s.y % 4) + 16 * (s.z % 8)));
            ASSERT_EQ(seen[std::size_t(sub) * 128 + bit]++, 0) << "cell " << x << "," << y << "," << z;
          }
    }
  }
}

TEST(BitBrickLayout, LowerHalfSubBrickIsWordsZeroAndOne) {
  // Fig. 7: the 4^3 half with s.z&7 < 4 lives in words 0,1.
  for (int z = 0; z < 8; ++z) {
    std::uint32_t bit = bitBrickBitIndex(glm::ivec3(1, 2, z), 0);
    EXPECT_EQ(bit >> 5 < 2, z < 4);
  }
}

TEST(BitBrickLayout, BitSetAndAttributeOffsetMatchBruteForce) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    glm::uvec4 sub(rng(), rng(), rng(), rng());
    sub[trial % 4] &= rng();  // vary the densities
    std::uint32_t base = rng() % 60000;
    std::uint32_t count = 0;
    for (std::uint32_t i = 0; i < 128; ++i) {
      bool set = (sub[i / 32] >> (i % 32)) & 1u;
      EXPECT_EQ(bitBrickBitSet(sub, i), set);
      EXPECT_EQ(bitBrickAttributeOffset(base, sub, i), base + count) << "bit " << i;
      count += set;
    }
  }
}

TEST(BitBrickLayout, MipLevelsHalveDownToOneBlock) {
  EXPECT_EQ(bitBrickMipLevelCount(64, 4), 6u);  // 18x18x9, 9x9x5, 5x5x3, 3x3x2, 2x2x1, 1x1x1
  EXPECT_EQ(bitBrickMipDims(2, 64, 4), glm::uvec3(9, 9, 5));
  EXPECT_EQ(bitBrickMipDims(6, 64, 4), glm::uvec3(1, 1, 1));
  EXPECT_EQ(bitBrickMipLevelCount(64, 0), 5u);  // 16x16x8 ... 1x1x1
  for (std::uint32_t brickSize : {32u, 64u, 128u}) {
    for (std::uint32_t overlap : {0u, 2u, 5u}) {
      std::uint32_t levels = bitBrickMipLevelCount(brickSize, overlap);
      EXPECT_EQ(bitBrickMipDims(levels, brickSize, overlap), glm::uvec3(1));
      std::uint32_t offset = 0;
      for (std::uint32_t k = 1; k <= levels + 1; ++k) {
        EXPECT_EQ(bitBrickMipWordOffset(k, brickSize, overlap), offset);
        glm::uvec3 d = bitBrickMipDims(k, brickSize, overlap);
        offset += (d.x * d.y * d.z + 31) / 32;
        std::set<std::uint32_t> bits;
        for (std::uint32_t z = 0; z < d.z; ++z)
          for (std::uint32_t y = 0; y < d.y; ++y)
            for (std::uint32_t x = 0; x < d.x; ++x) bits.insert(bitBrickMipBitIndex({x, y, z}, k, brickSize, overlap));
        EXPECT_EQ(bits.size(), std::size_t(d.x) * d.y * d.z);
        EXPECT_EQ(*bits.rbegin(), d.x * d.y * d.z - 1);
      }
    }
  }
}

}  // namespace
}  // namespace flipscope
