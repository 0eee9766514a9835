// finiteBounds against one position at a time: non-finite coordinates anywhere in the groups of
// four the vectorized pass reads, at the ends, in ranges of every length around its blocks.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "preprocess/FiniteBounds.h"

namespace flipscope {
namespace {

FiniteBounds oneAtATime(const std::vector<glm::vec3>& positions) {
  FiniteBounds t;
  for (const glm::vec3& p : positions)
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) ++t.finite, t.bounds.extend(glm::dvec3(p));
  return t;
}

TEST(FiniteBounds, SkipsEveryPositionWithANanOrInfAndBoundsTheRest) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> u(-50.0f, 50.0f);
  const float bad[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                       -std::numeric_limits<float>::infinity()};
  for (const std::size_t n : {0, 1, 3, 4, 5, 7, 8, 9, 16383, 16384, 16385, 50001}) {
    for (const int badEvery : {0, 2, 5, 97}) {
      std::vector<glm::vec3> positions(n);
      for (std::size_t i = 0; i < n; ++i) {
        positions[i] = {u(rng), u(rng), u(rng)};
        if (badEvery && i % std::size_t(badEvery) == 0) positions[i][int(i % 3)] = bad[i % 3];
      }
      if (n > 0 && badEvery) positions.back().z = bad[0];  // the tail after the last group of four
      // The extremes on a position that is dropped must not count: far out, beside a NaN.
      if (n > 8 && badEvery) positions[8] = {1e30f, -1e30f, bad[0]};
      const FiniteBounds expected = oneAtATime(positions), got = finiteBounds(positions);
      EXPECT_EQ(got.finite, expected.finite) << n << " positions, bad every " << badEvery;
      EXPECT_EQ(got.bounds.isEmpty(), expected.bounds.isEmpty()) << n;
      if (!expected.bounds.isEmpty()) {
        EXPECT_EQ(got.bounds.min, expected.bounds.min) << n << " positions, bad every " << badEvery;
        EXPECT_EQ(got.bounds.max, expected.bounds.max) << n << " positions, bad every " << badEvery;
      }
    }
  }
}

TEST(FiniteBounds, OnlyNonFinitePositionsGiveAnEmptyBox) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<glm::vec3> positions(9, glm::vec3(nan, 0.0f, 1.0f));
  const FiniteBounds t = finiteBounds(positions);
  EXPECT_EQ(t.finite, 0u);
  EXPECT_TRUE(t.bounds.isEmpty());
}

}  // namespace
}  // namespace flipscope
