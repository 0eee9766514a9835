// PresenceOctree: the octree over a frame's non-empty bricks that lets ray casting skip empty
// space (Reichl et al. 2014 §3, Fig. 2). Built over bricks sorted by Morton code.
//
// Layout (shared with the GPU as std430 uvec2[]): nodes breadth-first, root at index 0.
// A node's childMask bit c (c = x | y << 1 | z << 2 for the child's octant) is set when that
// child's subtree holds a non-empty brick; its children are stored contiguously from
// firstChild, in ascending c, one per set bit. At the last internal level (level
// levels - 1) "children" are bricks: firstChild indexes the brick table. A frame without
// bricks has an empty node array. The root covers 2^levels bricks per axis.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

namespace flipscope {

struct OctreeNode {
  std::uint32_t childMask = 0;
  std::uint32_t firstChild = 0;
  bool operator==(const OctreeNode&) const = default;
};
static_assert(sizeof(OctreeNode) == 8, "OctreeNode mirrors a std430 uvec2");

struct PresenceOctree {
  std::uint32_t levels = 0;  ///< internal levels; root covers (1 << levels) bricks per axis
  std::vector<OctreeNode> nodes;

  /// Builds the octree over brick Morton codes (ascending, unique) for a grid whose largest
  /// axis has `maxBricks` bricks.
  static PresenceOctree build(const std::vector<std::uint32_t>& sortedBrickMorton, std::uint32_t maxBricks);
  /// Index of the brick at `coord` in the brick table, or -1 when the brick is empty.
  std::int64_t find(glm::uvec3 coord) const;
};

/// Internal levels needed for a grid with `maxBricks` bricks along its largest axis.
std::uint32_t octreeLevelsFor(std::uint32_t maxBricks);

}  // namespace flipscope
