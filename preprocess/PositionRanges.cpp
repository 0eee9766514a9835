#include "preprocess/PositionRanges.h"

#include <algorithm>
#include <optional>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "core/Error.h"

namespace flipscope {

bool readPositionRangesInParallel(ParticleSource& source, const PositionRangeVisitor& visit, Progress* progress) {
  const std::optional<std::uint64_t> count = source.countHint();
  std::vector<glm::vec3> none;
  if (!count || !source.readPositionRange(0, 0, none)) return false;
  tbb::enumerable_thread_specific<std::vector<glm::vec3>> buffers;
  const std::uint64_t ranges = (*count + kPositionRangeParticles - 1) / kPositionRangeParticles;
  tbb::parallel_for(tbb::blocked_range<std::uint64_t>(0, ranges, 1), [&](const auto& r) {
    // Isolated: a visit that runs parallel work of its own (finiteBounds does) must not wait for
    // it by taking another range, which would read into this thread's buffer while the visit's
    // tasks still read it.
    tbb::this_task_arena::isolate([&] {
      std::vector<glm::vec3>& positions = buffers.local();
      for (std::uint64_t i = r.begin(); i != r.end(); ++i) {
        const std::uint64_t first = i * kPositionRangeParticles;
        const std::size_t n = std::size_t(std::min<std::uint64_t>(kPositionRangeParticles, *count - first));
        if (!source.readPositionRange(first, n, positions))
          throw LogicError(source.name() + ": the source stopped reading ranges of particles");
        visit(positions, first);
        if (progress) progress->advance(n);
      }
    });
  });
  return true;
}

}  // namespace flipscope
