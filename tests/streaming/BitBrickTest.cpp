// Brick conversion against a brute-force oracle over every stored cell of random neighbourhoods.
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <random>

#include "core/Error.h"
#include "streaming/BitBrick.h"
#include "streaming/RandomBricks.h"

namespace flipscope {
namespace {

// Oracle: the particles of the brick holding `cell`, or nullptr when none.
struct OracleCell {
  bool set = false;
  std::uint16_t mean = 0, max = 0;
};

/// The brick of the neighbourhood holding `cell` (nullptr when absent) and the cell's linear
/// index inside it.
std::pair<const DecodedBrick*, std::uint32_t> locate(const Neighbourhood<DecodedBrick>& bricks, glm::ivec3 cell,
                                                     int brickSize) {
  glm::ivec3 offset(0), local = cell;
  for (int a = 0; a < 3; ++a) {
    if (cell[a] < 0) offset[a] = -1;
    if (cell[a] >= brickSize) offset[a] = 1;
    local[a] = cell[a] - offset[a] * brickSize;
  }
  return {bricks[neighbourIndex(offset.x, offset.y, offset.z)],
          std::uint32_t(local.x + brickSize * (local.y + brickSize * local.z))};
}

OracleCell oracle(const Neighbourhood<DecodedBrick>& bricks, glm::ivec3 cell, int brickSize) {
  const auto [brick, linear] = locate(bricks, cell, brickSize);
  if (!brick) return {};
  // Binary search and a particle prefix scan: no lookup code shared with the converter.
  auto found = std::lower_bound(brick->cells.begin(), brick->cells.end(), linear);
  if (found == brick->cells.end() || *found != linear) return {};
  std::size_t particle = 0;
  for (std::size_t i = 0; i < brick->cells.size(); ++i) {
    if (brick->cells[i] == linear) {
      std::uint64_t sum = 0;
      std::uint16_t largest = 0;
      for (std::uint32_t p = 0; p < brick->counts[i]; ++p) {
        sum += brick->attributes[particle + p];
        largest = std::max(largest, brick->attributes[particle + p]);
      }
      return {true, std::uint16_t(sum / brick->counts[i]), largest};
    }
    particle += brick->counts[i];
  }
  return {};
}

void checkAgainstOracle(std::uint32_t brickSize, std::uint32_t overlap, double fill, AttributeReduction reduction,
                        std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::array<DecodedBrick, 27> storage;
  Neighbourhood<DecodedBrick> bricks{};
  for (int i = 0; i < 27; ++i) {
    if (i != kCentre && rng() % 5 == 0) continue;  // some neighbours are empty
    storage[i] = testing::randomBrick(rng, brickSize, fill);
    bricks[i] = &storage[i];
  }
  BitBrick converted = convertBrick(bricks, {brickSize, overlap, reduction});
  glm::uvec3 dims = bitBrickSubBrickDims(brickSize, overlap);
  ASSERT_EQ(converted.subBricks.size(), std::size_t(dims.x) * dims.y * dims.z);
  std::uint64_t expectedSet = 0;
  int lo = -int(overlap), hi = int(brickSize + overlap);
  for (int z = lo; z < hi; ++z)
    for (int y = lo; y < hi; ++y)
      for (int x = lo; x < hi; ++x) {
        // Every border cell, a sample of the interior (the total count covers the rest).
        bool border = x < int(overlap) || y < int(overlap) || z < int(overlap) || x >= int(brickSize) - int(overlap) ||
                      y >= int(brickSize) - int(overlap) || z >= int(brickSize) - int(overlap);
        glm::ivec3 cell(x, y, z);
        if (!border && (x * 7 + y * 3 + z) % 17 != 0) {
          expectedSet += converted.isSet(cell);  // counted, checked in total below
          continue;
        }
        OracleCell expected = oracle(bricks, cell, int(brickSize));
        ASSERT_EQ(converted.isSet(cell), expected.set) << "cell " << x << "," << y << "," << z;
        expectedSet += expected.set;
        if (expected.set && reduction != AttributeReduction::None) {
          ASSERT_EQ(converted.attribute(cell), reduction == AttributeReduction::Mean ? expected.mean : expected.max)
              << "cell " << x << "," << y << "," << z;
        }
      }
  // Every set bit is a stored cell (padding stays clear) and the interior matches the cell count.
  EXPECT_EQ(converted.setCells(), expectedSet);
  std::uint64_t storedInCentre = 0;
  for (int z = 0; z < int(brickSize); ++z)
    for (int y = 0; y < int(brickSize); ++y)
      for (int x = 0; x < int(brickSize); ++x) storedInCentre += converted.isSet({x, y, z});
  EXPECT_EQ(storedInCentre, bricks[kCentre]->cells.size());
  if (reduction != AttributeReduction::None) {
    EXPECT_EQ(converted.attributes.size(), converted.setCells());
  }
}

TEST(ConvertBrick, MatchesOracle32) {
  for (std::uint32_t overlap : {0u, 1u, 3u, 8u})
    checkAgainstOracle(32, overlap, 0.15, AttributeReduction::None, overlap);
}

TEST(ConvertBrick, MatchesOracleWithMeanAttributes) {
  checkAgainstOracle(32, 4, 0.3, AttributeReduction::Mean, 21);
  checkAgainstOracle(32, 5, 0.05, AttributeReduction::Mean, 22);
}

TEST(ConvertBrick, MatchesOracleWithMaxAttributes) { checkAgainstOracle(32, 2, 0.2, AttributeReduction::Max, 31); }

TEST(ConvertBrick, MatchesOracle64And128) {
  checkAgainstOracle(64, 4, 0.02, AttributeReduction::Mean, 41);
  checkAgainstOracle(128, 7, 0.002, AttributeReduction::None, 42);
}

TEST(ConvertBrick, AttributeBasesAreRowPlusSubBrickOffsets) {
  // A full 64^3 brick with a border holds more set cells than 16 bits address; bases stay exact.
  DecodedBrick full;
  for (std::uint32_t c = 0; c < 64u * 64 * 64; ++c) {
    full.cells.push_back(c);
    full.counts.push_back(1);
    full.attributes.push_back(std::uint16_t(c * 2654435761u >> 16));
  }
  Neighbourhood<DecodedBrick> bricks{};
  bricks.fill(&full);
  BitBrick converted = convertBrick(bricks, {64, 2, AttributeReduction::Mean});
  EXPECT_EQ(converted.setCells(), 68ull * 68 * 68);
  EXPECT_GT(converted.attributes.size(), 65536u);
  std::uint32_t expectedBase = 0;
  for (std::uint32_t i = 0; i < converted.subBricks.size(); ++i) {
    ASSERT_EQ(converted.attributeBase(i), expectedBase) << "sub-brick " << i;
    const glm::uvec4& s = converted.subBricks[i];
    expectedBase += std::popcount(s.x) + std::popcount(s.y) + std::popcount(s.z) + std::popcount(s.w);
  }
  glm::ivec3 cell(63, 10, 40);
  std::uint32_t linear = 63 + 64 * (10 + 64 * 40);
  EXPECT_EQ(converted.attribute(cell), std::uint16_t(linear * 2654435761u >> 16));
  EXPECT_EQ(converted.attribute({-2, 10, 40}), std::uint16_t((62 + 64 * (10 + 64 * 40)) * 2654435761u >> 16));
}

TEST(ConvertBrick, RejectsBadOptions) {
  DecodedBrick empty;
  Neighbourhood<DecodedBrick> bricks{};
  bricks[kCentre] = &empty;
  try {
    convertBrick(bricks, {48, 2, AttributeReduction::None});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("brick size must be 32, 64 or 128, got 48"), std::string::npos);
  }
  try {
    convertBrick(bricks, {64, 9, AttributeReduction::None});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("overlap must be at most 8 cells, got 9"), std::string::npos);
  }
}

TEST(ConvertBrick, RejectsCellsOutsideTheBrick) {
  DecodedBrick bad;
  bad.cells = {5, 32768};
  bad.counts = {1, 1};
  EXPECT_THROW(makeBrickCells(bad, 32, AttributeReduction::None), LogicError);
}

}  // namespace
}  // namespace flipscope

namespace flipscope {
namespace {

// The kind of `cell` (neighbourhood coordinates) and whether it is occupied, by binary search.
std::optional<ParticleKind> oracleKind(const Neighbourhood<DecodedBrick>& bricks, glm::ivec3 cell, int brickSize) {
  const auto [brick, linear] = locate(bricks, cell, brickSize);
  if (!brick) return std::nullopt;
  auto found = std::lower_bound(brick->cells.begin(), brick->cells.end(), linear);
  if (found == brick->cells.end() || *found != linear) return std::nullopt;
  return brick->kinds[std::size_t(found - brick->cells.begin())];
}

TEST(ConvertBrick, KindsHideBubblesAndGatherFoamAcrossTheBorder) {
  std::mt19937 rng(77);
  constexpr std::uint32_t kSize = 32, kOverlap = 4;
  std::array<DecodedBrick, 27> storage;
  Neighbourhood<DecodedBrick> bricks{};
  for (int i = 0; i < 27; ++i) {
    storage[i] = testing::randomBrick(rng, kSize, 0.3);
    storage[i].kinds.resize(storage[i].cells.size());
    for (ParticleKind& kind : storage[i].kinds) kind = ParticleKind(rng() % kParticleKindCount);
    bricks[i] = &storage[i];
  }
  ConversionOptions options{kSize, kOverlap, AttributeReduction::Max};
  options.hideBubbles = true;
  options.foamKinds = true;
  std::array<BrickCells, 27> cells;
  Neighbourhood<BrickCells> around{};
  for (int i = 0; i < 27; ++i) {
    cells[i] = makeBrickCells(storage[i], options);
    around[i] = &cells[i];
  }
  const BitBrick converted = convertBrick(around, options);
  BitBrick foam = converted;
  foam.subBricks = convertFoamKinds(around, options);
  ASSERT_EQ(foam.subBricks.size(), converted.subBricks.size());
  std::size_t hidden = 0, foamCells = 0;
  const int lo = -int(kOverlap), hi = int(kSize + kOverlap);
  for (int z = lo; z < hi; ++z)
    for (int y = lo; y < hi; ++y)
      for (int x = lo; x < hi; ++x) {
        const glm::ivec3 cell(x, y, z);
        const std::optional<ParticleKind> kind = oracleKind(bricks, cell, int(kSize));
        const bool shown = kind && *kind != ParticleKind::Bubble;
        hidden += kind && !shown;
        ASSERT_EQ(converted.isSet(cell), shown) << x << "," << y << "," << z;
        const bool isFoam = kind && (*kind == ParticleKind::Foam || *kind == ParticleKind::Spray);
        foamCells += isFoam;
        ASSERT_EQ(foam.isSet(cell), isFoam) << x << "," << y << "," << z;
        if (shown) {
          ASSERT_EQ(converted.attribute(cell), oracle(bricks, cell, int(kSize)).max) << x << "," << y << "," << z;
        }
      }
  EXPECT_GT(hidden, 1000u);
  EXPECT_GT(foamCells, 1000u);
  EXPECT_EQ(converted.attributes.size(), converted.setCells());

  // Without foam or spray anywhere there is nothing to upload.
  for (int i = 0; i < 27; ++i) {
    std::fill(storage[i].kinds.begin(), storage[i].kinds.end(), ParticleKind::Liquid);
    cells[i] = makeBrickCells(storage[i], options);
  }
  EXPECT_TRUE(convertFoamKinds(around, options).empty());
}

}  // namespace
}  // namespace flipscope
