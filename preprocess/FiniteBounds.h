// FiniteBounds: how many of a chunk's positions are finite, and their bounds, in parallel over
// the chunk. What convert's bounds pass and the spacing estimate's sampling pass gather.
#pragma once

#include <cstdint>
#include <span>

#include <glm/vec3.hpp>

#include "core/Box.h"

namespace flipscope {

struct FiniteBounds {
  std::uint64_t finite = 0;  ///< positions with no NaN or Inf coordinate
  Box bounds;                ///< of those (empty when there are none)
};

FiniteBounds finiteBounds(std::span<const glm::vec3> positions);

}  // namespace flipscope
