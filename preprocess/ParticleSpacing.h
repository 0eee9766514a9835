// ParticleSpacing: how far apart a cache's particles are. `convert` makes one cell per particle
// spacing when neither --cell-size nor --resolution is given, and records the spacing in the
// store (StoreHeader::particleSpacing) for render to size its splats by.
//
// Contract. The spacing is the cube root of the volume per particle, (V / N)^(1/3), in world
// units: s for particles on a cubic lattice of spacing s, dx / 2 for a FLIP solver's 8 particles
// per cell of size dx. Two estimates of it:
//  - metadata (ParticleSource::spacingHint(), nothing read): OpenVDB points grids, the volume of
//    the active voxels over the points they hold, i.e. voxelSize / cbrt(points per active voxel);
//  - neighbours (any source): a uniform random sample of up to kSpacingSample finite particles
//    (reservoir sampling, Li's algorithm L, with a fixed seed: deterministic; from a source that
//    seeks to a particle, ParticleSource::readPositionsAt, drawn by number among all its
//    particles, the non-finite ones drawn then dropped); for each sampled
//    particle, the distance r to its kSpacingNeighbour-th nearest neighbour among all the source's particles
//    (exact, not among the sample only); spacing = median(r) * cbrt(4 pi / (3 k)), the spacing at
//    which a ball of radius r holds k particles. Within about 2 % of s on a cubic lattice
//    (r = sqrt(2) s at k = 12), on jittered lattices and on uniform random points. The plain
//    nearest-neighbour distance is not used: it depends on the arrangement (s on a lattice,
//    0.55 s for random points) and does not match the metadata estimate.
// Both overestimate where particles are sparse (spray, thin sheets: a voxel or a ball partly
// empty); the median keeps a minority of such particles from mattering.
// Non-finite positions are skipped. The estimate is unknown (spacing 0) with fewer than k + 1
// finite particles, when the median neighbour distance is 0 (coincident particles), or when it is
// not found within kSpacingMaxPasses reads of the source.
// Cost of the neighbour estimate: one read of the source when it has at most kSpacingSample
// particles or seeks to a particle (raw, binary PLY: the sample costs kSpacingSample small
// reads, asked of the disk all at once), else two (rarely more); memory O(kSpacingSample) plus one chunk of particles,
// plus at most about 25 MiB, whatever the frame's size, for the search's cells near the sample: at most 4 MiB of bits
// and 2 MiB of their ranks and, per cell within the search radius of a sampled particle (at most 64 each), the list of
// those particles; where the sample lies far apart (two tanks, a particle flung far away), instead of the ranks, up to
// 20 MiB of (cell, particle) pairs while the lists of cells of the radius are made. The time stays about that of a read
// of the frame however far apart its particles lie. The source is rewound afterwards.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string>

#include <glm/vec3.hpp>

#include "core/Box.h"
#include "core/Progress.h"
#include "preprocess/particles/ParticleSource.h"

namespace flipscope {

/// The neighbour estimate's sample. Its median's sampling error is a few tenths of a percent at
/// this size, a tenth of the method's own 2 %: against 20000 (until 2026-12-06) the estimate moved
/// 0.055 % on the 20 M particle synth frame and 0.02 % on the 100 M one, while the spacing pass
/// of the 20 M PLY took 0.10 s instead of 0.15 s (the sample's reads, its own search and the
/// lists are fixed costs; 10000: 0.12 s).
inline constexpr std::size_t kSpacingSample = 5000;
inline constexpr int kSpacingNeighbour = 12;
inline constexpr int kSpacingMaxPasses = 6;

struct SpacingEstimate {
  double spacing = 0;  ///< world units; 0 = unknown
  std::string origin;  ///< how it was found, for messages (or why it is unknown)
  /// The bounds of the source's finite particles when the estimate read every particle (the
  /// neighbour estimate's sampling pass), so that convert need not read them again; else nullopt.
  std::optional<Box> bounds;
  /// The box of the particles the neighbour estimate sampled, where it sampled fewer than all:
  /// where most of them lie (a particle flung far away is seldom among them); else nullopt.
  std::optional<Box> sampledBounds;
  bool known() const { return spacing > 0; }
};

/// The metadata estimate when `source` has a spacing hint (nothing is read), else the
/// neighbour estimate. Progress, when given, advances by the particles read.
SpacingEstimate estimateParticleSpacing(ParticleSource& source, Progress* progress = nullptr);

/// The metadata estimate of a hint; unknown unless finite and positive.
SpacingEstimate hintSpacing(const SpacingHint& hint);

/// The neighbour estimate over every particle of `source` (see above), whatever its metadata.
SpacingEstimate neighbourSpacing(ParticleSource& source, std::size_t sampleSize = kSpacingSample,
                                 Progress* progress = nullptr);
/// The neighbour estimate over points in memory.
SpacingEstimate neighbourSpacing(std::span<const glm::vec3> points, std::size_t sampleSize = kSpacingSample);

namespace detail {
/// The search under the neighbour estimate: for each query, the distance to its
/// kSpacingNeighbour-th nearest candidate, +inf where that lies beyond `radius`. Candidate i
/// has id i; a candidate with a query's id is that query itself and does not count.
std::vector<double> kthNeighbourDistances(std::span<const glm::vec3> queries, std::span<const std::uint64_t> queryIds,
                                          std::span<const glm::vec3> candidates, double radius);
/// The search among the sample itself (queries and candidates the same points, a point not its
/// own neighbour): kthNeighbourDistances(points, 0..n-1, points, radius), found without lists of
/// queries by cell. Every try of the estimate's median within its sample runs it.
std::vector<double> kthNeighbourDistancesAmong(std::span<const glm::vec3> points, double radius);
}  // namespace detail

}  // namespace flipscope
