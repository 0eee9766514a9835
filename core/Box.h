// Axis-aligned boxes in world units (double precision: domains of 4096^3 cells and more keep
// sub-cell accuracy).
#pragma once

#include <algorithm>
#include <limits>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

namespace flipscope {

struct Box {
  glm::dvec3 min{std::numeric_limits<double>::infinity()};
  glm::dvec3 max{-std::numeric_limits<double>::infinity()};

  bool isEmpty() const { return !(min.x <= max.x && min.y <= max.y && min.z <= max.z); }
  void extend(const glm::dvec3& p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  void extend(const Box& b) {
    min = glm::min(min, b.min);
    max = glm::max(max, b.max);
  }
  glm::dvec3 extent() const { return max - min; }
  bool contains(const glm::dvec3& p) const {
    return p.x >= min.x && p.y >= min.y && p.z >= min.z && p.x <= max.x && p.y <= max.y && p.z <= max.z;
  }
};

}  // namespace flipscope
