// NearSphereMask against brute force: a cell's bit is set exactly when a sphere cell (a set bit
// that is no foam) lies within the reach, border cells included.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "raycast/NearSphereMask.h"
#include "streaming/BitBrickLayout.h"

namespace flipscope {
namespace {

struct Case {
  std::uint32_t brickSize, overlap, reach;
  bool foam;
};

TEST(NearSphereMask, MatchesTheCellsWithASphereWithinReach) {
  for (const Case c : {Case{32, 1, 1, false}, Case{64, 2, 2, true}, Case{64, 3, 1, false}, Case{128, 2, 0, false},
                       Case{32, 8, 8, true}, Case{128, 3, 3, true}}) {
    SCOPED_TRACE(::testing::Message() << c.brickSize << " overlap " << c.overlap << " reach " << c.reach);
    const glm::uvec3 dims = bitBrickSubBrickDims(c.brickSize, c.overlap);
    const std::size_t subBricks = std::size_t(dims.x) * dims.y * dims.z;
    std::vector<glm::uvec4> bits(subBricks, glm::uvec4(0)), foam(subBricks, glm::uvec4(0));
    const int B = int(c.brickSize), o = int(c.overlap), k = int(c.reach), stored = B + 2 * o;
    // Sparse cells, so that most cells have none near, everywhere in the stored cube.
    std::mt19937 random(c.brickSize * 31 + c.reach);
    auto setBit = [&](std::vector<glm::uvec4>& target, int x, int y, int z) {
      const glm::uvec3 s(std::uint32_t(x + o), std::uint32_t(y + o), std::uint32_t(z + o));
      const std::uint32_t sub = (s.x >> 2) + dims.x * ((s.y >> 2) + dims.y * (s.z >> 3));
      const std::uint32_t bit = (s.x & 3) | ((s.y & 3) << 2) | ((s.z & 7) << 4);
      target[sub][bit >> 5] |= 1u << (bit & 31);
    };
    // Per stored cell: 1 set, 2 foam (a cell drawn twice may be both: no sphere).
    std::vector<char> state(std::size_t(stored) * stored * stored, 0);
    auto stateAt = [&](int x, int y, int z) -> char& {
      return state[(std::size_t(z + o) * stored + std::size_t(y + o)) * stored + std::size_t(x + o)];
    };
    auto at = [&](int x, int y, int z) { return stateAt(x, y, z) == 1; };
    const int count = stored * stored * stored / (k == 0 ? 20 : 12 * (2 * k + 1) * (2 * k + 1) * (2 * k + 1));
    for (int i = 0; i < count; ++i) {
      const int x = int(random() % stored) - o, y = int(random() % stored) - o, z = int(random() % stored) - o;
      setBit(bits, x, y, z);
      const bool isFoam = c.foam && random() % 3 == 0;
      if (isFoam) setBit(foam, x, y, z);
      stateAt(x, y, z) |= char(isFoam ? 3 : 1);
    }
    std::vector<std::uint64_t> mask(nearSphereMaskWords(c.brickSize), ~std::uint64_t(0));
    buildNearSphereMask(bits.data(), c.foam ? foam.data() : nullptr, c.brickSize, c.overlap, c.reach, mask.data());
    const std::uint32_t rowWords = (c.brickSize + 63) / 64;
    int near = 0, wrong = 0;
    for (int z = 0; z < B; ++z)
      for (int y = 0; y < B; ++y)
        for (int x = 0; x < B; ++x) {
          bool expected = false;
          for (int dz = -k; dz <= k && !expected; ++dz)
            for (int dy = -k; dy <= k && !expected; ++dy)
              for (int dx = -k; dx <= k && !expected; ++dx) expected = at(x + dx, y + dy, z + dz);
          const std::uint64_t word = mask[(std::size_t(z) * B + std::size_t(y)) * rowWords + std::size_t(x >> 6)];
          const bool got = (word >> (x & 63)) & 1;
          near += expected;
          wrong += got != expected;
        }
    EXPECT_EQ(wrong, 0);
    EXPECT_GT(near, B * B * B / 100);  // the scene is neither empty
    EXPECT_LT(near, B * B * B * 9 / 10);  // nor full
    // A row's bits past the brick are clear.
    if (c.brickSize % 64 != 0) {
      for (std::size_t r = 0; r < std::size_t(B) * B; ++r) EXPECT_EQ(mask[r] >> c.brickSize, 0u) << r;
    }
  }
}

TEST(NearSphereMask, GroupsAreSetExactlyWhereOneOfTheirCellsIs) {
  for (const std::uint32_t brickSize : {32u, 64u, 128u}) {
    SCOPED_TRACE(brickSize);
    const std::uint32_t B = brickSize, W = (B + 63) / 64, G = B / kNearGroupCells;
    std::vector<std::uint64_t> mask(nearSphereMaskWords(B), 0);
    std::mt19937 random(B);
    // Single cells, so that a group is set by one cell at any of its 64 places.
    for (int i = 0; i < int(G * G * G / 3); ++i) {
      const std::uint32_t x = random() % B, y = random() % B, z = random() % B;
      mask[(std::size_t(z) * B + y) * W + x / 64] |= std::uint64_t(1) << (x % 64);
    }
    std::vector<std::uint32_t> groups((nearSphereGroupCount(B) + 31) / 32, ~0u);
    nearSphereGroups(mask.data(), B, groups.data());
    int set = 0, wrong = 0;
    for (std::uint32_t gz = 0; gz < G; ++gz)
      for (std::uint32_t gy = 0; gy < G; ++gy)
        for (std::uint32_t gx = 0; gx < G; ++gx) {
          bool expected = false;
          for (std::uint32_t z = gz * 4; z < gz * 4 + 4; ++z)
            for (std::uint32_t y = gy * 4; y < gy * 4 + 4; ++y)
              for (std::uint32_t x = gx * 4; x < gx * 4 + 4; ++x)
                expected |= ((mask[(std::size_t(z) * B + y) * W + x / 64] >> (x % 64)) & 1u) != 0u;
          const std::size_t i = gx + std::size_t(G) * (gy + std::size_t(G) * gz);
          set += expected;
          wrong += (((groups[i / 32] >> (i % 32)) & 1u) != 0u) != expected;
        }
    EXPECT_EQ(wrong, 0);
    EXPECT_GT(set, int(G * G * G / 5));
    EXPECT_LT(set, int(G * G * G / 2));
  }
}

}  // namespace
}  // namespace flipscope
