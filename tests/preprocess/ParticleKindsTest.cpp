// Particle kinds (store version 5): Mantaflow's type flags, the payload codec with a kind per
// cell, the store header's flag, and convert of the Mantaflow sample (its FLIP file with its
// secondary particles) against an oracle that bins the reader's columns itself; version 4
// stores, stores without kinds (the bytes of before) and the out-of-core path.
#include <gtest/gtest.h>

#include <zstd.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <random>

#include "StoreComparison.h"
#include "ParticleTestSupport.h"
#include "TestSupport.h"
#include "core/Bytes.h"
#include "core/Error.h"
#include "core/Hash.h"
#include "preprocess/Convert.h"
#include "preprocess/store/FrameFile.h"
#include "preprocess/store/ParticleKind.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;

const fs::path kFlip30 = testing::mantaflowFile("data", "fluid_data_0030.vdb");
const fs::path kSecondary30 = testing::mantaflowFile("particles", "fluid_particles_0030.vdb");

ConvertOptions silent() {
  ConvertOptions options;
  options.progress = Progress::Mode::Silent;
  return options;
}

TEST(ParticleKind, MantaflowFlagsAndNames) {
  EXPECT_EQ(fromMantaflowType(2), ParticleKind::Spray);
  EXPECT_EQ(fromMantaflowType(4), ParticleKind::Bubble);
  EXPECT_EQ(fromMantaflowType(8), ParticleKind::Foam);
  for (std::int32_t other : {0, 1, 3, 6, 10, 16, -2, 1 << 30}) EXPECT_EQ(fromMantaflowType(other), ParticleKind::Liquid);
  EXPECT_STREQ(particleKindName(ParticleKind::Liquid), "liquid");
  EXPECT_STREQ(particleKindName(ParticleKind::Foam), "foam");
  EXPECT_STREQ(particleKindName(ParticleKind::Spray), "spray");
  EXPECT_STREQ(particleKindName(ParticleKind::Bubble), "bubble");
  // The precedence inside a cell is the value order.
  EXPECT_LT(ParticleKind::Liquid, ParticleKind::Foam);
  EXPECT_LT(ParticleKind::Foam, ParticleKind::Spray);
  EXPECT_LT(ParticleKind::Spray, ParticleKind::Bubble);
}

DecodedBrick randomKindBrick(std::mt19937& rng, std::uint32_t cellsPerBrick, bool attribute) {
  DecodedBrick b;
  for (std::uint32_t cell = rng() % 100; cell < cellsPerBrick && b.cells.size() < 3000;
       cell += 1 + (rng() % 3 == 0 ? rng() % 2000 : rng() % 3)) {
    b.cells.push_back(cell);
    b.counts.push_back(1 + rng() % 12);
    b.kinds.push_back(rng() % 3 ? ParticleKind::Liquid : ParticleKind(rng() % kParticleKindCount));
    for (std::uint32_t i = 0; attribute && i < b.counts.back(); ++i) b.attributes.push_back(std::uint16_t(rng()));
  }
  return b;
}

BrickRecord recordOf(const DecodedBrick& brick) {
  BrickRecord r;
  r.cells = std::uint32_t(brick.cells.size());
  r.particles = std::uint32_t(brick.particleCount());
  return r;
}

TEST(BrickCodecKinds, RoundTripsRandomBricksWithKinds) {
  std::mt19937 rng(23);
  for (int i = 0; i < 40; ++i) {
    const bool attribute = i % 2;
    const DecodedBrick brick = randomKindBrick(rng, 64 * 64 * 64, attribute);
    const auto payload = encodeBrick(brick, 1, kAttributeCoding);
    const DecodedBrick back =
        decodeBrick(payload, "x.fsf", 3, recordOf(brick), 64 * 64 * 64, attribute, true, kAttributeCoding);
    EXPECT_EQ(back.cells, brick.cells);
    EXPECT_EQ(back.counts, brick.counts);
    EXPECT_EQ(back.attributes, brick.attributes);
    EXPECT_EQ(back.kinds, brick.kinds);
    // Read as a store without kinds, the kinds are trailing bytes (or misread attributes).
    EXPECT_THROW(decodeBrick(payload, "x.fsf", 3, recordOf(brick), 64 * 64 * 64, attribute, false, kAttributeCoding),
                 FileError);
  }
  // A brick without kinds, read as one with them, is too short.
  DecodedBrick plain = randomKindBrick(rng, 32 * 32 * 32, false);
  plain.kinds.clear();
  EXPECT_THROW(decodeBrick(encodeBrick(plain, 1, kAttributeCoding), "x.fsf", 0, recordOf(plain), 32 * 32 * 32, false,
                           true, kAttributeCoding),
               FileError);
}

std::vector<std::byte> compress(const ByteWriter& raw) {
  std::vector<std::byte> out(ZSTD_compressBound(raw.size()));
  out.resize(ZSTD_compress(out.data(), out.size(), raw.view().data(), raw.size(), 1));
  return out;
}

/// Two cells (0 and 5) of one particle each, then `kinds` as the kind stream.
std::vector<std::byte> twoCellPayload(const std::vector<std::uint8_t>& kinds) {
  ByteWriter raw;
  raw.putVarint(2);
  raw.putVarint(0);
  raw.putVarint(4);
  raw.putVarint(0);
  raw.putVarint(0);
  for (auto k : kinds) raw.put(k);
  return compress(raw);
}

void expectRefused(const std::vector<std::byte>& payload, const std::string& part) {
  BrickRecord r;
  r.cells = 2;
  r.particles = 2;
  try {
    decodeBrick(payload, "f.fsf", 7, r, 32 * 32 * 32, false, true, kAttributeCoding);
    ADD_FAILURE() << "accepted; expected a FileError mentioning " << part;
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("f.fsf"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("brick 7"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(BrickCodecKinds, RefusesKindsOutsideTheFourAndWrongLengths) {
  BrickRecord r;
  r.cells = 2;
  r.particles = 2;
  const DecodedBrick good =
      decodeBrick(twoCellPayload({0, 3}), "f.fsf", 7, r, 32 * 32 * 32, false, true, kAttributeCoding);
  EXPECT_EQ(good.kinds, (std::vector<ParticleKind>{ParticleKind::Liquid, ParticleKind::Bubble}));
  expectRefused(twoCellPayload({0, 4}), "cell 5 has particle kind 4");
  expectRefused(twoCellPayload({255, 0}), "cell 0 has particle kind 255");
  expectRefused(twoCellPayload({1}), "cell kind");          // one kind short
  expectRefused(twoCellPayload({1, 2, 0}), "trailing");     // one kind too many
}

TEST(StoreHeaderKinds, FlagRoundTripsAndIsChecked) {
  StoreHeader h;
  h.cellSize = 1;
  h.brickGrid = {1, 1, 1};
  h.particleKinds = true;
  auto bytes = serializeStoreHeader(h);
  EXPECT_TRUE(parseStoreHeader(bytes, "store.fsh").particleKinds);
  h.particleKinds = false;
  EXPECT_FALSE(parseStoreHeader(serializeStoreHeader(h), "store.fsh").particleKinds);
  // The flag is the 4 bytes before the up axis, the run count and the checksum: 2 is refused,
  // naming it.
  const std::size_t flag = bytes.size() - 8 - 4 - 4 - 4;
  bytes[flag] = std::byte{2};
  const std::uint64_t sum = checksum64(std::span<const std::byte>(bytes).first(bytes.size() - 8));
  std::memcpy(bytes.data() + bytes.size() - 8, &sum, 8);
  try {
    parseStoreHeader(bytes, "store.fsh");
    FAIL() << "accepted a particle kinds flag of 2";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("particle kinds flag"), std::string::npos) << e.what();
  }
}

TEST(StoreHeaderKinds, AppendingWithOtherKindsIsRefusedSayingWhich) {
  testing::TempDir dir("kinds-append");
  StoreHeader h;
  h.cellSize = 1;
  h.brickGrid = {1, 1, 1};
  h.particleKinds = true;
  BrickStore::createOrAppend(dir / "store", h);
  StoreHeader other = h;
  other.particleKinds = false;
  try {
    BrickStore::createOrAppend(dir / "store", other, BrickStore::FramelessStore::Join);
    FAIL() << "joined a store with particle kinds without them";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("has particle kinds, but this one writes frames without particle kinds"),
              std::string::npos)
        << e.what();
  }
}

/// The kind of every occupied cell of a frame (global cell coordinates packed in 64 bits).
using CellKinds = std::map<std::uint64_t, ParticleKind>;
std::uint64_t packCell(std::uint64_t x, std::uint64_t y, std::uint64_t z) { return x | y << 20 | z << 40; }

CellKinds storedCellKinds(const BrickStore& store, int frame) {
  const StoreHeader& h = store.header();
  const auto index = store.frame(frame);
  CellKinds cells;
  for (std::uint32_t b = 0; b < index->bricks.size(); ++b) {
    const DecodedBrick brick = store.readBrick(*index, b);
    EXPECT_EQ(brick.kinds.size(), brick.cells.size());
    for (std::size_t i = 0; i < brick.cells.size(); ++i) {
      const std::uint32_t c = brick.cells[i], n = h.brickSize;
      const glm::u64vec3 base = glm::u64vec3(index->bricks[b].coord) * std::uint64_t(n);
      cells[packCell(base.x + c % n, base.y + c / n % n, base.z + c / (n * n))] = brick.kinds[i];
    }
  }
  return cells;
}

/// The oracle: the reader's positions (and `U` of the secondary file) binned into the store's
/// cells here, a cell's kind the smallest of its particles'.
CellKinds oracleCellKinds(const StoreHeader& h) {
  CellKinds cells;
  auto add = [&](const fs::path& file, bool typed) {
    ReadOptions read;
    read.velocity = false;
    if (typed) read.attributes = {"U"};
    auto source = openParticleFile(file, read);
    std::vector<glm::vec3> positions;
    std::vector<float> types;
    for (ParticleChunk chunk; source->read(chunk, 1 << 14);) {
      positions.insert(positions.end(), chunk.positions.begin(), chunk.positions.end());
      if (typed) types.insert(types.end(), chunk.attributes[0].values.begin(), chunk.attributes[0].values.end());
    }
    ASSERT_EQ(types.size(), typed ? positions.size() : 0u);
    for (std::size_t i = 0; i < positions.size(); ++i) {
      const glm::dvec3 c = glm::floor((glm::dvec3(positions[i]) - h.origin) * (1.0 / h.cellSize));
      const glm::dvec3 limit = glm::dvec3(h.brickGrid) * double(h.brickSize);
      if (c.x < 0 || c.y < 0 || c.z < 0 || c.x >= limit.x || c.y >= limit.y || c.z >= limit.z) continue;
      ParticleKind kind = ParticleKind::Liquid;
      if (typed) {
        const float flags = types[i];
        kind = flags == 2 ? ParticleKind::Spray : flags == 4 ? ParticleKind::Bubble : flags == 8 ? ParticleKind::Foam
                                                                                                 : ParticleKind::Liquid;
      }
      const std::uint64_t key = packCell(std::uint64_t(c.x), std::uint64_t(c.y), std::uint64_t(c.z));
      auto [it, fresh] = cells.emplace(key, kind);
      if (!fresh) it->second = std::min(it->second, kind);
    }
  };
  add(kFlip30, false);
  add(kSecondary30, true);
  return cells;
}

std::array<std::uint64_t, kParticleKindCount> countKinds(const CellKinds& cells) {
  std::array<std::uint64_t, kParticleKindCount> counts{};
  for (const auto& [cell, kind] : cells) ++counts[std::size_t(kind)];
  return counts;
}

TEST(ConvertKinds, MantaflowFlipAndSecondaryFilesGiveKindsThatMatchAnOracle) {
  ASSERT_TRUE(fs::exists(kSecondary30)) << kSecondary30;
  testing::TempDir dir("kinds-mantaflow");
  ConvertOptions options = silent();
  options.resolution = 200;  // finer than the particle spacing: cells of one kind and of mixed kinds
  const ConvertReport report = convert({{30, {kFlip30, kSecondary30}}}, dir / "store", options);
  const BrickStore store = BrickStore::open(dir / "store");
  ASSERT_TRUE(store.header().particleKinds);
  EXPECT_EQ(store.header().version, kStoreVersion);
  const CellKinds stored = storedCellKinds(store, 30);
  const CellKinds oracle = oracleCellKinds(store.header());
  const auto counts = countKinds(oracle);
  for (std::size_t k = 0; k < kParticleKindCount; ++k)
    EXPECT_GT(counts[k], 0u) << particleKindName(ParticleKind(k)) << ": the sample has cells of every kind";
  EXPECT_EQ(countKinds(stored), counts);
  EXPECT_EQ(store.frame(30)->stats.kindCells, counts) << "the footer's counts";
  EXPECT_EQ(report.frames[0].stats.kindCells, counts);
  EXPECT_TRUE(stored == oracle) << "cell by cell";
  EXPECT_EQ(store.frame(30)->stats.particles, 14554u + 36497u);
}

/// checksum64 over a frame file but its footer: the payloads, the octree and the brick table.
std::uint64_t framePayloadsAndIndex(const BrickStore& store, int frame) {
  const std::string bytes = testing::readBytes(store.framePath(frame));
  const std::size_t footer = frameFooterBytes(store.header().version);
  return checksum64(bytes.data(), bytes.size() - footer);
}

/// convert(inputs) into a store at `dir` of `header` but for its version, which is `version`.
void convertIntoVersion(const std::vector<FrameInput>& inputs, StoreHeader header, std::uint32_t version,
                        const fs::path& dir, ConvertOptions options) {
  header.version = version;
  header.id = randomStoreId();
  fs::create_directories(dir);
  const auto bytes = serializeStoreHeader(header);
  testing::writeBytes(dir / kStoreHeaderName, std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  options.append = true;  // into the store without frames, not a new one
  convert(inputs, dir, options);
  ASSERT_EQ(BrickStore::open(dir).header().version, version);
}

TEST(ConvertKinds, FlipOnlyFrameHasNoKindsAndTheBytesOfBefore) {
  testing::TempDir dir("kinds-flip");
  const std::vector<FrameInput> flip{{30, {kFlip30}}};
  convert(flip, dir / "store", silent());
  const BrickStore store = BrickStore::open(dir / "store");
  EXPECT_FALSE(store.header().particleKinds);
  EXPECT_EQ(store.frame(30)->stats.kindCells, (std::array<std::uint64_t, kParticleKindCount>{}));
  EXPECT_TRUE(store.readBrick(*store.frame(30), 0).kinds.empty());
  // What this version writes (7: the FLIP file's speed coded as deltas), checksummed over all
  // but the footer.
  EXPECT_EQ(framePayloadsAndIndex(store, 30), 13144045917115703811ull);
  // Into a version 6 store, what flipscope wrote before particle kinds (version 4, commit
  // a6329ec, the same default `convert`), checksummed in the same way: all but the footer,
  // which grew by the kind counts.
  convertIntoVersion(flip, store.header(), 6, dir / "v6", silent());
  EXPECT_EQ(framePayloadsAndIndex(BrickStore::open(dir / "v6"), 30), 4298729064305623437ull);
  // The FLIP and secondary files with --kind-attribute none: the same too.
  ConvertOptions none = silent();
  none.kindAttribute = "none";
  const std::vector<FrameInput> pair{{30, {kFlip30, kSecondary30}}};
  convert(pair, dir / "none", none);
  const BrickStore both = BrickStore::open(dir / "none");
  EXPECT_FALSE(both.header().particleKinds);
  EXPECT_EQ(framePayloadsAndIndex(both, 30), 16379238223709756725ull);
  convertIntoVersion(pair, both.header(), 6, dir / "none-v6", none);
  EXPECT_EQ(framePayloadsAndIndex(BrickStore::open(dir / "none-v6"), 30), 5215621096355647369ull);
}

TEST(ConvertKinds, OutOfCoreGivesTheStoreOfInCore) {
  testing::TempDir dir("kinds-spill");
  // Each file twice: more particles than the smallest budget bins at once.
  const std::vector<FrameInput> inputs{{30, {kFlip30, kSecondary30, kFlip30, kSecondary30}}};
  ConvertOptions options = silent();
  options.brickSize = 32;
  options.resolution = 200;
  const ConvertReport inCore = convert(inputs, dir / "core", options);
  ASSERT_EQ(inCore.frames[0].spillBuckets, 0u);
  options.memoryBudget = 1 << 20;
  const ConvertReport spilled = convert(inputs, dir / "spill", options);
  ASSERT_GT(spilled.frames[0].spillBuckets, 0u) << "the frame was binned in core";
  testing::expectSameFrames(dir / "core", dir / "spill");
  EXPECT_EQ(inCore.frames[0].stats.kindCells, spilled.frames[0].stats.kindCells);
  EXPECT_TRUE(BrickStore::open(dir / "spill").header().particleKinds);
}

TEST(ConvertKinds, KindAttributeByNameNoneAndErrors) {
  testing::TempDir dir("kinds-named");
  const std::vector<FrameInput> inputs{{30, {kFlip30, kSecondary30}}};
  ConvertOptions options = silent();
  options.resolution = 100;
  convert(inputs, dir / "auto", options);
  // U by name: the FLIP file's U (0 and 1) is liquid, so the same store as auto's.
  options.kindAttribute = "U";
  convert(inputs, dir / "named", options);
  EXPECT_TRUE(BrickStore::open(dir / "named").header().particleKinds);
  testing::expectSameFrames(dir / "auto", dir / "named");
  options.kindAttribute = "none";
  convert(inputs, dir / "none", options);
  EXPECT_FALSE(BrickStore::open(dir / "none").header().particleKinds);
  options.kindAttribute = "particles_velocity_secondary";
  testing::expectFileError([&] { convert(inputs, dir / "float", options); },
                           {kSecondary30.string(), "--kind-attribute", "particles_velocity_secondary", "float32"});
  options.kindAttribute = "nosuch";
  testing::expectFileError([&] { convert(inputs, dir / "nosuch", options); },
                           {kFlip30.string(), "--kind-attribute", "'nosuch'", "particles_velocity"});
  EXPECT_FALSE(fs::exists(dir / "nosuch"));
}

TEST(ConvertKinds, VersionFourStoresOpenWithoutKindsAndStayVersionFour) {
  testing::TempDir dir("kinds-v4");
  // A version 4 store, as flipscope wrote it before particle kinds.
  ConvertOptions options = silent();
  options.domain = Box{{0, 0, 0}, {4, 2, 0.6}};
  options.cellSize = 0.05;
  StoreHeader header = makeStoreHeader(*options.domain, options, AttributeKind::Speed);
  header.version = 4;
  header.id = randomStoreId();
  const fs::path store = dir / "store";
  fs::create_directories(store);
  const auto bytes = serializeStoreHeader(header);
  testing::writeBytes(store / kStoreHeaderName, std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  BrickStore v4 = BrickStore::open(store);
  EXPECT_EQ(v4.header().version, 4u);
  EXPECT_FALSE(v4.header().particleKinds);
  auto flip = openParticleFile(kFlip30);
  convertFrame(*flip, v4, 1, options);
  // Appending the FLIP and secondary files keeps version 4: no kinds, with a warning.
  const ConvertReport report = convert({{30, {kFlip30, kSecondary30}}}, store, options);
  ASSERT_FALSE(report.warnings.empty());
  EXPECT_NE(report.warnings.back().find("no particle kinds"), std::string::npos) << report.warnings.back();
  const BrickStore back = BrickStore::open(store);
  EXPECT_EQ(back.header().version, 4u);
  EXPECT_FALSE(back.header().particleKinds);
  EXPECT_EQ(back.frames(), (std::vector<int>{1, 30}));
  for (int f : back.frames()) {
    const auto index = back.frame(f);
    EXPECT_EQ(index->fileBytes - index->bricks.size() * 40 - 8 * index->octree.nodes.size() - 8 -
                  [&] {
                    std::uint64_t payloads = 0;
                    for (const auto& b : index->bricks) payloads += b.bytes;
                    return payloads;
                  }(),
              kFrameFooterBytes)
        << "a version 4 footer";
    EXPECT_EQ(index->stats.kindCells, (std::array<std::uint64_t, kParticleKindCount>{}));
    EXPECT_TRUE(back.readBrick(*index, 0).kinds.empty());
  }
  EXPECT_EQ(back.frame(30)->stats.particles, 14554u + 36497u);
  // Kinds asked for by name are refused for it.
  options.kindAttribute = "U";
  try {
    convert({{31, {kFlip30, kSecondary30}}}, store, options);
    FAIL() << "appended kinds to a version 4 store";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no particle kinds (store version 4)"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace flipscope
