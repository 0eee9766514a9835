// ClearDistance against brute force: each block's Chebyshev distance, in blocks, to the nearest
// set block (0 when set), capped at kMaxClearDistance; the bounds of the set blocks; and the
// slab a march tests after crossing a clear cube.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <random>
#include <vector>

#include <glm/common.hpp>

#include "raycast/ClearDistance.h"

namespace flipscope {
namespace {

std::vector<std::uint8_t> bruteForce(const std::vector<bool>& set, glm::ivec3 n) {
  std::vector<std::uint8_t> out(set.size());
  for (int z = 0; z < n.z; z++)
    for (int y = 0; y < n.y; y++)
      for (int x = 0; x < n.x; x++) {
        int best = kMaxClearDistance;
        for (int qz = 0; qz < n.z; qz++)
          for (int qy = 0; qy < n.y; qy++)
            for (int qx = 0; qx < n.x; qx++)
              if (set[std::size_t(qx + n.x * (qy + n.y * qz))])
                best = std::min(best, std::max({std::abs(qx - x), std::abs(qy - y), std::abs(qz - z)}));
        out[std::size_t(x + n.x * (y + n.y * z))] = std::uint8_t(best);
      }
  return out;
}

TEST(ClearDistance, IsTheChebyshevDistanceToTheNearestSetBlock) {
  // Dims of a 64^3 brick with overlap 1 (17x17x9), a 128^3 one (33x33x17), and odd shapes (one
  // a single block deep in y, where the y and z strides are equal); from none set to most set,
  // so that distances run from 0 to the cap.
  const glm::ivec3 shapes[] = {{17, 17, 9}, {33, 33, 17}, {1, 1, 1}, {5, 40, 3}, {6, 1, 20}};
  const double densities[] = {0.0, 0.0005, 0.01, 0.2, 0.9};
  std::mt19937 random(7);
  for (const glm::ivec3 n : shapes)
    for (const double density : densities) {
      SCOPED_TRACE(::testing::Message() << n.x << "x" << n.y << "x" << n.z << " density " << density);
      const std::size_t count = std::size_t(n.x) * n.y * n.z;
      std::vector<bool> set(count);
      std::vector<std::uint32_t> words((count + 31) / 32, 0);
      std::bernoulli_distribution draw(density);
      for (std::size_t i = 0; i < count; i++)
        if ((set[i] = draw(random))) words[i >> 5] |= 1u << (i & 31);
      std::vector<std::uint8_t> distances(count, 0xff);
      buildClearDistances(words.data(), glm::uvec3(n), distances.data());
      EXPECT_EQ(distances, bruteForce(set, n));
    }
}

TEST(ClearDistance, ASingleSetBlockGivesRingsAroundIt) {
  const glm::ivec3 n(33, 33, 17);
  std::vector<std::uint32_t> words((33 * 33 * 17 + 31) / 32, 0);
  const std::size_t centre = 16 + 33 * (16 + 33 * 8);
  words[centre >> 5] |= 1u << (centre & 31);
  std::vector<std::uint8_t> distances(33 * 33 * 17);
  buildClearDistances(words.data(), glm::uvec3(n), distances.data());
  EXPECT_EQ(distances[centre], 0);
  EXPECT_EQ(distances[centre + 1], 1);
  EXPECT_EQ(distances[centre - 33 * 33 * 3 + 2], 3);      // z -3, x +2
  EXPECT_EQ(distances[centre + 33 * 14 + 33 * 33 * 8], 14);  // y +14, z +8
  EXPECT_EQ(distances[0], kMaxClearDistance);                 // 16 away
}

TEST(ClearDistance, SetBlockBoundsHoldEverySetBlockAndNoMore) {
  std::mt19937 random(11);
  for (const glm::ivec3 n : {glm::ivec3(17, 17, 9), glm::ivec3(16, 16, 16), glm::ivec3(1, 1, 1)})
    for (int blocks : {0, 1, 3, 40}) {
      SCOPED_TRACE(::testing::Message() << n.x << "x" << n.y << "x" << n.z << ", " << blocks << " set");
      const std::size_t count = std::size_t(n.x) * n.y * n.z;
      std::vector<std::uint32_t> words((count + 31) / 32, 0);
      glm::ivec3 lo(1 << 20), hi(-1);
      for (int b = 0; b < blocks; b++) {
        const glm::ivec3 q(int(random() % n.x), int(random() % n.y), int(random() % n.z));
        const std::size_t i = std::size_t(q.x + n.x * (q.y + n.y * q.z));
        words[i >> 5] |= 1u << (i & 31);
        lo = glm::min(lo, q);
        hi = glm::max(hi, q + 1);
      }
      const SetBlockBounds bounds = setBlockBounds(words.data(), glm::uvec3(n));
      EXPECT_EQ(bounds.empty(), blocks == 0);
      if (blocks == 0) continue;
      EXPECT_EQ(bounds.lo, lo);
      EXPECT_EQ(bounds.hi, hi);
    }
}

TEST(ClearDistance, AfterAClearCubeOnlyAFaceNeighbourTestsJustItsFarSlab) {
  const int lo[3] = {4, 8, 0}, hi[3] = {12, 16, 8};
  auto slab = [&](int x, int y, int z) {
    const int cell[3] = {x, y, z};
    return slabAfterClearCube(cell, lo, hi);
  };
  // Beside each of the six faces: that axis, towards the cell.
  EXPECT_EQ(slab(12, 10, 3).axis, 0);
  EXPECT_EQ(slab(12, 10, 3).side, 1);
  EXPECT_EQ(slab(3, 10, 3).axis, 0);
  EXPECT_EQ(slab(3, 10, 3).side, -1);
  EXPECT_EQ(slab(5, 16, 3).axis, 1);
  EXPECT_EQ(slab(5, 16, 3).side, 1);
  EXPECT_EQ(slab(5, 7, 3).axis, 1);
  EXPECT_EQ(slab(5, 7, 3).side, -1);
  EXPECT_EQ(slab(11, 15, 8).axis, 2);
  EXPECT_EQ(slab(11, 15, 8).side, 1);
  EXPECT_EQ(slab(4, 8, -1).axis, 2);
  EXPECT_EQ(slab(4, 8, -1).side, -1);
  // Across an edge, a corner, or two cells away: the whole neighbourhood.
  EXPECT_EQ(slab(12, 16, 3).axis, -1);
  EXPECT_EQ(slab(3, 7, 3).axis, -1);
  EXPECT_EQ(slab(12, 10, 8).axis, -1);
  EXPECT_EQ(slab(12, 16, 8).axis, -1);
  EXPECT_EQ(slab(3, 7, -1).axis, -1);
  EXPECT_EQ(slab(13, 10, 3).axis, -1);
  EXPECT_EQ(slab(5, 10, -2).axis, -1);
  // Inside the cube (a march never meets one there): the whole neighbourhood.
  EXPECT_EQ(slab(5, 10, 3).axis, -1);
}

}  // namespace
}  // namespace flipscope
