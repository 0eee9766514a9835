// Binning (convertFrame) against a brute-force oracle, and out-of-core against in-core.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <sstream>
#include <tuple>

#include <tbb/task_arena.h>

#include "GzipTestWriter.h"
#include "ParticleTestSupport.h"
#include "StoreComparison.h"
#include "TestSupport.h"
#include "VectorSource.h"
#include "core/AtomicFile.h"
#include "core/Error.h"
#include "core/Morton.h"
#include "preprocess/BrickBinning.h"
#include "preprocess/Convert.h"
#include "preprocess/ParticleSpacing.h"
#include "preprocess/PositionRanges.h"
#include "preprocess/particles/DirectReadAhead.h"
#include "preprocess/particles/ParticleWriter.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;

using BrickKey = std::tuple<std::uint32_t, std::uint32_t, std::uint32_t>;
/// brick -> cell -> attribute values (sorted), computed particle by particle.
using Oracle = std::map<BrickKey, std::map<std::uint32_t, std::vector<std::uint16_t>>>;

Oracle bruteForce(const std::vector<glm::vec3>& p, const std::vector<glm::vec3>& v, const StoreHeader& h,
                  std::uint64_t& invalid, std::uint64_t& outside) {
  Oracle oracle;
  float smin = std::numeric_limits<float>::max(), smax = -smin;
  std::vector<int> keep(p.size(), 0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!std::isfinite(p[i].x) || !std::isfinite(p[i].y) || !std::isfinite(p[i].z)) {
      ++invalid;
      continue;
    }
    bool inside = true;
    for (int a = 0; a < 3; ++a) {
      const double c = std::floor((double(p[i][a]) - h.origin[a]) / h.cellSize);
      inside = inside && c >= 0 && c < double(h.brickGrid[a]) * h.brickSize;
    }
    if (!inside) {
      ++outside;
      continue;
    }
    keep[i] = 1;
    if (!v.empty()) {
      smin = std::min(smin, glm::length(v[i]));
      smax = std::max(smax, glm::length(v[i]));
    }
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!keep[i]) continue;
    std::uint32_t c[3];
    for (int a = 0; a < 3; ++a) c[a] = std::uint32_t(std::floor((double(p[i][a]) - h.origin[a]) / h.cellSize));
    const std::uint32_t B = h.brickSize;
    BrickKey brick{c[0] / B, c[1] / B, c[2] / B};
    const std::uint32_t cell = c[0] % B + B * (c[1] % B + B * (c[2] % B));
    const std::uint16_t a = v.empty() ? 0 : detail::quantizeAttribute(glm::length(v[i]), smin, smax);
    oracle[brick][cell].push_back(a);
  }
  for (auto& [brick, cells] : oracle)
    for (auto& [cell, attrs] : cells) std::sort(attrs.begin(), attrs.end());
  return oracle;
}

struct Case {
  std::uint32_t brickSize;
  double cellSize;
  bool attribute;
  std::size_t particles = 20000;
};

class ConvertOracle : public ::testing::TestWithParam<Case> {};

TEST_P(ConvertOracle, StoreMatchesBruteForceBinning) {
  const Case c = GetParam();
  auto positions = testing::randomParticles(c.particles, 1000 + c.brickSize, 12.0f);
  positions[17] = {std::nanf(""), 1, 1};
  positions[18] = {1, std::numeric_limits<float>::infinity(), 1};
  positions[19] = {-5, 1, 1};  // outside the domain below
  std::vector<glm::vec3> velocities;
  if (c.attribute) {
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> u(-3, 3);
    for (std::size_t i = 0; i < positions.size(); ++i) velocities.push_back({u(rng), u(rng), u(rng)});
  }
  ConvertOptions options;
  options.cellSize = c.cellSize;
  options.brickSize = c.brickSize;
  options.progress = Progress::Mode::Silent;
  testing::TempDir temp("oracle");
  const fs::path dir = temp / "store";
  const AttributeKind attribute = c.attribute ? AttributeKind::Speed : AttributeKind::None;
  BrickStore store = BrickStore::createOrAppend(dir, makeStoreHeader(Box{{0, 0, 0}, {12, 12, 12}}, options, attribute));
  testing::VectorSource source(positions, velocities);
  const FrameReport report = convertFrame(source, store, 0, options);

  std::uint64_t invalid = 0, outside = 0;
  const Oracle oracle = bruteForce(positions, velocities, store.header(), invalid, outside);
  EXPECT_EQ(report.stats.skippedInvalid, invalid);
  EXPECT_EQ(report.stats.skippedOutside, outside);
  EXPECT_EQ(invalid, 2u);
  EXPECT_EQ(outside, 1u);

  BrickStore reopened = BrickStore::open(dir);
  auto frame = reopened.frame(0);
  ASSERT_EQ(frame->bricks.size(), oracle.size());
  EXPECT_EQ(frame->stats.particles, positions.size() - invalid - outside);
  std::uint32_t previous = 0;
  // Bricks in Morton order, each equal to the oracle's.
  for (std::uint32_t b = 0; b < frame->bricks.size(); ++b) {
    const BrickRecord& r = frame->bricks[b];
    const std::uint32_t code = mortonEncode3(r.coord.x, r.coord.y, r.coord.z);
    if (b) {
      EXPECT_GT(code, previous);
    }
    previous = code;
    EXPECT_EQ(frame->octree.find(r.coord), std::int64_t(b));
    auto it = oracle.find({r.coord.x, r.coord.y, r.coord.z});
    ASSERT_NE(it, oracle.end());
    DecodedBrick d = reopened.readBrick(*frame, b);
    ASSERT_EQ(d.cells.size(), it->second.size());
    std::size_t k = 0, a = 0;
    for (const auto& [cell, attrs] : it->second) {
      EXPECT_EQ(d.cells[k], cell);
      EXPECT_EQ(d.counts[k], attrs.size());
      if (c.attribute) {
        for (auto value : attrs) EXPECT_EQ(d.attributes[a++], value);
      }
      ++k;
    }
  }
}

// With an attribute, 64 and 0.02 (600 cells) make 30-bit cell keys, which carry their values
// (KeyGrid::valueInKey), and 128 and 0.01 (1200 cells) 33-bit ones, which do not. 32 and 0.004
// (94 bricks an axis) make 21-bit brick codes: split in stripes, not blocks, in two digits.
// With 150000 particles, 32 and 0.05 (8^3 bricks) have computeKeys sort its blocks, the first of
// them thinned by the skipped particles; 32 and 0.04 (10^3 bricks) have binKeys sort three
// blocks of 64 Ki keys; with 300000, 32 and 0.0234375 (17^3 bricks) two blocks of 256 Ki
// (BrickBinning.cpp's kBlockKeys and kBlockKeysPerBrick).
INSTANTIATE_TEST_SUITE_P(BrickSizes, ConvertOracle,
                         ::testing::Values(Case{32, 0.05, false}, Case{64, 0.02, true}, Case{128, 0.01, true},
                                           Case{32, 0.5, true}, Case{32, 0.004, true}, Case{32, 0.05, true, 150000},
                                           Case{32, 0.04, true, 150000}, Case{32, 0.0234375, true, 300000}));

// The 16-bit attribute code, against values worked out by hand (the oracle above shares the
// converter's quantizeAttribute, so it cannot catch a rounding or range bug).
TEST(Convert, AttributeQuantizationByHand) {
  EXPECT_EQ(detail::quantizeAttribute(0.0f, 0.0f, 1.0f), 0);
  EXPECT_EQ(detail::quantizeAttribute(1.0f, 0.0f, 1.0f), 65535);
  EXPECT_EQ(detail::quantizeAttribute(0.5f, 0.0f, 1.0f), 32768);  // 32767.5 rounds away from zero
  EXPECT_EQ(detail::quantizeAttribute(3.0f, 2.0f, 6.0f), 16384);  // a quarter: 16383.75
  EXPECT_EQ(detail::quantizeAttribute(-1.0f, 0.0f, 1.0f), 0);     // clamped below
  EXPECT_EQ(detail::quantizeAttribute(7.0f, 2.0f, 6.0f), 65535);  // clamped above
  EXPECT_EQ(detail::quantizeAttribute(5.0f, 5.0f, 5.0f), 0);      // an empty range
  // Rounding half away from zero, as std::lround, at and beside every half step.
  for (std::uint32_t step = 0; step < 65535; ++step)
    for (const float t : {(float(step) + 0.5f) / 65535.0f, std::nextafter((float(step) + 0.5f) / 65535.0f, 0.0f),
                          std::nextafter((float(step) + 0.5f) / 65535.0f, 1.0f)})
      if (t > 0.0f && t < 1.0f) {
        ASSERT_EQ(detail::quantizeAttribute(t, 0.0f, 1.0f), std::uint16_t(std::lround(t * 65535.0f))) << t;
      }
}

/// Brick size and cell size of a store over [0, 50)^3 stretched by `stretch`, whether its batch
/// keys carry their attribute values (KeyBatch's two layouts, also in the spill files), and the
/// case's name.
struct OutOfCoreCase {
  std::uint32_t brickSize;
  double cellSize;
  bool valueInKey;
  const char* name;
  glm::vec3 stretch{1.0f};
  /// Particles in order along x, as a solver's cache often is (near particles near in the file):
  /// then a block of keys touches few bricks, and computeKeys keeps its runs.
  bool alongX = false;
  /// The store's attribute: without one, keys of at most 32 bits are binned in memory as narrow
  /// keys (KeyBatch::narrow), and spilled as the 8-byte keys they widen to.
  AttributeKind attribute = AttributeKind::Speed;
};

class ConvertOutOfCore : public ::testing::TestWithParam<OutOfCoreCase> {};

TEST_P(ConvertOutOfCore, StoreIsByteIdenticalToInCoreWithAndWithoutReadAhead) {
  // ~2.4 M particles (29 MB of float32, 58 MB with velocities) against a 4 MiB budget. Neither
  // budget's chunk (174762 and 4096 particles) divides the count. The keys are sorted by brick
  // a block at a time: in core by computeKeys on the grid of 512 bricks, by binKeys on the others
  // (spilled keys always by binKeys); on the long, thin grid (125 bricks along x) split in place
  // in stripes instead, one a task from 2^20 keys on, so in core its bricks come in two runs.
  const OutOfCoreCase c = GetParam();
  auto positions = testing::randomParticles(2400000, 77, 50.0f);
  for (glm::vec3& p : positions) p *= c.stretch;
  if (c.alongX) std::sort(positions.begin(), positions.end(), [](const auto& a, const auto& b) { return a.x < b.x; });
  // One particle not finite, one outside the domain: skipped, so that the keys binned in memory
  // when a source without a count starts spilling are no whole number of chunks (narrow keys
  // are widened for the spill a chunk's worth at a time: the last piece is short).
  positions[1000] = {std::nanf(""), 1, 1};
  positions[2000].x = -1;
  std::vector<glm::vec3> velocities(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) velocities[i] = glm::vec3(std::sin(float(i)), 0.5f, 0);
  ConvertOptions options;
  options.cellSize = c.cellSize;
  options.brickSize = c.brickSize;
  options.progress = Progress::Mode::Silent;
  const Box domain{{0, 0, 0}, glm::dvec3(50.0f * c.stretch)};
  const detail::KeyGrid grid(makeStoreHeader(domain, options, c.attribute));
  ASSERT_EQ(grid.valueInKey, c.valueInKey);
  ASSERT_EQ(grid.narrowKeys(), c.attribute == AttributeKind::None);
  testing::TempDir temp("out-of-core");
  auto run = [&](std::uint64_t budget, const std::string& name, bool readAhead = true, bool hintsCount = true,
                 std::optional<std::uint64_t> wrongCount = std::nullopt) {
    options.memoryBudget = budget;
    options.readAhead = readAhead;
    const fs::path dir = temp / name;
    StoreHeader header = makeStoreHeader(domain, options, c.attribute);
    header.id = {7, 7, 7};  // the same id for both stores: then the files are the same bytes
    BrickStore store = BrickStore::createOrAppend(dir, header);
    testing::VectorSource source(positions, velocities);
    source.hintsCount = hintsCount;
    source.wrongCount = wrongCount;
    tbb::task_arena arena(4);  // as many stripes as tasks, whatever the cores here (in stripes)
    FrameReport report = arena.execute([&] { return convertFrame(source, store, 1, options); });
    return std::make_pair(dir, report);
  };
  auto [inCore, inReport] = run(1ull << 30, "incore");
  auto [outOfCore, outReport] = run(4ull << 20, "outofcore");
  EXPECT_EQ(inReport.spillBuckets, 0u);
  EXPECT_GT(outReport.spillBuckets, 1u);
  EXPECT_EQ(readFile(inCore / "frame_000001.fsf"), readFile(outOfCore / "frame_000001.fsf"));
  EXPECT_EQ(readFile(inCore / "store.fsh"), readFile(outOfCore / "store.fsh"));
  // Reading the next chunk on a thread of its own (the default) writes what reading and binning
  // in turn does, in core and out of core.
  for (const auto& [budget, name] : {std::pair(1ull << 30, "incore-in-turn"), std::pair(4ull << 20, "ooc-in-turn")}) {
    const auto [dir, report] = run(budget, name, false);
    EXPECT_EQ(report.spillBuckets > 0, budget < (1ull << 30)) << name;
    EXPECT_EQ(readFile(dir / "frame_000001.fsf"), readFile(inCore / "frame_000001.fsf")) << name;
  }
  // Under 16 MiB the buckets are small against a bin: the next one is read while this one is
  // binned (FrameBinner::binBuckets). Under 4 MiB they are not, and are read in turn.
  const auto [aheadDir, aheadReport] = run(16ull << 20, "ooc-read-ahead");
  EXPECT_GT(aheadReport.spillBuckets, 1u);
  EXPECT_EQ(readFile(aheadDir / "frame_000001.fsf"), readFile(inCore / "frame_000001.fsf"));
  // So they are under 24 MiB, also where the values travel beside the keys (12 bytes a particle),
  // which under 16 MiB are read in turn (a mutation of SpillBuckets::unpack fails all four cases
  // here, only three of them under 16 MiB).
  const auto [ahead24Dir, ahead24Report] = run(24ull << 20, "ooc-read-ahead-24");
  EXPECT_GT(ahead24Report.spillBuckets, 1u);
  EXPECT_EQ(readFile(ahead24Dir / "frame_000001.fsf"), readFile(inCore / "frame_000001.fsf"));
  // A source that gives its count spills from its first chunk; one that does not is binned in
  // memory until it overflows, then spills what it holds.
  const auto [unhinted, unhintedReport] = run(4ull << 20, "ooc-no-count", true, false);
  EXPECT_GT(unhintedReport.spillBuckets, 1u);
  EXPECT_EQ(readFile(unhinted / "frame_000001.fsf"), readFile(inCore / "frame_000001.fsf"));
  // A count below the frame's (a header that lies) reserves too few keys: they grow, in memory.
  const auto [undercounted, undercountedReport] = run(1ull << 30, "incore-undercounted", true, true, 1000);
  EXPECT_EQ(undercountedReport.spillBuckets, 0u);
  EXPECT_EQ(readFile(undercounted / "frame_000001.fsf"), readFile(inCore / "frame_000001.fsf"));
  // No spill file is left behind.
  for (const auto& e : fs::directory_iterator(outOfCore))
    EXPECT_TRUE(e.path().filename() == "store.fsh" || e.path().filename() == "store.lock" ||
                e.path().filename() == "frame_000001.fsf")
        << e.path();
}

// 1000 cells of 64: 30 bits of cell key, the value rides in the key; 2500 cells of 128: 36 bits,
// the value travels beside it; 500 cells of 64: 8^3 bricks, few enough for computeKeys to sort
// its keys (and keep their runs: the particles in order along x); 4000 by 80 by 80 cells of 32 (200 x 4 x 4): 125 x 3 x
// 3 bricks, split in stripes. Without an attribute, narrow keys: sorted as they are made (8^3
// bricks) or by binKeys a block at a time (16^3 bricks), and 250 cells of 32 (8^3 bricks), whose
// bricks are dense (a histogram of their cells). Narrow keys never take the stripes: the grids
// whose cell keys fit 32 bits have at most 32 bricks along an axis.
INSTANTIATE_TEST_SUITE_P(
    KeyLayouts, ConvertOutOfCore,
    ::testing::Values(
        OutOfCoreCase{64, 0.05, true, "ValueInKey"}, OutOfCoreCase{128, 0.02, false, "ValueBesideKey"},
        OutOfCoreCase{64, 0.1, true, "FewBricksSortedAsKeysAreMade", glm::vec3(1.0f), true},
        OutOfCoreCase{32, 0.05, false, "LongThinGridInStripes", {4.0f, 0.08f, 0.08f}},
        OutOfCoreCase{64, 0.1, false, "NarrowKeysSortedAsTheyAreMade", glm::vec3(1.0f), true, AttributeKind::None},
        OutOfCoreCase{64, 0.05, false, "NarrowKeys", glm::vec3(1.0f), false, AttributeKind::None},
        OutOfCoreCase{32, 0.2, false, "NarrowKeysDenseBricks", glm::vec3(1.0f), false, AttributeKind::None}),
    [](const auto& info) { return std::string(info.param.name); });

// convert's binning pass reads its input once, around the page cache where it is not cached
// (DirectReadAhead): the store is the bytes of one binned from memory, in core and out of core.
// The particles of the PLY start past its header, at no whole block, and end at no whole piece.
TEST(Convert, AFileReadAroundThePageCacheGivesTheSameStoreInCoreAndOutOfCore) {
  const auto positions = testing::randomParticles(1000003, 78, 50.0f);
  std::vector<glm::vec3> velocities(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) velocities[i] = glm::vec3(std::cos(float(i)), 0.25f, 1);
  testing::TempDir temp("read-around");
  const fs::path ply = temp / "frame.ply";
  {
    WriteOptions write;
    write.velocity = true;
    auto writer = createParticleWriter(ply, write);
    ParticleChunk chunk;
    chunk.positions = positions;
    chunk.velocities = velocities;
    writer->write(chunk);
    writer->commit();
  }
  ConvertOptions options;
  options.cellSize = 0.05;
  options.progress = Progress::Mode::Silent;
  const Box domain{{0, 0, 0}, {50, 50, 50}};
  auto run = [&](ParticleSource& source, std::uint64_t budget, const std::string& name) {
    options.memoryBudget = budget;
    StoreHeader header = makeStoreHeader(domain, options, AttributeKind::Speed);
    header.id = {7, 7, 7};
    BrickStore store = BrickStore::createOrAppend(temp / name, header);
    const FrameReport report = convertFrame(source, store, 1, options);
    EXPECT_EQ(report.stats.particles, positions.size()) << name;
    EXPECT_EQ(report.spillBuckets > 0, budget < (1ull << 30)) << name;
    return readFile(temp / name / "frame_000001.fsf");
  };
  testing::VectorSource fromMemory(positions, velocities);
  const auto expected = run(fromMemory, 1ull << 30, "memory");
  for (const std::uint64_t budget : {1ull << 30, 4ull << 20}) {
    const std::string name = budget < (1ull << 30) ? "out-of-core" : "in-core";
    const bool dropped = testing::dropFromPageCache(ply);
    ReadOptions read;
    read.readOnceAheadBytes = 4 << 20;
    auto source = openParticleFile(ply, read);
    EXPECT_EQ(run(*source, budget, name), expected) << name;
    // Read around the cache: the middle of the file stays out of it (not on tmpfs, whose pages
    // are the file).
    if (dropped) {
      const int fd = ::open(ply.c_str(), O_RDONLY | O_CLOEXEC);
      const PageCacheResidency residency(fd, fs::file_size(ply));
      EXPECT_FALSE(residency.cached(fs::file_size(ply) / 2, 1 << 20)) << name;
      ::close(fd);
    }
  }
}

// convert keeps the storage of a frame's keys for the next frame (its pages touched once): frames
// of a sequence that shrinks and grows, their keys sorted as they are made (particles in order
// along x: runs kept) or not (random order), convert into the frames of converts one frame each.
// So they do without an attribute (narrow keys), also where the first and last frames spill
// (under 2 MiB, 157286 particles a bin: then the keys of the frame after are narrow again).
TEST(Convert, FramesBinnedInTheKeysOfTheFrameBeforeAreTheFramesConvertedAlone) {
  testing::TempDir temp("reused-keys");
  const std::size_t counts[] = {300000, 100000, 200000};
  std::vector<FrameInput> inputs;
  for (int f = 0; f < 3; ++f) {
    auto positions = testing::randomParticles(counts[f], 90 + f, 50.0f);
    if (f != 1) std::sort(positions.begin(), positions.end(), [](const auto& a, const auto& b) { return a.x < b.x; });
    ParticleChunk chunk;
    chunk.positions = positions;
    chunk.velocities.resize(positions.size());
    for (std::size_t i = 0; i < positions.size(); ++i) chunk.velocities[i] = glm::vec3(std::sin(float(i + f)), 1, 0);
    const fs::path file = temp / ("frame_" + std::to_string(f) + ".ply");
    WriteOptions write;
    write.velocity = true;
    auto writer = createParticleWriter(file, write);
    writer->write(chunk);
    writer->commit();
    inputs.push_back({f, {file}});
  }
  ConvertOptions options;
  options.cellSize = 0.1;  // 8^3 bricks of 64: computeKeys sorts
  options.particleSpacing = 0.05;
  options.domain = Box{{0, 0, 0}, {50, 50, 50}};
  options.progress = Progress::Mode::Silent;
  const auto sequenceAndOneByOne = [&](const std::string& name) {
    const ConvertReport sequence = convert(inputs, temp / (name + "-sequence"), options);
    for (const FrameInput& input : inputs) convert({input}, temp / (name + "-one-by-one"), options);  // appended
    testing::expectSameFrames(temp / (name + "-sequence"), temp / (name + "-one-by-one"));
    return sequence;
  };
  sequenceAndOneByOne("speed");
  options.attribute = "none";
  sequenceAndOneByOne("narrow");
  options.memoryBudget = 2 << 20;
  const ConvertReport spilled = sequenceAndOneByOne("narrow-spilled");
  ASSERT_EQ(spilled.frames.size(), 3u);
  EXPECT_GT(spilled.frames[0].spillBuckets, 0u);
  EXPECT_EQ(spilled.frames[1].spillBuckets, 0u);
  EXPECT_GT(spilled.frames[2].spillBuckets, 0u);
}

// computeKeys keeps the runs of its sorted blocks only while they stay within one per
// kKeysPerRun keys (plus one a brick), whatever the particles' order: particles in random order
// over 8^3 bricks touch every brick in every block of 16 Ki, and a small chunk (a small --mem)
// is one short block; in order along x, a block touches a slab of bricks.
TEST(Convert, KeysSortedAsTheyAreMadeKeepTheirRunsOnlyWithinTheirBound) {
  ConvertOptions options;
  options.cellSize = 0.1;
  options.brickSize = 64;
  const StoreHeader header = makeStoreHeader(Box{{0, 0, 0}, {50, 50, 50}}, options, AttributeKind::Speed);
  const detail::KeyGrid grid(header);
  ASSERT_EQ(header.brickGrid, glm::uvec3(8));
  ASSERT_TRUE(grid.valueInKey);
  ParticleChunk chunk;
  chunk.positions = testing::randomParticles(200000, 3, 50.0f);
  chunk.velocities.assign(chunk.positions.size(), glm::vec3(1, 0, 0));
  const auto keysOf = [&](const ParticleChunk& c, std::size_t from, std::size_t count) {
    ParticleChunk part;
    part.positions.assign(c.positions.begin() + std::ptrdiff_t(from),
                          c.positions.begin() + std::ptrdiff_t(from + count));
    part.velocities.assign(count, glm::vec3(1, 0, 0));
    return part;
  };
  const auto withinBound = [&](const detail::KeyBatch& batch) {
    return batch.runs.size() <= batch.cellKeys.size() / detail::kKeysPerRun + 512;
  };
  detail::KeyBatch random;
  for (std::size_t from = 0; from < chunk.size(); from += 50000)
    detail::computeKeys(keysOf(chunk, from, 50000), grid, random);
  EXPECT_LT(random.sortedKeys, random.cellKeys.size());  // binKeys sorts them
  EXPECT_TRUE(random.runs.empty()) << random.runs.size() << " runs";
  detail::KeyBatch small;  // chunks of 4096 keys: each one short block with a run a brick
  for (std::size_t from = 0; from < 40960; from += 4096) detail::computeKeys(keysOf(chunk, from, 4096), grid, small);
  EXPECT_LT(small.sortedKeys, small.cellKeys.size());
  EXPECT_TRUE(withinBound(small));
  std::sort(chunk.positions.begin(), chunk.positions.end(), [](const auto& a, const auto& b) { return a.x < b.x; });
  detail::KeyBatch ordered;
  for (std::size_t from = 0; from < chunk.size(); from += 50000)
    detail::computeKeys(keysOf(chunk, from, 50000), grid, ordered);
  EXPECT_EQ(ordered.sortedKeys, ordered.cellKeys.size());
  EXPECT_TRUE(withinBound(ordered)) << ordered.runs.size() << " runs";
  // The runs cover every key once, each of one brick code, a block's codes ascending.
  std::size_t covered = 0;
  for (const detail::CodedRun& r : ordered.runs) {
    covered += r.run.end - r.run.begin;
    for (std::size_t i = r.run.begin; i < r.run.end; ++i)
      ASSERT_EQ((ordered.cellKeys[i] >> (32 + grid.cellBits)) & ((1u << grid.codeBits) - 1), r.code) << i;
  }
  EXPECT_EQ(covered, ordered.cellKeys.size());
  // Spilled keys are not sorted.
  detail::KeyBatch spilled;
  spilled.sortRuns = false;
  detail::computeKeys(keysOf(chunk, 0, 50000), grid, spilled);
  EXPECT_EQ(spilled.sortedKeys, 0u);
  EXPECT_TRUE(spilled.runs.empty());
}

TEST(Convert, SkewedDataSplitsBucketsRecursively) {
  // Most particles in one corner brick region: the first-level bucket overflows.
  auto positions = testing::randomParticles(300000, 5, 2.0f);
  for (std::size_t i = 0; i < positions.size(); i += 50) positions[i] += glm::vec3(40.0f);
  ConvertOptions options;
  options.cellSize = 0.01;
  options.brickSize = 32;
  options.progress = Progress::Mode::Silent;
  const Box domain{{0, 0, 0}, {45, 45, 45}};
  std::vector<std::vector<std::byte>> files;
  testing::TempDir temp("skew");
  for (std::uint64_t budget : {1ull << 30, 2ull << 20}) {
    options.memoryBudget = budget;
    const fs::path dir = temp / std::to_string(budget);
    StoreHeader header = makeStoreHeader(domain, options);
    header.id = {1, 2, 3};  // the same id for both stores
    BrickStore store = BrickStore::createOrAppend(dir, header);
    testing::VectorSource source(positions);
    const FrameReport report = convertFrame(source, store, 0, options);
    if (budget < (1ull << 30)) {
      EXPECT_GT(report.spillBuckets, 4u) << "the overflowing bucket was not split";
    }
    files.push_back(readFile(dir / "frame_000000.fsf"));
  }
  EXPECT_EQ(files[0], files[1]);
}

TEST(Convert, DomainIsDerivedFromTheBoundsAndLimited) {
  ConvertOptions options;
  options.resolution = 100;
  StoreHeader h = makeStoreHeader(Box{{1, 2, 3}, {11, 7, 4}}, options);
  EXPECT_EQ(h.origin, glm::dvec3(1, 2, 3));
  EXPECT_DOUBLE_EQ(h.cellSize, 0.1);
  EXPECT_EQ(h.brickGrid, glm::uvec3(2, 1, 1));
  options.cellSize = 1e-6;
  EXPECT_THROW(makeStoreHeader(Box{{0, 0, 0}, {1, 1, 1}}, options), InputError);
  EXPECT_THROW(makeStoreHeader(Box{}, ConvertOptions{}), InputError);
}

fs::path mantaflowFrame30() { return flipscope::testing::mantaflowFile("data", "fluid_data_0030.vdb"); }

void writeRaw(const fs::path& path, const std::vector<glm::vec3>& positions) {
  auto writer = createParticleWriter(path);
  ParticleChunk chunk;
  chunk.positions = positions;
  writer->write(chunk);
  writer->commit();
}

/// n^3 particles, `spacing` apart, from `origin`.
std::vector<glm::vec3> latticePoints(int n, float spacing, glm::vec3 origin = glm::vec3(0)) {
  std::vector<glm::vec3> points;
  for (int x = 0; x < n; ++x)
    for (int y = 0; y < n; ++y)
      for (int z = 0; z < n; ++z) points.push_back(origin + spacing * glm::vec3(x, y, z));
  return points;
}

ConvertOptions silent() {
  ConvertOptions options;
  options.progress = Progress::Mode::Silent;
  return options;
}

// The bounds pass reads a PLY by ranges on every core (readPositionRangesInParallel) and a gzip
// around the same bytes in order: the same domain, from extremes and NaN/Inf in several ranges
// (the last one short), and the same frame.
TEST(Convert, TheBoundsPassFindsTheSameDomainByRangesAsInOrder) {
  const std::size_t n = 3 * kPositionRangeParticles + 500;
  auto positions = testing::randomParticles(n, 77u, 12.0f);
  positions[10] = {std::nanf(""), 100, 100};
  positions[kPositionRangeParticles + 3] = {-100, std::numeric_limits<float>::infinity(), 5};
  positions[kPositionRangeParticles + 9] = {30.5f, -4.25f, 2};  // the far corner, in the second range
  positions[n - 2] = {1, 2, -7.5f};                             // and in the last, short one
  testing::TempDir temp("bounds-ranges");
  writeRaw(temp / "p.ply", positions);
  testing::writeBytes(temp / "p.ply.gz", testing::gzip(testing::readBytes(temp / "p.ply")));
  ConvertOptions options = silent();
  options.cellSize = 0.5;
  options.particleSpacing = 0.25;  // no spacing estimate: its read would find the bounds instead
  convert({{0, {temp / "p.ply"}}}, temp / "ranges", options);
  convert({{0, {temp / "p.ply.gz"}}}, temp / "in-order", options);
  const StoreHeader a = BrickStore::open(temp / "ranges").header();
  const StoreHeader b = BrickStore::open(temp / "in-order").header();
  EXPECT_EQ(a.origin, b.origin);
  EXPECT_EQ(a.brickGrid, b.brickGrid);
  EXPECT_EQ(a.origin.y, -4.25);  // the planted extremes
  EXPECT_EQ(a.origin.z, -7.5);
  EXPECT_EQ(BrickStore::open(temp / "ranges").frame(0)->stats.particles, n - 2);
  EXPECT_EQ(BrickStore::open(temp / "in-order").frame(0)->stats.particles, n - 2);
}

TEST(ConvertSpacing, DefaultConvertOfMantaflowMakesOneCellPerParticleSpacing) {
  const fs::path file = mantaflowFrame30();
  ASSERT_TRUE(fs::exists(file)) << file;
  testing::TempDir temp("spacing");
  const ConvertReport report = convert({{30, {file}}}, temp / "store", silent());
  const StoreHeader& h = report.header;
  EXPECT_GT(h.particleSpacing, 0.0);
  EXPECT_EQ(h.cellSize, h.particleSpacing);
  auto source = openParticleFile(file);
  EXPECT_EQ(h.particleSpacing, estimateParticleSpacing(*source).spacing);  // the OpenVDB metadata estimate
  // Mantaflow at resolution 64 seeds FLIP particles about two a cell axis, cells of 0.0625: the
  // spacing lies between half a cell and a cell, whatever the estimator does.
  EXPECT_GT(h.particleSpacing, 0.0625 / 2 * 0.9);
  EXPECT_LT(h.particleSpacing, 0.0625);
  EXPECT_NE(report.cellSizeOrigin.find("particle spacing"), std::string::npos) << report.cellSizeOrigin;
  EXPECT_NE(report.spacingOrigin.find("frame 30: OpenVDB grid 'particles'"), std::string::npos) << report.spacingOrigin;
  EXPECT_TRUE(report.warnings.empty());
  ASSERT_EQ(report.frames.size(), 1u);
  EXPECT_EQ(report.frames[0].stats.particles, source->countHint());
  // Recorded in store.fsh.
  const StoreHeader reopened = BrickStore::open(temp / "store").header();
  EXPECT_EQ(reopened.particleSpacing, h.particleSpacing);
  EXPECT_EQ(reopened.cellSize, h.cellSize);
  // Appending keeps the store's cell size and spacing.
  const ConvertReport again = convert({{31, {file}}}, temp / "store", silent());
  EXPECT_EQ(again.header.particleSpacing, h.particleSpacing);
  EXPECT_EQ(again.header.cellSize, h.cellSize);
}

TEST(ConvertSpacing, GivenCellSizeOrResolutionStillRecordsTheSpacing) {
  testing::TempDir temp("spacing-given");
  const fs::path raw = temp / "lattice.bin";
  writeRaw(raw, latticePoints(30, 0.2f, {1, 2, 3}));  // no metadata: the neighbour estimate
  ConvertOptions options = silent();
  options.cellSize = 0.5;
  const ConvertReport a = convert({{0, {raw}}}, temp / "a", options);
  EXPECT_EQ(a.header.cellSize, 0.5);
  EXPECT_NEAR(a.header.particleSpacing, 0.2, 0.2 * 0.03);
  EXPECT_EQ(a.cellSizeOrigin, "--cell-size");

  options = silent();
  options.resolution = 50;
  const ConvertReport b = convert({{0, {raw}}}, temp / "b", options);
  EXPECT_NEAR(b.header.cellSize, 29 * 0.2 / 50, 1e-6);
  EXPECT_EQ(b.header.particleSpacing, a.header.particleSpacing);

  const ConvertReport c = convert({{0, {raw}}}, temp / "c", silent());
  EXPECT_EQ(c.header.cellSize, a.header.particleSpacing);
  EXPECT_NE(c.spacingOrigin.find("12th-neighbour"), std::string::npos) << c.spacingOrigin;

  options = silent();
  options.particleSpacing = 0.25;  // known to the caller: nothing measured
  EXPECT_EQ(convert({{0, {raw}}}, temp / "d", options).header.cellSize, 0.25);
}

TEST(ConvertSpacing, AStoreConvertedIntoAgainKeepsItsCellsAndRefusesOthersByNumber) {
  testing::TempDir temp("cell-size-kept");
  const fs::path raw = temp / "lattice.bin";
  writeRaw(raw, latticePoints(10, 0.2f, {1, 2, 3}));
  ConvertOptions options = silent();
  options.cellSize = 0.3;
  convert({{0, {raw}}}, temp / "s", options);
  // The same cell size, or none given: kept, the frame added.
  const ConvertReport same = convert({{1, {raw}}}, temp / "s", options);
  EXPECT_EQ(same.header.cellSize, 0.3);
  EXPECT_EQ(same.cellSizeOrigin, "kept from the existing store");
  EXPECT_EQ(convert({{2, {raw}}}, temp / "s", silent()).header.cellSize, 0.3);
  // Another, even in the last digit: refused, the store as it was.
  options.cellSize = std::nextafter(0.3, 1.0);
  try {
    convert({{3, {raw}}}, temp / "s", options);
    FAIL() << "converted into the store with other cells";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cells are 0.3 world units, not 0.30000000000000004 (--cell-size)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(BrickStore::open(temp / "s").frames(), (std::vector<int>{0, 1, 2}));
}

TEST(ConvertSpacing, AParticleFlungFarIsLeftOutByTheDomainTheWarningNames) {
  // 125000 particles in a box of 0.05 and one 10^6 spacings away: one cell per spacing does not
  // fit, and the warning names the box of the particles the estimate sampled (the far one seldom
  // among them; the sample is drawn with a fixed seed) as the --domain to give. With it, the
  // store has one cell per spacing and leaves out the far particle alone.
  testing::TempDir temp("spacing-flung");
  auto points = latticePoints(50, 1e-3f);
  points.push_back({1000, 0, 0});
  const fs::path raw = temp / "flung.bin";
  writeRaw(raw, points);
  const ConvertReport report = convert({{0, {raw}}}, temp / "store", silent());
  ASSERT_EQ(report.warnings.size(), 1u);
  const std::string& warning = report.warnings[0];
  const std::size_t at = warning.find("--domain ");
  ASSERT_NE(at, std::string::npos) << warning;
  std::istringstream box(warning.substr(at + 9));
  Box domain;
  char comma = 0;
  box >> domain.min.x >> comma >> domain.min.y >> comma >> domain.min.z >> comma >> domain.max.x >> comma >>
      domain.max.y >> comma >> domain.max.z;
  ASSERT_FALSE(box.fail()) << warning;
  EXPECT_TRUE(domain.contains(glm::dvec3(0)) && domain.contains(glm::dvec3(0.049))) << warning;
  EXPECT_FALSE(domain.contains(glm::dvec3(1000, 0, 0))) << warning;
  EXPECT_LT(domain.extent().x, 0.1) << warning;

  ConvertOptions options = silent();
  options.domain = domain;
  const ConvertReport within = convert({{0, {raw}}}, temp / "within", options);
  EXPECT_TRUE(within.warnings.empty()) << within.warnings.front();
  EXPECT_EQ(within.cellSizeOrigin, "one cell per particle spacing");
  EXPECT_EQ(within.header.cellSize, within.header.particleSpacing);
  ASSERT_EQ(within.frames.size(), 1u);
  EXPECT_EQ(within.frames[0].stats.particles, points.size() - 1);
  EXPECT_EQ(within.frames[0].stats.skippedOutside, 1u);
}

TEST(ConvertSpacing, SpacingThatOverflowsTheGridFallsBackToTheFinestGridOrUnknownToTheDefault) {
  testing::TempDir temp("spacing-fallback");
  auto points = latticePoints(16, 1e-4f);
  points.push_back({20, 0, 0});  // 200000 spacings away
  const fs::path raw = temp / "far.bin";
  writeRaw(raw, points);
  const ConvertReport report = convert({{0, {raw}}}, temp / "store", silent());
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("more than 65536"), std::string::npos) << report.warnings[0];
  EXPECT_NE(report.warnings[0].find("using 65535 cells along the longest axis"), std::string::npos)
      << report.warnings[0];
  EXPECT_DOUBLE_EQ(report.header.cellSize, 20.0 / (kMaxCellsPerAxis - 1));
  EXPECT_EQ(std::uint64_t(report.header.brickGrid.x) * report.header.brickSize, kMaxCellsPerAxis)
      << "the finest grid a store holds, the far particle in its last cell";
  ASSERT_EQ(report.frames.size(), 1u);
  EXPECT_EQ(report.frames[0].stats.particles, points.size()) << "none outside";
  EXPECT_NEAR(report.header.particleSpacing, 1e-4, 5e-6);  // still recorded

  // Too few particles to measure: the same fallback, the spacing unknown.
  writeRaw(temp / "few.bin", latticePoints(2, 1.0f));
  const ConvertReport few = convert({{0, {temp / "few.bin"}}}, temp / "few", silent());
  ASSERT_EQ(few.warnings.size(), 1u);
  EXPECT_NE(few.warnings[0].find("unknown"), std::string::npos) << few.warnings[0];
  EXPECT_EQ(few.header.particleSpacing, 0.0);
  EXPECT_DOUBLE_EQ(few.header.cellSize, 1.0 / kDefaultResolution);
}

}  // namespace
}  // namespace flipscope
