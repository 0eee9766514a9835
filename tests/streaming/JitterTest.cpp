// TEA and cell jitter (streaming/glsl/Jitter.glsl). The reference values below are shared with
// the GLSL side: a compute-shader test must reproduce them bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "streaming/Jitter.h"
#include "streaming/JitterReferences.h"

namespace flipscope {
namespace {

// Textbook TEA encryption (Wheeler and Needham 1994) with an explicit key, 32 rounds.
glm::uvec2 teaTextbook(glm::uvec2 v, const std::uint32_t key[4], std::uint32_t rounds) {
  std::uint32_t v0 = v.x, v1 = v.y, sum = 0;
  for (std::uint32_t n = 0; n < rounds; ++n) {
    sum += 0x9e3779b9u;
    v0 += ((v1 << 4) + key[0]) ^ (v1 + sum) ^ ((v1 >> 5) + key[1]);
    v1 += ((v0 << 4) + key[2]) ^ (v0 + sum) ^ ((v0 >> 5) + key[3]);
  }
  return {v0, v1};
}

TEST(Tea, TextbookMatchesPublishedTestVector) {
  const std::uint32_t zeroKey[4] = {0, 0, 0, 0};
  EXPECT_EQ(teaTextbook({0, 0}, zeroKey, 32), glm::uvec2(0x41ea3a0au, 0x94baa940u));
}

TEST(Tea, IsTextbookTeaWithTheGpuKey) {
  const std::uint32_t gpuKey[4] = {0xa341316cu, 0xc8013ea4u, 0xad90777du, 0x7e95761eu};
  std::mt19937 rng(3);
  for (std::uint32_t rounds : {1u, 4u, 8u, 32u})
    for (int i = 0; i < 100; ++i) {
      glm::uvec2 v(rng(), rng());
      EXPECT_EQ(tea(v, rounds), teaTextbook(v, gpuKey, rounds));
    }
}

TEST(Tea, ReferenceValues) {
  for (const auto& r : testing::kTeaReferences) EXPECT_EQ(tea(r.input, r.rounds), r.output);
}

TEST(CellJitter, ReferenceValues) {
  for (const auto& r : testing::kJitterReferences) EXPECT_EQ(cellJitter(r.cell, r.timeStep, r.maxJitter), r.offset);
}

TEST(CellJitter, BoundedAndRoughlyUniform) {
  std::mt19937 rng(11);
  const float maxJitter = 0.75f;
  glm::dvec3 sum(0), sumSq(0);
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    glm::uvec3 cell(rng() % (1u << 17), rng() % (1u << 17), rng() % (1u << 17));
    glm::vec3 j = cellJitter(cell, rng() % 1000, maxJitter);
    for (int a = 0; a < 3; ++a) {
      ASSERT_GE(j[a], -maxJitter);
      ASSERT_LT(j[a], maxJitter);
    }
    sum += glm::dvec3(j);
    sumSq += glm::dvec3(j) * glm::dvec3(j);
  }
  glm::dvec3 mean = sum / double(n);
  glm::dvec3 var = sumSq / double(n) - mean * mean;
  double uniformVar = maxJitter * maxJitter / 3.0;
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(mean[a], 0.0, 0.02);
    EXPECT_NEAR(var[a], uniformVar, 0.03 * uniformVar);
  }
}

TEST(CellJitter, NeighbouringCellsAndAxesAreUncorrelated) {
  std::mt19937 rng(5);
  double xy = 0, neighbour = 0, xx = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    glm::uvec3 cell(rng() % 4096, rng() % 4096, rng() % 4096);
    std::uint32_t step = rng() % 100;
    glm::vec3 j = cellJitter(cell, step, 1.0f);
    glm::vec3 k = cellJitter(cell + glm::uvec3(1, 0, 0), step, 1.0f);
    xy += j.x * j.y;
    neighbour += j.x * k.x;
    xx += j.x * j.x;
  }
  EXPECT_LT(std::abs(xy / xx), 0.05);
  EXPECT_LT(std::abs(neighbour / xx), 0.05);
}

TEST(CellJitter, DependsOnCellHighBitsAndTimeStep) {
  // Cells that share their low 10 bits per axis, and consecutive time steps, jitter differently.
  glm::uvec3 cell(5, 700, 1023);
  glm::vec3 base = cellJitter(cell, 9, 1.0f);
  EXPECT_NE(base, cellJitter(cell + glm::uvec3(1024, 0, 0), 9, 1.0f));
  EXPECT_NE(base, cellJitter(cell + glm::uvec3(0, 0, 1u << 16), 9, 1.0f));
  EXPECT_NE(base, cellJitter(cell, 10, 1.0f));
  EXPECT_EQ(base, cellJitter(cell, 9, 1.0f));
  EXPECT_NE(base.x, base.y);
}

}  // namespace
}  // namespace flipscope
