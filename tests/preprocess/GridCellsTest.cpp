// GridCells (preprocess/GridCells.h): four particles' cells, in SSE registers on x86-64-v2
// builds, are one() of each, bit for bit, and four() fails exactly where one() fails for one of
// them: non-finite positions, cells past either end of an axis, positions outside the clip box.
// computeKeys, which takes four at a time, keeps what one() keeps, in order, and counts the rest.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include "core/Error.h"
#include "preprocess/BrickBinning.h"
#include "preprocess/Convert.h"
#include "preprocess/GridCells.h"

namespace flipscope {
namespace {

using detail::CellsOfFour;
using detail::GridCells;

/// Coordinates along one axis that a grid from `origin` of `cells` cells of `size` must sort out:
/// cell borders and their float neighbours, both ends, the clip box's ends, beyond, non-finite.
std::vector<float> edgeCoordinates(double origin, double size, std::uint64_t cells, const std::optional<Box>& clip,
                                   int axis) {
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> v{0.0f,
                       -0.0f,
                       std::numeric_limits<float>::denorm_min(),
                       -std::numeric_limits<float>::denorm_min(),
                       std::numeric_limits<float>::max(),
                       -std::numeric_limits<float>::max(),
                       inf,
                       -inf,
                       std::numeric_limits<float>::quiet_NaN(),
                       3e9f,
                       -3e9f};
  for (const double border : {origin, origin + size, origin + size * double(cells / 2), origin + size * double(cells),
                              origin + size * double(cells - 1)}) {
    const auto f = float(border);
    v.insert(v.end(), {f, std::nextafter(f, inf), std::nextafter(f, -inf)});
  }
  if (clip)
    for (const double end : {clip->min[axis], clip->max[axis]}) {
      const auto f = float(end);
      v.insert(v.end(), {f, std::nextafter(f, inf), std::nextafter(f, -inf)});
    }
  return v;
}

void expectFourIsOneOfEach(const GridCells& grid, const glm::vec3* p) {
  CellsOfFour four;
  const bool all = grid.four(p, four);
  bool each = true;
  for (int k = 0; k < 4; ++k) {
    glm::uvec3 cell;
    if (!grid.one(p[k], cell)) {
      each = false;
      continue;
    }
    if (!all) continue;
    EXPECT_EQ(four.x[k], cell.x) << "particle " << k << " at " << p[k].x;
    EXPECT_EQ(four.y[k], cell.y) << "particle " << k << " at " << p[k].y;
    EXPECT_EQ(four.z[k], cell.z) << "particle " << k << " at " << p[k].z;
  }
  EXPECT_EQ(all, each) << p[0].x << " " << p[0].y << " " << p[0].z << " | " << p[1].x << " " << p[1].y << " " << p[1].z
                       << " | " << p[2].x << " " << p[2].y << " " << p[2].z << " | " << p[3].x << " " << p[3].y << " "
                       << p[3].z;
}

TEST(GridCells, FourParticlesCellsAreEachOnesWhereverTheyLie) {
  const glm::dvec3 origin(0.1, -0.2, 0.3);
  const double size = 0.01;
  const glm::u64vec3 cells(100, 50, 120);
  for (const std::optional<Box> clip :
       {std::optional<Box>(), std::optional<Box>(Box{glm::dvec3(0.25, -0.2, 0.5), glm::dvec3(0.75, 0.125, 1.5)})}) {
    const GridCells grid(origin, 1.0 / size, cells, clip);
    std::vector<float> edges[3];
    for (int a = 0; a < 3; ++a) edges[a] = edgeCoordinates(origin[a], size, cells[a], clip, a);
    std::mt19937 rng(11);
    int kept = 0;
    for (int trial = 0; trial < 40000; ++trial) {
      glm::vec3 p[4];
      for (auto& q : p)
        for (int a = 0; a < 3; ++a) {
          // Mostly inside (the clip box and the grid), so that whole fours pass; else an edge.
          if (rng() % 8 != 0) {
            const double low = clip ? clip->min[a] : origin[a];
            const double high = clip ? clip->max[a] : origin[a] + size * double(cells[a]);
            q[a] = float(std::uniform_real_distribution<double>(low, high)(rng));
          } else {
            q[a] = edges[a][rng() % edges[a].size()];
          }
        }
      expectFourIsOneOfEach(grid, p);
      CellsOfFour four;
      kept += grid.four(p, four);
      if (HasFailure()) return;
    }
    EXPECT_GT(kept, 1000) << "whole fours inside: the fast path was tried";
  }
}

TEST(GridCells, EveryEdgeCoordinateInEachLaneIsSortedOutAsOneDoes) {
  // Each edge coordinate on each axis of each of the four particles, the others inside.
  const glm::dvec3 origin(-1.0, 0.0, 2.5);
  const double size = 1.0 / 64;
  const glm::u64vec3 cells(64, 128, 32);
  const std::optional<Box> clip = Box{glm::dvec3(-0.75, 0.0, 2.5), glm::dvec3(-0.0625, 1.5, 2.75)};
  for (const bool clipped : {false, true}) {
    const GridCells grid(origin, 1.0 / size, cells, clipped ? clip : std::nullopt);
    const glm::vec3 inside(-0.5f, 0.75f, 2.625f);
    for (int lane = 0; lane < 4; ++lane)
      for (int a = 0; a < 3; ++a)
        for (const float v : edgeCoordinates(origin[a], size, cells[a], clip, a)) {
          glm::vec3 p[4] = {inside, inside, inside, inside};
          p[lane][a] = v;
          expectFourIsOneOfEach(grid, p);
          if (HasFailure()) return;
        }
  }
}

TEST(GridCells, OneIsTheFlooredCellOfTheDoublePosition) {
  const GridCells grid(glm::dvec3(0.0), 10.0, glm::u64vec3(10, 10, 10), Box{glm::dvec3(0.0), glm::dvec3(0.5)});
  glm::uvec3 cell;
  ASSERT_TRUE(grid.one(glm::vec3(0.0f, 0.25f, 0.5f), cell));
  EXPECT_EQ(cell, glm::uvec3(0, 2, 5));  // 0.25f * 10 = 2.5; 0.5: the clip box's end is inside it
  EXPECT_FALSE(grid.one(glm::vec3(0.0f, 0.25f, std::nextafter(0.5f, 1.0f)), cell));  // past the clip box
  EXPECT_FALSE(grid.one(glm::vec3(-0.0001f, 0.25f, 0.25f), cell));                   // cell -1
  EXPECT_FALSE(grid.one(glm::vec3(std::nanf(""), 0.25f, 0.25f), cell));
  const GridCells unclipped(glm::dvec3(0.0), 10.0, glm::u64vec3(10, 10, 10));
  ASSERT_TRUE(unclipped.one(glm::vec3(0.95f, 0.0f, 0.0f), cell));
  EXPECT_EQ(cell.x, 9u);
  EXPECT_FALSE(unclipped.one(glm::vec3(1.0f, 0.0f, 0.0f), cell));  // cell 10 of 10
}

TEST(GridCells, AGridOfNoCellsOrOfTooManyAlongAnAxisIsRefused) {
  EXPECT_THROW(GridCells(glm::dvec3(0.0), 1.0, glm::u64vec3(0, 4, 4)), LogicError);
  EXPECT_THROW(GridCells(glm::dvec3(0.0), 1.0, glm::u64vec3(4, 4, std::uint64_t(1) << 31)), LogicError);
  EXPECT_NO_THROW(GridCells(glm::dvec3(0.0), 1.0, glm::u64vec3(4, (std::uint64_t(1) << 31) - 1, 4)));
}

TEST(GridCells, ComputeKeysKeepsWhatOneKeepsInOrderWhereverTheSkippedParticlesLie) {
  // Chunks of 1 to 13 particles, a NaN at one place and a particle outside (the grid, or the clip
  // box) at another: in a four, in the tail, or both; narrow keys and 8-byte ones.
  ConvertOptions options;
  options.cellSize = 0.25;
  options.brickSize = 32;
  const StoreHeader header = makeStoreHeader(Box{{0, 0, 0}, {4, 4, 4}}, options, AttributeKind::None);
  for (const std::optional<Box> clip : {std::optional<Box>(), std::optional<Box>(Box{{0, 0, 0}, {2, 4, 4}})}) {
    const detail::KeyGrid grid(header, clip);
    ASSERT_TRUE(grid.narrowKeys());
    const GridCells cells(header.origin, grid.invCellSize, grid.cells, clip);
    for (const bool narrow : {true, false}) {
      for (std::size_t n = 1; n <= 13; ++n) {
        for (std::size_t nan = 0; nan <= n; ++nan) {  // nan == n: none
          const std::size_t outside = (nan * 7 + 3) % (n + 1);
          ParticleChunk chunk;
          for (std::size_t i = 0; i < n; ++i) chunk.positions.push_back(glm::vec3(0.3f + 0.1f * float(i), 1.1f, 3.9f));
          if (nan < n) chunk.positions[nan].y = std::nanf("");
          if (outside < n && outside != nan) chunk.positions[outside].x = clip ? 3.0f : -0.5f;
          std::vector<std::uint64_t> expected;
          std::uint64_t invalid = 0, skipped = 0;
          for (const glm::vec3& p : chunk.positions) {
            glm::uvec3 cell;
            if (!std::isfinite(p.y)) {
              ++invalid;
            } else if (!cells.one(p, cell)) {
              ++skipped;
            } else {
              expected.push_back(grid.axisKeys[0][cell.x] | grid.axisKeys[1][cell.y] | grid.axisKeys[2][cell.z]);
            }
          }
          detail::KeyBatch batch;
          batch.sortRuns = false;  // the keys in the particles' order
          batch.setNarrow(narrow);
          const detail::KeyTally tally = detail::computeKeys(chunk, grid, batch);
          std::vector<std::uint64_t> keys;
          batch.withKeys([&](const auto& v) { keys.assign(v.begin(), v.end()); });
          EXPECT_EQ(keys, expected) << n << " particles, NaN at " << nan << ", outside at " << outside;
          EXPECT_EQ(tally.kept, expected.size());
          EXPECT_EQ(tally.invalid, invalid);
          EXPECT_EQ(tally.outside, skipped);
          if (HasFailure()) return;
        }
      }
    }
  }
}

}  // namespace
}  // namespace flipscope
