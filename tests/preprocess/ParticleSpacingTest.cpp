// The particle spacing estimates (ParticleSpacing.h): the neighbour estimate on point sets of
// known spacing, in memory and streamed (sampled), and on the Mantaflow sample against the
// OpenVDB metadata estimate of the same points.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numeric>
#include <random>
#include <span>

#include <glm/common.hpp>

#include "TestSupport.h"
#include "VectorSource.h"
#include "preprocess/ParticleSpacing.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;

/// n^3 particles on a cubic lattice of `spacing` from `origin`, each moved by up to
/// jitter * spacing / 2 along every axis (uniform), shuffled (a file order without locality).
std::vector<glm::vec3> lattice(int n, float spacing, float jitter, glm::vec3 origin = {-1.3f, 0.7f, 2.1f},
                               unsigned seed = 5) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-0.5f, 0.5f);
  std::vector<glm::vec3> points;
  for (int x = 0; x < n; ++x)
    for (int y = 0; y < n; ++y)
      for (int z = 0; z < n; ++z)
        points.push_back(origin + spacing * glm::vec3(x + jitter * u(rng), y + jitter * u(rng), z + jitter * u(rng)));
  std::shuffle(points.begin(), points.end(), rng);
  return points;
}

/// Each query's 12th smallest float squared distance to a candidate that is not itself (by id),
/// by comparing every pair (the search's float arithmetic).
std::vector<float> kthSquaredByEveryPair(std::span<const glm::vec3> queries, std::span<const std::uint64_t> ids,
                                         std::span<const glm::vec3> candidates) {
  std::vector<float> kth2;
  std::vector<float> d2(candidates.size());
  for (std::size_t q = 0; q < queries.size(); ++q) {
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      const glm::vec3 d = queries[q] - candidates[c];
      d2[c] = c == ids[q] ? std::numeric_limits<float>::infinity() : d.x * d.x + d.y * d.y + d.z * d.z;
    }
    std::nth_element(d2.begin(), d2.begin() + (kSpacingNeighbour - 1), d2.end());
    kth2.push_back(d2[kSpacingNeighbour - 1]);
  }
  return kth2;
}

/// What the search must give a query whose 12th squared distance is kth2, at `radius`.
double expectedKth(float kth2, double radius) {
  return double(kth2) <= radius * radius ? std::sqrt(double(kth2)) : std::numeric_limits<double>::infinity();
}

TEST(ParticleSpacing, RegularLatticeGivesItsSpacing) {
  for (float spacing : {0.1f, 2.5f}) {
    const auto points = lattice(17, spacing, 0);  // 4913 particles, within kSpacingSample: every one a query
    const SpacingEstimate e = neighbourSpacing(points);
    ASSERT_TRUE(e.known()) << e.origin;
    EXPECT_NEAR(e.spacing, spacing, 0.03 * spacing) << e.origin;
    EXPECT_NE(e.origin.find("all 4913 particles"), std::string::npos) << e.origin;
  }
}

TEST(ParticleSpacing, JitteredAndRandomPointsGiveTheirSpacing) {
  // One particle per cell anywhere in it (jitter 1), half-cell jitter, and uniform random points
  // at the same density: the volume per particle is spacing^3 in every case.
  for (float jitter : {0.5f, 1.0f}) {
    const SpacingEstimate e = neighbourSpacing(lattice(26, 0.04f, jitter));
    ASSERT_TRUE(e.known()) << e.origin;
    EXPECT_NEAR(e.spacing, 0.04, 0.05 * 0.04) << "jitter " << jitter << ": " << e.origin;
  }
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0, 30 * 0.2f);
  std::vector<glm::vec3> random(30 * 30 * 30);
  for (auto& p : random) p = {u(rng), u(rng), u(rng)};
  const SpacingEstimate e = neighbourSpacing(random);
  ASSERT_TRUE(e.known()) << e.origin;
  EXPECT_NEAR(e.spacing, 0.2, 0.05 * 0.2) << e.origin;
}

TEST(ParticleSpacing, TheSearchFindsTheKthNeighboursOfComparingEveryPair) {
  // The search under every estimate (detail::kthNeighbourDistances): each query's 12th-neighbour
  // distance, +inf beyond the radius, must be the one of comparing every pair (the same float
  // arithmetic), on clusters of different densities over a sparse background, at radii around
  // the median distance. The search turns candidates away by their cells' lists before it measures;
  // turning away one within the radius changes that query's distance.
  std::mt19937 rng(21);
  std::vector<glm::vec3> candidates;
  for (const float spread : {0.05f, 0.2f, 0.6f}) {
    std::normal_distribution<float> blob(0.0f, spread);
    const glm::vec3 centre(spread * 10, 1.0f, -spread * 5);
    for (int i = 0; i < 6000; ++i) candidates.push_back(centre + glm::vec3(blob(rng), blob(rng), blob(rng)));
  }
  std::uniform_real_distribution<float> background(-3.0f, 8.0f);
  for (int i = 0; i < 2000; ++i) candidates.push_back({background(rng), background(rng), background(rng)});
  std::vector<glm::vec3> queries;
  std::vector<std::uint64_t> ids;
  for (std::size_t i = 0; i < candidates.size(); i += 11) {
    queries.push_back(candidates[i]);
    ids.push_back(i);
  }
  for (int i = 0; i < 50; ++i) {  // queries that are no candidate
    queries.push_back({background(rng), background(rng), background(rng)});
    ids.push_back(candidates.size() + std::size_t(i));
  }

  const std::vector<float> kth2 = kthSquaredByEveryPair(queries, ids, candidates);
  std::vector<float> sorted = kth2;
  std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(sorted.size() / 2), sorted.end());
  const double median = std::sqrt(double(sorted[sorted.size() / 2]));

  for (const double radius : {0.4 * median, median, 2.5 * median}) {
    const std::vector<double> found = detail::kthNeighbourDistances(queries, ids, candidates, radius);
    ASSERT_EQ(found.size(), queries.size());
    std::size_t within = 0;
    for (std::size_t q = 0; q < queries.size(); ++q) {
      const double expected = expectedKth(kth2[q], radius);
      within += std::isfinite(expected);
      ASSERT_EQ(found[q], expected) << "query " << q << " at radius " << radius;
    }
    EXPECT_GT(within, 0u);
    EXPECT_LT(within, queries.size()) << "some queries' 12th neighbour lies beyond the radius";
  }
}

TEST(ParticleSpacing, TheSearchOfQueriesFarApartKeepsCellsOfTheRadius) {
  // Two lattices 10^4 apart (two tanks), and one query flung between them: a grid of cells of the
  // radius over the queries' box would be too large, and the bits' cells are coarser than two
  // radii, so the lists are of cells of the radius again, hashed (buildFineLists). Each query's
  // 12th-neighbour distance must still be the one of comparing every pair.
  std::vector<glm::vec3> candidates = lattice(12, 0.25f, 0.0f, glm::vec3(0.0f));
  const std::vector<glm::vec3> far = lattice(12, 0.25f, 0.6f, glm::vec3(1.0e4f, 0.0f, 5.0e3f), 9);
  candidates.insert(candidates.end(), far.begin(), far.end());
  std::vector<glm::vec3> queries;
  std::vector<std::uint64_t> ids;
  for (std::size_t i = 0; i < candidates.size(); i += 7) {
    queries.push_back(candidates[i]);
    ids.push_back(i);
  }
  queries.push_back(glm::vec3(4.0e3f));
  ids.push_back(candidates.size());
  const std::vector<float> kth2 = kthSquaredByEveryPair(queries, ids, candidates);
  // The 12th neighbour on the lattice is sqrt(2) spacings away: none within 0.3, on the cells'
  // faces at sqrt(2) / 4 (the plain lattice), most within 0.4.
  for (const double radius : {0.3, std::sqrt(2.0) * 0.25, 0.4}) {
    const std::vector<double> found = detail::kthNeighbourDistances(queries, ids, candidates, radius);
    std::size_t within = 0;
    for (std::size_t q = 0; q < queries.size(); ++q) {
      within += std::isfinite(found[q]);
      ASSERT_EQ(found[q], expectedKth(kth2[q], radius)) << "query " << q << " at radius " << radius;
    }
    if (radius == 0.4) {
      EXPECT_GT(within, queries.size() / 2);
    }
  }
}

TEST(ParticleSpacing, TheSearchAmongTheSampleFindsWhatTheSearchOfQueriesFinds) {
  // The estimate's start (the median within the sample) searches the sampled points among
  // themselves (detail::kthNeighbourDistancesAmong). It must give each point the distance the
  // search of queries gives it with the same points as candidates, bit for bit: on clusters of
  // different densities, a sheet, coincident points and a lattice whose neighbours lie exactly
  // a radius (and a cell face) apart; at radii far below the spacing (whose cells it coarsens),
  // around it, and beyond the spread.
  std::mt19937 rng(5);
  std::vector<glm::vec3> points;
  for (const float spread : {0.03f, 0.3f}) {
    std::normal_distribution<float> blob(0.0f, spread);
    for (int i = 0; i < 1500; ++i)
      points.push_back(glm::vec3(spread * 8, 0, 0) + glm::vec3(blob(rng), blob(rng), blob(rng)));
  }
  std::uniform_real_distribution<float> sheet(-2.0f, 2.0f);
  for (int i = 0; i < 800; ++i) points.push_back({sheet(rng), 3.0f, sheet(rng)});
  for (int i = 0; i < 20; ++i) points.push_back(points[std::size_t(i) * 7]);  // coincident
  for (int x = 0; x < 6; ++x)
    for (int y = 0; y < 6; ++y)
      for (int z = 0; z < 6; ++z) points.push_back(glm::vec3(-5.0f) + 0.25f * glm::vec3(x, y, z));
  std::vector<std::uint64_t> ids(points.size());
  std::iota(ids.begin(), ids.end(), 0);
  for (const double radius : {1e-4, 0.02, 0.25, 0.5, 3.0, 40.0}) {
    const std::vector<double> among = detail::kthNeighbourDistancesAmong(points, radius);
    const std::vector<double> expected = detail::kthNeighbourDistances(points, ids, points, radius);
    ASSERT_EQ(among.size(), points.size());
    std::size_t within = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      within += std::isfinite(expected[i]);
      ASSERT_EQ(among[i], expected[i]) << "point " << i << " at radius " << radius;
    }
    if (radius == 0.25) {
      EXPECT_GT(within, 0u);
      EXPECT_LT(within, points.size());
    }
  }
  // Groups of 12 coincident points and one exactly a radius (0.25) along x: the 12th neighbour of
  // each point is 0.25 away. The groups start at every 4096th of a radius along x, so some lie
  // just below a cell face and their 12th neighbour just above the next one.
  std::vector<glm::vec3> groups;
  for (int i = 0; i <= 4096; ++i) {
    const glm::vec3 base(float(i) / 16384.0f, 0.75f * float(i), 0.0f);
    for (int c = 0; c < kSpacingNeighbour; ++c) groups.push_back(base);
    groups.push_back(base + glm::vec3(0.25f, 0.0f, 0.0f));
  }
  const std::vector<double> grouped = detail::kthNeighbourDistancesAmong(groups, 0.25);
  for (std::size_t i = 0; i < groups.size(); ++i) ASSERT_EQ(grouped[i], 0.25) << "point " << i;
  // The same with one point flung far away, so that the cells of the radius are too many to keep
  // a table of (the occupied ones are hashed instead), in both searches.
  std::vector<glm::vec3> flung = groups;
  flung.push_back(glm::vec3(1.0e4f));
  const std::vector<double> far = detail::kthNeighbourDistancesAmong(flung, 0.25);
  for (std::size_t i = 0; i < groups.size(); ++i) ASSERT_EQ(far[i], 0.25) << "point " << i << ", one flung far";
  EXPECT_EQ(far.back(), std::numeric_limits<double>::infinity());
  std::vector<std::uint64_t> flungIds(flung.size());
  std::iota(flungIds.begin(), flungIds.end(), 0);
  const std::vector<double> farOfQueries = detail::kthNeighbourDistances(flung, flungIds, flung, 0.25);
  for (std::size_t i = 0; i < flung.size(); ++i)
    ASSERT_EQ(farOfQueries[i], far[i]) << "point " << i << ", one flung far, the search of queries";
  // Scaled by 2^-70 the squared distances are subnormal floats, rounded to 3 % of them: groups
  // whose 13th point lies 0.4 % beyond the radius still count it, as the search of queries does,
  // though from just below a cell face it lies two cells of the radius on.
  std::vector<glm::vec3> tiny;
  for (int i = 0; i <= 4096; ++i) {
    const glm::vec3 base(float(i) / 16384.0f, 0.75f * float(i), 0.0f);
    for (int c = 0; c < kSpacingNeighbour; ++c) tiny.push_back(std::ldexp(1.0f, -70) * base);
    tiny.push_back(std::ldexp(1.0f, -70) * (base + glm::vec3(0.25f + 0x1p-10f, 0.0f, 0.0f)));
  }
  std::vector<std::uint64_t> tinyIds(tiny.size());
  std::iota(tinyIds.begin(), tinyIds.end(), 0);
  const double tinyRadius = std::ldexp(0.25, -70);
  const std::vector<double> tinyExpected = detail::kthNeighbourDistances(tiny, tinyIds, tiny, tinyRadius);
  ASSERT_TRUE(std::isfinite(tinyExpected.front())) << "the 13th point counts";
  const std::vector<double> tinyFound = detail::kthNeighbourDistancesAmong(tiny, tinyRadius);
  for (std::size_t i = 0; i < tiny.size(); ++i) ASSERT_EQ(tinyFound[i], tinyExpected[i]) << "point " << i << ", scaled";
  EXPECT_EQ(detail::kthNeighbourDistancesAmong(std::span(points).first(kSpacingNeighbour), 40.0),
            std::vector<double>(kSpacingNeighbour, std::numeric_limits<double>::infinity()))
      << "12 points have 11 neighbours each";
}

TEST(ParticleSpacing, TheSearchFindsNeighboursExactlyAtTheRadiusOnTheFacesOfItsCells) {
  // One query at (1, 1, 1), radius 0.5: the search's cells (of the radius, from the query's
  // bounds grown by the radius) have faces through x = 1.5, y = 1.5 and z = 1.5, so
  // the candidates at +0.5 on each axis lie on the near faces of cells exactly 0.5 away. Nine
  // candidates nearer make those three the 10th to 12th neighbours: the 12th distance is 0.5
  // when the cells' lists reach the whole radius, +inf when they stop short of it.
  const glm::vec3 q(1.0f);
  std::vector<glm::vec3> candidates{q + glm::vec3(0.5f, 0, 0), q + glm::vec3(0, 0.5f, 0), q + glm::vec3(0, 0, 0.5f)};
  for (int a = 0; a < 3; ++a) {
    glm::vec3 step(0.0f);
    step[a] = 0.25f;
    candidates.push_back(q + step);
    candidates.push_back(q - step);
    candidates.push_back(q - 1.5f * step);
  }
  const std::vector<glm::vec3> queries{q};
  const std::vector<std::uint64_t> ids{candidates.size()};  // no candidate
  EXPECT_EQ(detail::kthNeighbourDistances(queries, ids, candidates, 0.5), std::vector<double>{0.5});
}

TEST(ParticleSpacing, SampledEstimateReadsEveryParticleForNeighbours) {
  // 40^3 particles, 2000 sampled: neighbours among the sample alone would be 3 times farther.
  const auto points = lattice(40, 0.5f, 0.5f);
  testing::VectorSource source(points);
  const SpacingEstimate e = neighbourSpacing(source, 2000);
  ASSERT_TRUE(e.known()) << e.origin;
  EXPECT_NEAR(e.spacing, 0.5, 0.05 * 0.5) << e.origin;
  EXPECT_NE(e.origin.find("2000 sampled of 64000 particles"), std::string::npos) << e.origin;
  // Deterministic, and the source is rewound.
  EXPECT_EQ(neighbourSpacing(source, 2000).spacing, e.spacing);
  ParticleChunk chunk;
  ASSERT_TRUE(source.read(chunk, 1));
  EXPECT_EQ(chunk.positions[0], points[0]);
}

TEST(ParticleSpacing, SampledEstimateSkipsNonFiniteParticles) {
  // A sampled source (2000 of 64000) with every 7th particle NaN or infinite, in runs that end
  // chunks early and late: the sample is drawn from the finite particles only.
  auto points = lattice(40, 0.5f, 0.5f);
  const std::size_t all = points.size();
  std::size_t bad = 0;
  for (std::size_t i = 3; i < all; i += 7, ++bad)
    points[i] = i % 2 ? glm::vec3(std::numeric_limits<float>::quiet_NaN()) : glm::vec3(0, std::numeric_limits<float>::infinity(), 0);
  testing::VectorSource source(points);
  const SpacingEstimate e = neighbourSpacing(source, 2000);
  ASSERT_TRUE(e.known()) << e.origin;
  // A seventh fewer particles in the same volume: the spacing grows by cbrt(7 / 6).
  EXPECT_NEAR(e.spacing, 0.5 * std::cbrt(7.0 / 6.0), 0.05 * 0.5) << e.origin;
  EXPECT_NE(e.origin.find("2000 sampled of " + std::to_string(all - bad) + " particles"), std::string::npos) << e.origin;
  EXPECT_EQ(neighbourSpacing(source, 2000).spacing, e.spacing) << "deterministic";
}

TEST(ParticleSpacing, ASampleByNumberSavesARead) {
  // A source that seeks to a particle: its sample is drawn by number, and one read of it, by
  // ranges on every core, finds the neighbours, the count and the bounds. Without non-finite
  // particles, the numbers drawn are those of the reservoir over a whole read: the same estimate.
  auto points = lattice(40, 0.5f, 0.5f);
  testing::VectorSource seeking(points), reading(points);
  seeking.seeks = true;
  const SpacingEstimate bySeeking = neighbourSpacing(seeking, 2000);
  const SpacingEstimate byReading = neighbourSpacing(reading, 2000);
  ASSERT_TRUE(bySeeking.known()) << bySeeking.origin;
  EXPECT_EQ(bySeeking.spacing, byReading.spacing);
  EXPECT_EQ(bySeeking.origin, byReading.origin);
  EXPECT_EQ(seeking.particlesRead, 0u);
  EXPECT_EQ(seeking.particlesInRanges, points.size());
  EXPECT_EQ(reading.particlesRead, 2 * points.size());
  ASSERT_TRUE(bySeeking.bounds && byReading.bounds);
  EXPECT_EQ(bySeeking.bounds->min, byReading.bounds->min);
  EXPECT_EQ(bySeeking.bounds->max, byReading.bounds->max);

  // Every 7th particle NaN or infinite: those drawn are dropped from the sample; the count and
  // bounds are of the finite particles.
  std::size_t bad = 0;
  Box finite;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (i % 7 == 3) {
      points[i] = i % 2 ? glm::vec3(std::numeric_limits<float>::quiet_NaN())
                        : glm::vec3(0, std::numeric_limits<float>::infinity(), 0);
      ++bad;
    } else {
      finite.extend(glm::dvec3(points[i]));
    }
  testing::VectorSource holey(points);
  holey.seeks = true;
  const SpacingEstimate e = neighbourSpacing(holey, 2000);
  ASSERT_TRUE(e.known()) << e.origin;
  EXPECT_NEAR(e.spacing, 0.5 * std::cbrt(7.0 / 6.0), 0.05 * 0.5) << e.origin;
  EXPECT_NE(e.origin.find(" sampled of " + std::to_string(points.size() - bad) + " particles"), std::string::npos)
      << e.origin;
  EXPECT_EQ(e.origin.find("2000 sampled"), std::string::npos) << e.origin << ": the non-finite ones drawn are dropped";
  EXPECT_EQ(holey.particlesInRanges, points.size());
  ASSERT_TRUE(e.bounds);
  EXPECT_EQ(e.bounds->min, finite.min);
  EXPECT_EQ(e.bounds->max, finite.max);

  // Too few finite particles among those drawn: the sample of a whole read instead.
  auto sparse = lattice(40, 0.5f, 0.5f);
  for (std::size_t i = 0; i < sparse.size(); ++i)
    if (i % 500) sparse[i] = glm::vec3(std::numeric_limits<float>::quiet_NaN());
  testing::VectorSource few(sparse);
  few.seeks = true;
  const SpacingEstimate fallback = neighbourSpacing(few, 2000);
  EXPECT_NE(fallback.origin.find("all 128 particles"), std::string::npos) << fallback.origin;
}

TEST(ParticleSpacing, FarApartClustersGiveTheSameSpacingAsOne) {
  // Two sampled lattices far apart: the grid of query cells spans more cells than are indexed
  // directly, so the cells are hashed, and candidates are turned away by a bit per cell (500
  // spacings apart: 15 M cells) or by nothing (10^4 apart). The estimate is the one of a
  // lattice alone, since every neighbour lies in its own lattice.
  for (const glm::vec3 offset : {glm::vec3(500, 500, 500), glm::vec3(5000, -3000, 4000)}) {
    auto points = lattice(40, 0.5f, 0.5f);
    const auto far = lattice(40, 0.5f, 0.5f, offset, 9);
    points.insert(points.end(), far.begin(), far.end());
    testing::VectorSource both(points);
    const SpacingEstimate e = neighbourSpacing(both, 2000);
    ASSERT_TRUE(e.known()) << e.origin;
    EXPECT_NEAR(e.spacing, 0.5, 0.05 * 0.5) << e.origin;
    EXPECT_NE(e.origin.find("2000 sampled of 128000 particles"), std::string::npos) << e.origin;
    // The bounds of every finite particle come with the estimate that read them all.
    ASSERT_TRUE(e.bounds);
    Box expected;
    for (const glm::vec3& p : points) expected.extend(glm::dvec3(p));
    EXPECT_EQ(e.bounds->min, expected.min);
    EXPECT_EQ(e.bounds->max, expected.max);
  }
}

TEST(ParticleSpacing, NonFiniteSkippedAndDegenerateInputsUnknown) {
  auto points = lattice(20, 1.0f, 0);
  for (std::size_t i = 0; i < points.size(); i += 7) {
    const float bad = i % 2 ? std::numeric_limits<float>::quiet_NaN() : std::numeric_limits<float>::infinity();
    points.insert(points.begin() + std::ptrdiff_t(i), glm::vec3(1, bad, 1));
  }
  EXPECT_NEAR(neighbourSpacing(points).spacing, 1.0, 0.03);
  EXPECT_NEAR(neighbourSpacing(points, 1000).spacing, 1.0, 0.05);  // sampled: ids count the skipped ones

  EXPECT_FALSE(neighbourSpacing(std::vector<glm::vec3>{}).known());
  const SpacingEstimate few = neighbourSpacing(lattice(2, 1.0f, 0));  // 8 particles < k + 1
  EXPECT_FALSE(few.known());
  EXPECT_NE(few.origin.find("too few"), std::string::npos) << few.origin;
  EXPECT_FALSE(neighbourSpacing(std::vector<glm::vec3>(500, glm::vec3(1, 2, 3))).known());  // all coincide
}

TEST(ParticleSpacing, HintsGiveTheVolumePerParticle) {
  SpacingHint hint{8.0, 1000, "test"};
  EXPECT_DOUBLE_EQ(hintSpacing(hint).spacing, 0.2);
  EXPECT_FALSE(hintSpacing(SpacingHint{1.0, 0, "none"}).known());
  EXPECT_FALSE(hintSpacing(SpacingHint{std::numeric_limits<double>::infinity(), 5, "bad"}).known());
  // Sources without metadata are measured.
  testing::VectorSource source(lattice(16, 0.3f, 0));
  EXPECT_FALSE(source.spacingHint());
  EXPECT_NEAR(estimateParticleSpacing(source).spacing, 0.3, 0.03 * 0.3);
}

TEST(ParticleSpacing, MantaflowVdbMetadataAgreesWithNeighbours) {
  const fs::path path = testing::mantaflowFile("data", "fluid_data_0030.vdb");
  ASSERT_TRUE(fs::exists(path)) << path;
  auto source = openParticleFile(path);
  const auto hint = source->spacingHint();
  ASSERT_TRUE(hint);
  EXPECT_EQ(hint->points, source->countHint());
  EXPECT_NE(hint->origin.find("'particles'"), std::string::npos) << hint->origin;
  const SpacingEstimate vdb = estimateParticleSpacing(*source);
  ASSERT_TRUE(vdb.known());
  // Blender's 64-cell dam break: voxels of 0.0625, about 8 particles a cell where it is full.
  EXPECT_GT(vdb.spacing, 0.0625 / 2 * 0.9);
  EXPECT_LT(vdb.spacing, 0.0625);
  const SpacingEstimate nn = neighbourSpacing(*source);
  ASSERT_TRUE(nn.known()) << nn.origin;
  EXPECT_NEAR(nn.spacing, vdb.spacing, 0.3 * vdb.spacing) << "VDB " << vdb.origin << "; neighbours " << nn.origin;
  std::printf("fluid_data_0030.vdb: VDB estimate %g (%s), neighbour estimate %g (%s)\n", vdb.spacing,
              vdb.origin.c_str(), nn.spacing, nn.origin.c_str());

  // FLIP and secondary particles read as one frame: the hints add up.
  std::vector<std::unique_ptr<ParticleSource>> parts;
  parts.push_back(openParticleFile(path));
  parts.push_back(openParticleFile(testing::mantaflowFile("particles", "fluid_particles_0030.vdb")));
  const auto secondary = parts.back()->spacingHint();
  ASSERT_TRUE(secondary);
  auto both = concatSources(std::move(parts));
  const auto sum = both->spacingHint();
  ASSERT_TRUE(sum);
  EXPECT_EQ(sum->points, hint->points + secondary->points);
  EXPECT_DOUBLE_EQ(sum->volume, hint->volume + secondary->volume);
  // A part without metadata leaves the whole to the neighbour estimate.
  std::vector<std::unique_ptr<ParticleSource>> mixed;
  mixed.push_back(openParticleFile(path));
  mixed.push_back(std::make_unique<testing::VectorSource>(lattice(3, 1.0f, 0)));
  EXPECT_FALSE(concatSources(std::move(mixed))->spacingHint());
}

}  // namespace
}  // namespace flipscope
