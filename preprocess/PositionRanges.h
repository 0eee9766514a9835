// PositionRanges: one read of every particle's position of a source, ranges of it on every core
// at once, for the passes over a frame that need the positions alone and in no order: the spacing
// estimate's neighbour search (ParticleSpacing.h) and convert's bounds scan. Only for sources that
// seek to a particle cheaply (ParticleSource::readPositionRange: raw and binary PLY, fixed-size
// records of an uncompressed file); the others are read in order by their callers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>

#include <glm/vec3.hpp>

#include "core/Progress.h"
#include "preprocess/particles/ParticleSource.h"

namespace flipscope {

/// Particles a range holds: 768 KiB of positions per core at a time.
inline constexpr std::size_t kPositionRangeParticles = std::size_t(1) << 16;

/// The positions of particles [first, first + positions.size()) of a source.
using PositionRangeVisitor = std::function<void(std::span<const glm::vec3> positions, std::uint64_t first)>;

/// Calls `visit` once for each of the consecutive ranges of kPositionRangeParticles particles
/// (the last one shorter) that cover `source` (countHint()), several at once on different
/// threads, and returns true; returns false, reading nothing and calling nothing, unless the
/// source knows its count and reads ranges (readPositionRange). `visit` may run parallel work of
/// its own: a range's positions stay as read until its visit returns. Progress, when given,
/// advances by each range read. The source's next read() stays where it was. Throws FileError
/// like the source, what `visit` throws, and LogicError when the source stops reading ranges
/// part way.
bool readPositionRangesInParallel(ParticleSource& source, const PositionRangeVisitor& visit,
                                  Progress* progress = nullptr);

}  // namespace flipscope
