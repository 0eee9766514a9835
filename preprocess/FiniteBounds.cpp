#include "preprocess/FiniteBounds.h"

#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

namespace flipscope {

FiniteBounds finiteBounds(std::span<const glm::vec3> positions) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, positions.size(), 1 << 14), FiniteBounds{},
      [&](const auto& range, FiniteBounds t) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          const glm::vec3 p = positions[i];
          if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))
            ++t.finite, t.bounds.extend(glm::dvec3(p));
        }
        return t;
      },
      [](FiniteBounds a, const FiniteBounds& b) {
        a.finite += b.finite;
        a.bounds.extend(b.bounds);
        return a;
      });
}

}  // namespace flipscope
