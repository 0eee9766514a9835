// Presence octree construction over Morton-sorted bricks (Reichl et al. 2014 §3, Fig. 2).
#include "preprocess/store/PresenceOctree.h"

#include <bit>

#include "core/Error.h"
#include "core/Morton.h"

namespace flipscope {

std::uint32_t octreeLevelsFor(std::uint32_t maxBricks) {
  std::uint32_t levels = 1;
  while ((1u << levels) < maxBricks) ++levels;
  return levels;
}

PresenceOctree PresenceOctree::build(const std::vector<std::uint32_t>& codes, std::uint32_t maxBricks) {
  FLIPSCOPE_CHECK(maxBricks <= kMortonAxisLimit, "maxBricks=" << maxBricks);
  PresenceOctree tree;
  tree.levels = octreeLevelsFor(maxBricks);
  if (codes.empty()) return tree;
  const std::uint32_t levels = tree.levels;

  struct Range {
    std::size_t begin, end;
  };
  std::vector<Range> current{{0, codes.size()}};
  std::size_t levelStart = 0;
  tree.nodes.resize(1);
  for (std::uint32_t level = 0; level < levels; ++level) {
    const std::uint32_t shift = 3 * (levels - 1 - level);
    const bool childrenAreBricks = level + 1 == levels;
    const std::size_t nextStart = levelStart + current.size();
    std::vector<Range> next;
    for (std::size_t i = 0; i < current.size(); ++i) {
      OctreeNode& node = tree.nodes[levelStart + i];
      node.firstChild = std::uint32_t(childrenAreBricks ? current[i].begin : nextStart + next.size());
      for (std::size_t b = current[i].begin; b < current[i].end;) {
        std::uint32_t octant = (codes[b] >> shift) & 7u;
        std::size_t e = b + 1;
        while (e < current[i].end && ((codes[e] >> shift) & 7u) == octant) ++e;
        FLIPSCOPE_CHECK(!(node.childMask & (1u << octant)), "brick codes not sorted or not unique");
        node.childMask |= 1u << octant;
        if (childrenAreBricks) {
          FLIPSCOPE_CHECK(e == b + 1, "duplicate brick code " << codes[b]);
        } else {
          next.push_back({b, e});
        }
        b = e;
      }
    }
    if (!childrenAreBricks) tree.nodes.resize(nextStart + next.size());
    levelStart = nextStart;
    current = std::move(next);
  }
  return tree;
}

std::int64_t PresenceOctree::find(glm::uvec3 coord) const {
  if (nodes.empty() || levels == 0) return -1;
  if (coord.x >= (1u << levels) || coord.y >= (1u << levels) || coord.z >= (1u << levels)) return -1;
  const std::uint32_t code = mortonEncode3(coord.x, coord.y, coord.z);
  std::uint32_t index = 0;
  for (std::uint32_t level = 0; level < levels; ++level) {
    const OctreeNode& node = nodes[index];
    const std::uint32_t octant = (code >> (3 * (levels - 1 - level))) & 7u;
    if (!(node.childMask & (1u << octant))) return -1;
    const std::uint32_t rank = std::popcount(node.childMask & ((1u << octant) - 1u));
    if (level + 1 == levels) return std::int64_t(node.firstChild) + rank;
    index = node.firstChild + rank;
  }
  return -1;
}

}  // namespace flipscope
