// PresenceOctree against a brute-force oracle on random brick sets.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <random>
#include <set>

#include "core/Morton.h"
#include "preprocess/store/PresenceOctree.h"

namespace flipscope {
namespace {

TEST(Morton, RoundTripsAndOrdersByOctant) {
  std::mt19937 rng(7);
  for (int i = 0; i < 10000; ++i) {
    glm::uvec3 c(rng() % 1024, rng() % 1024, rng() % 1024);
    EXPECT_EQ(mortonDecode3(mortonEncode3(c.x, c.y, c.z)), c);
  }
  EXPECT_EQ(mortonEncode3(1, 0, 0), 1u);
  EXPECT_EQ(mortonEncode3(0, 1, 0), 2u);
  EXPECT_EQ(mortonEncode3(0, 0, 1), 4u);
  EXPECT_EQ(mortonEncode3(1023, 1023, 1023), (1u << 30) - 1);
}

TEST(PresenceOctree, FindsExactlyTheNonEmptyBricks) {
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    const std::uint32_t maxBricks = 1 + rng() % 40;
    std::set<std::uint32_t> codes;
    const int count = int(rng() % 200);
    for (int i = 0; i < count; ++i) codes.insert(mortonEncode3(rng() % maxBricks, rng() % maxBricks, rng() % maxBricks));
    std::vector<std::uint32_t> sorted(codes.begin(), codes.end());
    const PresenceOctree tree = PresenceOctree::build(sorted, maxBricks);
    EXPECT_EQ(tree.levels, octreeLevelsFor(maxBricks));
    EXPECT_GE(1u << tree.levels, maxBricks);
    for (std::uint32_t x = 0; x < maxBricks; ++x)
      for (std::uint32_t y = 0; y < maxBricks; ++y)
        for (std::uint32_t z = 0; z < maxBricks; ++z) {
          auto it = std::lower_bound(sorted.begin(), sorted.end(), mortonEncode3(x, y, z));
          const std::int64_t expected =
              (it != sorted.end() && *it == mortonEncode3(x, y, z)) ? std::int64_t(it - sorted.begin()) : -1;
          ASSERT_EQ(tree.find({x, y, z}), expected) << "seed " << seed << " brick " << x << "," << y << "," << z;
        }
  }
}

TEST(PresenceOctree, EveryNodeMaskBitHasANonEmptySubtree) {
  std::mt19937 rng(3);
  std::set<std::uint32_t> codes;
  for (int i = 0; i < 500; ++i) codes.insert(mortonEncode3(rng() % 64, rng() % 64, rng() % 64));
  std::vector<std::uint32_t> sorted(codes.begin(), codes.end());
  const PresenceOctree tree = PresenceOctree::build(sorted, 64);
  // Walk every node; count leaves reached: must equal the brick count, each once.
  std::vector<int> seen(sorted.size(), 0);
  struct Item {
    std::uint32_t node, level;
  };
  std::vector<Item> stack{{0, 0}};
  while (!stack.empty()) {
    auto [node, level] = stack.back();
    stack.pop_back();
    const OctreeNode& n = tree.nodes[node];
    ASSERT_NE(n.childMask, 0u);
    for (int c = 0; c < std::popcount(n.childMask); ++c) {
      if (level + 1 == tree.levels) ++seen.at(n.firstChild + c);
      else stack.push_back({n.firstChild + std::uint32_t(c), level + 1});
    }
  }
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int s) { return s == 1; }));
}

TEST(PresenceOctree, EmptyFrameHasNoNodes) {
  const PresenceOctree tree = PresenceOctree::build({}, 16);
  EXPECT_TRUE(tree.nodes.empty());
  EXPECT_EQ(tree.find({0, 0, 0}), -1);
}

}  // namespace
}  // namespace flipscope
