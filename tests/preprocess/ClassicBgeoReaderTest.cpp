// The Houdini classic geometry reader (preprocess/particles/houdini/ClassicBgeo*.cpp): partio's
// real BgeoV and PGEOMETRY files with their declared counts and values, round trips through the
// test writer (binary and ASCII, every attribute type, many chunks), the bgeo-in-gzip path, and
// damage.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <map>

#include "ClassicBgeoTestWriter.h"
#include "DamageTestSupport.h"
#include "GzipTestWriter.h"
#include "ParticleTestSupport.h"
#include "preprocess/particles/ParticleFormatRegistry.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;
using testing::expectFileError;
using testing::TempDir;

const fs::path kClassicFolder = fs::path(FLIPSCOPE_DATA_DIR) / "formats" / "houdini-classic";

/// The point count the file's header declares (BgeoV: big-endian int32 at byte 9).
std::uint64_t declaredPoints(const std::string& bytes) {
  if (bytes.rfind("BgeoV", 0) == 0) {
    std::uint32_t n;
    std::memcpy(&n, bytes.data() + 9, 4);
    return __builtin_bswap32(n);
  }
  const std::size_t at = bytes.find("NPoints ");
  return std::stoull(bytes.substr(at + 8));
}

struct ReadAll {
  ParticleChunk particles;
  std::map<std::string, std::vector<float>> attributes;
};

ReadAll readWithAttributes(ParticleSource& source, std::size_t chunkSize) {
  ReadAll all;
  ParticleChunk chunk;
  while (source.read(chunk, chunkSize)) {
    all.particles.positions.insert(all.particles.positions.end(), chunk.positions.begin(), chunk.positions.end());
    all.particles.velocities.insert(all.particles.velocities.end(), chunk.velocities.begin(), chunk.velocities.end());
    for (const auto& column : chunk.attributes) {
      EXPECT_EQ(column.values.size(), chunk.size() * std::size_t(column.arity)) << column.name;
      auto& values = all.attributes[column.name];
      values.insert(values.end(), column.values.begin(), column.values.end());
    }
  }
  return all;
}

TEST(ClassicBgeoReader, RealFilesReadWithTheirDeclaredCounts) {
  ASSERT_TRUE(fs::is_directory(kClassicFolder)) << kClassicFolder;
  int files = 0;
  for (const auto& entry : fs::directory_iterator(kClassicFolder)) {
    const fs::path& path = entry.path();
    SCOPED_TRACE(path.filename().string());
    const std::string bytes = testing::readBytes(path);
    ReadOptions options;
    options.allAttributes = true;
    auto source = openParticleFile(path, options);
    EXPECT_NE(source->format().find("Houdini classic"), std::string::npos) << source->format();
    const std::uint64_t declared = declaredPoints(bytes);
    EXPECT_EQ(source->countHint(), declared);
    const ReadAll all = readWithAttributes(*source, 3);
    EXPECT_EQ(all.particles.size(), declared);
    for (const auto& a : source->attributes())
      EXPECT_EQ(all.attributes.at(a.name).size(), declared * std::size_t(a.arity)) << a.name;
    ++files;
  }
  EXPECT_GE(files, 3);
}

TEST(ClassicBgeoReader, RealFileValues) {
  // test.bgeo and its ASCII twin test.geo (partio's): 5 points with life[2] and id, one
  // particle primitive with an index attribute.
  for (const char* name : {"test.bgeo", "test.geo"}) {
    SCOPED_TRACE(name);
    ReadOptions options;
    options.allAttributes = true;
    auto source = openParticleFile(kClassicFolder / name, options);
    const std::vector<AttributeDesc> expected = {{"life", ValueType::Float32, 2}, {"id", ValueType::Int32, 1}};
    EXPECT_EQ(source->attributes(), expected);
    EXPECT_FALSE(source->hasVelocity());
    const ReadAll all = readWithAttributes(*source, 2);
    ASSERT_EQ(all.particles.size(), 5u);
    const float coordinates[7] = {0.f, 0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f};
    const float life[5] = {-1.2f, -0.2f, 0.8f, 1.8f, 2.8f};
    for (int p = 0; p < 5; ++p) {
      EXPECT_EQ(all.particles.positions[p], glm::vec3(coordinates[p], coordinates[p + 1], coordinates[p + 2])) << p;
      EXPECT_EQ(all.attributes.at("life")[2 * p], life[p]) << p;
      EXPECT_EQ(all.attributes.at("life")[2 * p + 1], 10.f);
      EXPECT_EQ(all.attributes.at("id")[p], float(p));
    }
  }
  if (fs::exists(kClassicFolder / "scatter.bgeo")) {  // Cd (float[3]), id, and an index attribute (not numeric)
    ReadOptions options;
    options.attributes = {"Cd", "id"};
    auto source = openParticleFile(kClassicFolder / "scatter.bgeo", options);
    const std::vector<AttributeDesc> expected = {{"id", ValueType::Int32, 1}, {"Cd", ValueType::Float32, 3}};
    EXPECT_EQ(source->attributes(), expected);
    const ReadAll all = readWithAttributes(*source, 10);
    ASSERT_EQ(all.particles.size(), 25u);
    EXPECT_EQ(all.particles.positions[0], glm::vec3(-0.038692329078912735f, -0.9017146825790405f, 1.3786622285842896f));
    EXPECT_EQ(all.attributes.at("Cd")[0], 0.9219434261322021f);
    EXPECT_EQ(all.attributes.at("Cd")[2], 0.21119284629821777f);
    EXPECT_EQ(all.attributes.at("id")[24], 24.f);
  }
  if (fs::exists(kClassicFolder / "reindeer.bgeo")) {  // 491 point attributes, among them v
    auto source = openParticleFile(kClassicFolder / "reindeer.bgeo");
    EXPECT_TRUE(source->hasVelocity());
    EXPECT_GT(source->attributes().size(), 400u);
    EXPECT_EQ(testing::readAll(*source, 5).size(), 16u);
  }
  if (fs::exists(kClassicFolder / "json.bgeo")) {  // despite its name a classic BgeoV, with a string (index) attribute
    auto source = openParticleFile(kClassicFolder / "json.bgeo");
    const std::vector<AttributeDesc> expected = {{"life", ValueType::Float32, 2}, {"id", ValueType::Int32, 1}};
    EXPECT_EQ(source->attributes(), expected);
    EXPECT_EQ(testing::readAll(*source, 5).size(), 5u);
  }
}

const std::vector<testing::BgeoAttributeSpec> kAttributes = {
    {"pscale", 0, 1, {}}, {"v", 5, 3, {}}, {"id", 1, 1, {}}, {"name", 4, 1, {"a", "bb"}}, {"uv", 0, 2, {}}};

float position(std::size_t p, int axis) { return float(p) * 0.25f - 100.f + float(axis) * 1.5f; }
double value(std::size_t p, std::size_t attribute, int c) {
  switch (attribute) {
    case 0:
      return 0.5 + double(p % 7);
    case 1:
      return double(p) * 0.125 * (c + 1) - 3;
    case 2:
      return double(p) - 50;
    case 3:
      return double(p % 2);
    default:
      return double(c) - double(p) * 0.5;
  }
}

void expectRoundTrip(const std::string& name, const std::string& bytes, std::size_t count) {
  TempDir dir("bgeo-roundtrip");
  testing::writeBytes(dir / name, bytes);
  for (std::size_t chunkSize : {std::size_t(1), std::size_t(7), std::size_t(1000), count + 1}) {
    SCOPED_TRACE(name + " in chunks of " + std::to_string(chunkSize));
    ReadOptions options;
    options.allAttributes = true;
    auto source = openParticleFile(dir / name, options);
    const std::vector<AttributeDesc> expected = {{"pscale", ValueType::Float32, 1},
                                                 {"v", ValueType::Float32, 3},
                                                 {"id", ValueType::Int32, 1},
                                                 {"uv", ValueType::Float32, 2}};
    ASSERT_EQ(source->attributes(), expected);
    ASSERT_TRUE(source->hasVelocity());
    for (int pass = 0; pass < 2; ++pass) {
      const ReadAll all = readWithAttributes(*source, chunkSize);
      ASSERT_EQ(all.particles.size(), count);
      for (std::size_t p = 0; p < count; ++p) {
        ASSERT_EQ(all.particles.positions[p], glm::vec3(position(p, 0), position(p, 1), position(p, 2))) << p;
        ASSERT_EQ(all.particles.velocities[p],
                  glm::vec3(float(value(p, 1, 0)), float(value(p, 1, 1)), float(value(p, 1, 2))));
        ASSERT_EQ(all.attributes.at("pscale")[p], float(value(p, 0, 0)));
        ASSERT_EQ(all.attributes.at("id")[p], float(value(p, 2, 0)));
        ASSERT_EQ(all.attributes.at("uv")[2 * p + 1], float(value(p, 4, 1)));
        ASSERT_EQ(all.attributes.at("v")[3 * p + 2], float(value(p, 1, 2)));
      }
      source->rewind();
    }
  }
}

TEST(ClassicBgeoReader, RoundTripBinaryAndAscii) {
  for (bool primitive : {false, true})
    for (bool detail : {false, true}) {
      const testing::BgeoWriteOptions options{primitive, detail};
      expectRoundTrip("points.bgeo", testing::makeClassicBgeo(2345, kAttributes, position, value, options), 2345);
      expectRoundTrip("points.geo", testing::makeClassicGeo(2345, kAttributes, position, value, options), 2345);
    }
  // More than 65535 points: the particle primitive's point indices are 32-bit.
  testing::BgeoWriteOptions options;
  options.particlePrimitive = true;
  TempDir dir("bgeo-wide");
  testing::writeBytes(dir / "wide.bgeo", testing::makeClassicBgeo(70000, kAttributes, position, value, options));
  EXPECT_EQ(testing::readFile(dir / "wide.bgeo", 4096).size(), 70000u);
}

TEST(ClassicBgeoReader, SelectsAttributesAndVelocity) {
  TempDir dir("bgeo-select");
  testing::writeBytes(dir / "p.bgeo", testing::makeClassicBgeo(10, kAttributes, position, value));
  ReadOptions options;
  options.attributes = {"uv", "id"};
  options.velocity = false;
  auto source = openParticleFile(dir / "p.bgeo", options);
  EXPECT_FALSE(source->hasVelocity());
  ParticleChunk chunk;
  ASSERT_TRUE(source->read(chunk, 100));
  ASSERT_EQ(chunk.attributes.size(), 2u);
  EXPECT_EQ(chunk.attributes[0].name, "uv");
  EXPECT_EQ(chunk.attributes[0].values[3], float(value(1, 4, 1)));
  EXPECT_EQ(chunk.attributes[1].name, "id");
  EXPECT_TRUE(chunk.velocities.empty());
  options.attributes = {"name"};  // an index (string) attribute is not a numeric attribute
  expectFileError([&] { openParticleFile(dir / "p.bgeo", options); }, {"p.bgeo", "no attribute 'name'", "pscale"});
}

TEST(ClassicBgeoReader, RecognisedByContentAndThroughGzip) {
  TempDir dir("bgeo-gzip");
  const std::string plain = testing::readBytes(kClassicFolder / "test.bgeo");
  const ParticleChunk expected = testing::readFile(kClassicFolder / "test.bgeo");
  for (const char* name : {"test.bgeo.gz", "test.dat", "test.gz"}) {
    const std::string bytes = std::string(name) == "test.dat" ? plain : testing::gzip(plain);
    testing::writeBytes(dir / name, bytes);
    auto source = openParticleFile(dir / name);
    EXPECT_NE(source->format().find("BgeoV"), std::string::npos) << name;
    const ParticleChunk read = testing::readAll(*source, 2);
    EXPECT_EQ(read.positions, expected.positions) << name;
  }
  const std::string geo = testing::makeClassicGeo(500, kAttributes, position, value);
  testing::writeBytes(dir / "many.geo.gz", testing::gzip(geo, 3));
  testing::writeBytes(dir / "many.geo", geo);
  EXPECT_EQ(testing::readFile(dir / "many.geo.gz", 64).positions, testing::readFile(dir / "many.geo").positions);
}

TEST(ClassicBgeoReader, RefusesWhatItCannotRead) {
  TempDir dir("bgeo-refuse");
  std::string bytes = testing::makeClassicBgeo(3, kAttributes, position, value);
  bytes[8] = 4;  // version 4
  testing::writeBytes(dir / "v4.bgeo", bytes);
  expectFileError([&] { testing::readFile(dir / "v4.bgeo"); }, {"v4.bgeo", "version 4", "version 5"});
  std::vector<testing::BgeoAttributeSpec> mixed = {{"m", 3, 1, {}}};
  testing::writeBytes(dir / "mixed.bgeo", testing::makeClassicBgeo(3, mixed, position, value));
  expectFileError([&] { testing::readFile(dir / "mixed.bgeo"); }, {"mixed.bgeo", "point attribute 'm'", "mixed"});
  // Garbage after the end of the geometry.
  testing::writeBytes(dir / "tail.bgeo", testing::makeClassicBgeo(3, kAttributes, position, value) + "xyz");
  expectFileError([&] { testing::readFile(dir / "tail.bgeo"); }, {"tail.bgeo", "3 bytes of trailing garbage"});
  testing::writeBytes(dir / "tail.geo", testing::makeClassicGeo(3, kAttributes, position, value) + "Poly 3\n");
  expectFileError([&] { testing::readFile(dir / "tail.geo"); }, {"tail.geo", "after 'endExtra'"});
  std::string geo = testing::makeClassicGeo(3, kAttributes, position, value);
  geo.replace(geo.find("PGEOMETRY V5"), 12, "PGEOMETRY V4");
  testing::writeBytes(dir / "v4.geo", geo);
  expectFileError([&] { testing::readFile(dir / "v4.geo"); }, {"v4.geo", "line 1", "V4"});
}

TEST(ClassicBgeoReader, TruncatedAtEveryLengthIsRefused) {
  testing::BgeoWriteOptions options{true, true};
  testing::expectEveryTruncationRefused("test.bgeo", testing::readBytes(kClassicFolder / "test.bgeo"));
  testing::expectEveryTruncationRefused("test.geo", testing::readBytes(kClassicFolder / "test.geo"));
  testing::expectEveryTruncationRefused("w.bgeo", testing::makeClassicBgeo(4, kAttributes, position, value, options));
  testing::expectEveryTruncationRefused("w.geo", testing::makeClassicGeo(4, kAttributes, position, value, options));
  // No points: the header and what follows it (detail attributes here) are all there is.
  const testing::BgeoWriteOptions detail{false, true};
  const std::string none = testing::makeClassicBgeo(0, kAttributes, position, value, detail);
  EXPECT_EQ(testing::readBytesCompletely("none.bgeo", none), 0u);
  testing::expectEveryTruncationRefused("none.bgeo", none);
  const std::string noneGeo = testing::makeClassicGeo(0, kAttributes, position, value, detail);
  EXPECT_EQ(testing::readBytesCompletely("none.geo", noneGeo), 0u);
  testing::expectEveryTruncationRefused("none.geo", noneGeo);
}

TEST(ClassicBgeoReader, SingleByteCorruptionsAreReadOrRefused) {
  for (const char* name : {"test.bgeo", "test.geo", "base.bgeo"}) {
    if (!fs::exists(kClassicFolder / name)) continue;
    const std::size_t refused = testing::expectCorruptionsHandled(name, testing::readBytes(kClassicFolder / name));
    EXPECT_GT(refused, 0u) << name;
  }
}

}  // namespace
}  // namespace flipscope
