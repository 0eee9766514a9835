// convert with ConvertOptions::attribute: any attribute of the inputs stored as the 16-bit
// per-particle attribute (a scalar as it is, a vector by its length), its name and range in the
// store, the quantized values particle by particle, the messages for a missing name and for
// appending another attribute, and version 3 stores (speed only) read and appended to.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <vector>

#include <glm/geometric.hpp>

#include "ParticleTestSupport.h"
#include "preprocess/BrickBinning.h"
#include "preprocess/Convert.h"
#include "preprocess/store/FrameFile.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;
using testing::expectFileError;
using testing::TempDir;

/// Particle i of a frame: the centre of its own cell of a 10x10x10 grid of unit cells.
glm::vec3 cellCentre(std::size_t i) {
  return {float(i % 10) + 0.5f, float((i / 10) % 10) + 0.5f, float(i / 100) + 0.5f};
}

/// An ascii PLY of `count` particles, one per cell, with velocity (vx vy vz), a float
/// `temperature` and an int `id`: temperature(i) = base + 0.37 i (some negative), id = 7 i.
fs::path writePly(const fs::path& path, std::size_t count, float base) {
  std::string text = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(count) +
                     "\nproperty float x\nproperty float y\nproperty float z\nproperty float vx\nproperty float vy\n"
                     "property float vz\nproperty float temperature\nproperty int id\nend_header\n";
  for (std::size_t i = 0; i < count; ++i) {
    const glm::vec3 p = cellCentre(i);
    char line[256];
    std::snprintf(line, sizeof line, "%.9g %.9g %.9g %.9g %.9g %.9g %.9g %d\n", p.x, p.y, p.z, 0.5 * double(i % 7),
                  -1.0, 0.25, double(base + 0.37f * float(i)), int(7 * i));
    text += line;
  }
  testing::writeBytes(path, text);
  return path;
}

float temperature(std::size_t i, float base) { return base + 0.37f * float(i); }

ConvertOptions unitCells() {
  ConvertOptions options;
  options.cellSize = 1.0;
  options.domain = Box{{0, 0, 0}, {10, 10, 10}};
  options.particleSpacing = 1.0;
  options.brickSize = 32;
  options.progress = Progress::Mode::Silent;
  return options;
}

/// The stored 16-bit value of every particle of `frame`, by cell (one particle a cell).
std::map<std::uint32_t, std::uint16_t> storedValues(const BrickStore& store, int frame) {
  std::map<std::uint32_t, std::uint16_t> byCell;
  auto index = store.frame(frame);
  for (std::uint32_t b = 0; b < index->bricks.size(); ++b) {
    const DecodedBrick brick = store.readBrick(*index, b);
    EXPECT_EQ(brick.attributes.size(), brick.particleCount());
    std::size_t particle = 0;
    for (std::size_t c = 0; c < brick.cells.size(); ++c) {
      EXPECT_EQ(brick.counts[c], 1u);
      byCell[brick.cells[c]] = brick.attributes[particle];
      particle += brick.counts[c];
    }
  }
  return byCell;
}

std::uint32_t cellIndex(std::size_t i) {
  const glm::vec3 p = cellCentre(i);
  return std::uint32_t(p.x) + 32 * (std::uint32_t(p.y) + 32 * std::uint32_t(p.z));
}

TEST(ConvertAttribute, StoresAScalarAttributeOfThePlyWithItsNameAndRange) {
  TempDir dir("convert-attr");
  const float bases[2] = {-20.0f, 5.5f};
  const std::size_t counts[2] = {300, 250};
  std::vector<FrameInput> inputs;
  for (int f = 0; f < 2; ++f)
    inputs.push_back({f, {writePly(dir / ("t" + std::to_string(f) + ".ply"), counts[f], bases[f])}});
  ConvertOptions options = unitCells();
  options.attribute = "temperature";
  const ConvertReport report = convert(inputs, dir / "store", options);
  EXPECT_EQ(report.header.attribute, AttributeKind::Scalar);
  EXPECT_EQ(report.header.attributeName, "temperature");

  const BrickStore store = BrickStore::open(dir / "store");
  EXPECT_EQ(store.header().version, kStoreVersion);
  EXPECT_EQ(store.header().attribute, AttributeKind::Scalar);
  EXPECT_EQ(store.header().attributeName, "temperature");
  for (int f = 0; f < 2; ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    const FrameStats stats = store.frame(f)->stats;
    const float lo = temperature(0, bases[f]), hi = temperature(counts[f] - 1, bases[f]);
    EXPECT_EQ(stats.attributeMin, lo);
    EXPECT_EQ(stats.attributeMax, hi);
    const auto values = storedValues(store, f);
    ASSERT_EQ(values.size(), counts[f]);
    for (std::size_t i = 0; i < counts[f]; ++i)
      ASSERT_EQ(values.at(cellIndex(i)), detail::quantizeAttribute(temperature(i, bases[f]), lo, hi)) << i;
    EXPECT_EQ(values.at(cellIndex(0)), 0);
    EXPECT_EQ(values.at(cellIndex(counts[f] - 1)), 65535);
  }
  // The store's range: over both frames, recorded in store.fsh.
  const auto range = store.attributeRange();
  ASSERT_TRUE(range);
  EXPECT_EQ(range->min, temperature(0, bases[0]));
  EXPECT_EQ(range->max, temperature(counts[1] - 1, bases[1]));

  // An int attribute is a scalar too; velocities are not read for it.
  options.attribute = "id";
  convert({inputs[0]}, dir / "ids", options);
  const BrickStore ids = BrickStore::open(dir / "ids");
  EXPECT_EQ(ids.frame(0)->stats.attributeMax, float(7 * (counts[0] - 1)));
  EXPECT_EQ(storedValues(ids, 0).at(cellIndex(1)), detail::quantizeAttribute(7.0f, 0.0f, float(7 * (counts[0] - 1))));
}

TEST(ConvertAttribute, SpeedStaysTheDefaultAndNoneStoresNone) {
  TempDir dir("convert-speed");
  const std::vector<FrameInput> inputs{{0, {writePly(dir / "a.ply", 120, 1.0f)}}};
  ConvertOptions options = unitCells();
  const ConvertReport automatic = convert(inputs, dir / "auto", options);
  EXPECT_EQ(automatic.header.attribute, AttributeKind::Speed);
  EXPECT_EQ(automatic.header.attributeName, "speed");
  const auto values = storedValues(BrickStore::open(dir / "auto"), 0);
  const float hi = glm::length(glm::vec3(3.0f, -1.0f, 0.25f)), lo = glm::length(glm::vec3(0.0f, -1.0f, 0.25f));
  for (std::size_t i = 0; i < 120; ++i)
    ASSERT_EQ(values.at(cellIndex(i)),
              detail::quantizeAttribute(glm::length(glm::vec3(0.5f * float(i % 7), -1.0f, 0.25f)), lo, hi));
  options.attribute = "speed";
  EXPECT_EQ(convert(inputs, dir / "speed", options).header.attribute, AttributeKind::Speed);
  options.attribute = "none";
  const ConvertReport none = convert(inputs, dir / "none", options);
  EXPECT_EQ(none.header.attribute, AttributeKind::None);
  EXPECT_EQ(none.header.attributeName, "");
  EXPECT_FALSE(BrickStore::open(dir / "none").attributeRange());
}

TEST(ConvertAttribute, AVectorAttributeIsStoredByItsLength) {
  TempDir dir("convert-vector");
  // VDB points with a vec3s `v`: stored as its length, the same values as speed.
  WriteOptions write;
  write.velocity = true;
  ParticleChunk particles;
  for (std::size_t i = 0; i < 200; ++i) {
    particles.positions.push_back(cellCentre(i));
    particles.velocities.emplace_back(0.1f * float(i % 13), 2.0f, -0.5f * float(i % 3));
  }
  const fs::path vdb = dir / "p.vdb";
  testing::writeFile(vdb, particles, write);
  ConvertOptions options = unitCells();
  options.attribute = "v";
  const ConvertReport report = convert({{0, {vdb}}}, dir / "v", options);
  EXPECT_EQ(report.header.attribute, AttributeKind::Magnitude);
  EXPECT_EQ(report.header.attributeName, "v");
  options.attribute = "speed";
  convert({{0, {vdb}}}, dir / "speed", options);
  const BrickStore v = BrickStore::open(dir / "v"), speed = BrickStore::open(dir / "speed");
  EXPECT_EQ(v.frame(0)->stats.attributeMin, speed.frame(0)->stats.attributeMin);
  EXPECT_EQ(v.frame(0)->stats.attributeMax, speed.frame(0)->stats.attributeMax);
  EXPECT_EQ(storedValues(v, 0), storedValues(speed, 0));
}

TEST(ConvertAttribute, AMissingNameNamesTheFileAndWhatItHolds) {
  TempDir dir("convert-missing");
  const std::vector<FrameInput> inputs{{0, {writePly(dir / "few.ply", 10, 0.0f)}}};
  ConvertOptions options = unitCells();
  options.attribute = "pscale";
  expectFileError([&] { convert(inputs, dir / "store", options); },
                  {"few.ply", "has no attribute 'pscale'", "vx, vy, vz, temperature, id"});
  EXPECT_FALSE(fs::exists(dir / "store"));
  // speed without velocities (raw positions) is refused the same way.
  const fs::path raw = dir / "p.bin";
  testing::writeBytes(raw, std::string(12 * 4, '\0'));
  options.attribute = "speed";
  expectFileError([&] { convert({{0, {raw}}}, dir / "raw", options); }, {"p.bin", "no attribute 'speed'"});
}

TEST(ConvertAttribute, AppendingKeepsTheStoresAttributeAndRefusesAnother) {
  TempDir dir("convert-append");
  ConvertOptions options = unitCells();
  options.attribute = "temperature";
  convert({{0, {writePly(dir / "a.ply", 50, 0.0f)}}}, dir / "store", options);
  // Another attribute: refused, naming both.
  options.attribute = "id";
  try {
    convert({{1, {writePly(dir / "b.ply", 50, 100.0f)}}}, dir / "store", options);
    FAIL() << "appended another attribute";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("keeps the attribute 'temperature'"), std::string::npos) << message;
    EXPECT_NE(message.find("'id'"), std::string::npos) << message;
  }
  // auto keeps the store's, and the store's range widens.
  options.attribute.reset();
  convert({{1, {writePly(dir / "b.ply", 50, 100.0f)}}}, dir / "store", options);
  const BrickStore store = BrickStore::open(dir / "store");
  EXPECT_EQ(store.frames(), (std::vector<int>{0, 1}));
  EXPECT_EQ(store.frame(1)->stats.attributeMin, 100.0f);
  ASSERT_TRUE(store.attributeRange());
  // Within a few ulps: compilers may contract the test's arithmetic into FMAs differently.
  EXPECT_FLOAT_EQ(store.attributeRange()->min, 0.0f);
  EXPECT_FLOAT_EQ(store.attributeRange()->max, temperature(49, 100.0f));
}

TEST(ConvertAttribute, VersionThreeStoresAreReadAndAppendedToAsVersionThree) {
  TempDir dir("convert-v3");
  // A version 3 store with a speed attribute, as flipscope wrote it before attribute names.
  ConvertOptions options = unitCells();
  StoreHeader header = makeStoreHeader(*options.domain, options, AttributeKind::Speed);
  header.version = 3;
  header.id = randomStoreId();
  const fs::path store = dir / "store";
  fs::create_directories(store);
  {
    const auto bytes = serializeStoreHeader(header);
    testing::writeBytes(store / kStoreHeaderName,
                        std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  }
  BrickStore v3 = BrickStore::open(store);
  ASSERT_EQ(v3.header().version, 3u);
  EXPECT_EQ(v3.header().attributeName, "speed");
  const std::vector<FrameInput> inputs{{0, {writePly(dir / "a.ply", 80, 0.0f)}}};
  auto source = openParticleFile(inputs[0].files[0]);
  const FrameReport first = convertFrame(*source, v3, 0, options);
  EXPECT_GT(first.stats.attributeMax, 0.0f);

  // Appending through convert() keeps version 3 (frames and store.fsh).
  convert({{3, {writePly(dir / "b.ply", 40, 0.0f)}}}, store, options);
  const BrickStore back = BrickStore::open(store);
  EXPECT_EQ(back.header().version, 3u);
  EXPECT_EQ(back.frames(), (std::vector<int>{0, 3}));
  EXPECT_EQ(back.header().attribute, AttributeKind::Speed);
  const auto range = back.attributeRange();  // gathered from the frames' footers
  ASSERT_TRUE(range);
  EXPECT_EQ(range->min, std::min(back.frame(0)->stats.attributeMin, back.frame(3)->stats.attributeMin));
  EXPECT_EQ(range->max, std::max(back.frame(0)->stats.attributeMax, back.frame(3)->stats.attributeMax));
  EXPECT_EQ(storedValues(back, 3).size(), 40u);
  // Its payloads lay the values out as version 3 did (AttributeCoding::Values), not as this
  // version does.
  const auto index = back.frame(3);
  for (std::uint32_t b = 0; b < index->bricks.size(); ++b) {
    const UninitializedVector<std::byte> payload = back.readPayload(*index, b);
    const DecodedBrick read = back.readBrick(*index, b);
    const auto decode = [&](AttributeCoding coding) {
      return decodeBrick(payload, "f", b, index->bricks[b], back.header().cellsPerBrick(), true, false, coding)
          .attributes;
    };
    EXPECT_EQ(decode(AttributeCoding::Values), read.attributes);
    EXPECT_NE(decode(AttributeCoding::CellDeltas), read.attributes);
  }
  // A version 3 frame file in a store of this version is refused, naming both versions.
  StoreHeader current = header;
  current.version = kStoreVersion;
  try {
    readFrameIndex(back.framePath(0), current);
    FAIL();
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("unsupported frame version 3 (the store is version " +
                                         std::to_string(kStoreVersion)),
              std::string::npos)
        << e.what();
  }
}

TEST(StoreHeaderAttribute, NameAndRangeRoundTripAndAreChecked) {
  StoreHeader h;
  h.cellSize = 1;
  h.brickGrid = {1, 1, 1};
  h.attribute = AttributeKind::Magnitude;
  h.attributeName = "Cd";
  std::vector<int> frames{2, 3, 9};
  const AttributeRange range{-1.5f, 7.25f};
  std::vector<int> backFrames;
  std::optional<AttributeRange> backRange;
  const StoreHeader back =
      parseStoreHeader(serializeStoreHeader(h, frames, range), "store.fsh", &backFrames, &backRange);
  EXPECT_EQ(back.attribute, AttributeKind::Magnitude);
  EXPECT_EQ(back.attributeName, "Cd");
  EXPECT_EQ(backFrames, frames);
  ASSERT_TRUE(backRange);
  EXPECT_EQ(*backRange, range);
  // No range; a name that does not fit its kind; a range min above max.
  EXPECT_FALSE(([&] {
    std::optional<AttributeRange> r;
    parseStoreHeader(serializeStoreHeader(h, frames), "store.fsh", nullptr, &r);
    return r;
  })());
  StoreHeader unnamed = h;
  unnamed.attributeName.clear();
  EXPECT_THROW(parseStoreHeader(serializeStoreHeader(unnamed), "store.fsh"), FileError);
  StoreHeader none = h;
  none.attribute = AttributeKind::None;
  EXPECT_THROW(parseStoreHeader(serializeStoreHeader(none), "store.fsh"), FileError);
  EXPECT_THROW(parseStoreHeader(serializeStoreHeader(h, frames, AttributeRange{2.0f, 1.0f}), "store.fsh"), FileError);
}

}  // namespace
}  // namespace flipscope
