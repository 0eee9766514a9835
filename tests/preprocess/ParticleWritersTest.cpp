// The streaming writers of Houdini JSON geometry (.bgeo, .geo, .bgeo.sc, .geo.sc), Krakatoa PRT
// (.prt) and VTK legacy (.vtk): particles written in chunks through createParticleWriter read
// back bit for bit through openParticleFile, with the declared count and the format's name.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "ParticleTestSupport.h"
#include "preprocess/particles/ParticleFormatRegistry.h"
#include "preprocess/particles/ParticleFormats.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;

using testing::expectFileError;
using testing::randomParticles;
using testing::sameBits;
using testing::TempDir;
using testing::writeFile;

struct WriterCase {
  std::string extension;
  std::string format;     ///< the start of the reader's format()
  std::string container;  ///< the container recognised around it, or ""
};

const WriterCase kCases[] = {
    {".bgeo", "Houdini binary JSON geometry (.bgeo), Houdini 18.5.408", ""},
    {".bgeo.sc", "Houdini binary JSON geometry (.bgeo), Houdini 18.5.408", "scf1"},
    {".geo", "Houdini ASCII JSON geometry (.geo), Houdini 18.5.408", ""},
    {".geo.sc", "Houdini ASCII JSON geometry (.geo), Houdini 18.5.408", "scf1"},
    {".prt", "Krakatoa PRT 1.0", ""},
    {".vtk", "VTK legacy 3.0 (binary, POLYDATA)", ""},
};

void PrintTo(const WriterCase& c, std::ostream* os) { *os << c.extension; }

std::string caseName(const WriterCase& c) {
  std::string name = c.extension.substr(1);
  std::replace(name.begin(), name.end(), '.', '_');
  return name;
}

void expectSameParticles(const ParticleChunk& expected, const ParticleChunk& actual, bool velocity) {
  ASSERT_EQ(actual.size(), expected.size());
  ASSERT_EQ(actual.velocities.size(), velocity ? expected.size() : 0u);
  for (std::size_t i = 0; i < expected.size(); ++i) {
    ASSERT_TRUE(sameBits(actual.positions[i], expected.positions[i])) << "position " << i;
    if (velocity) {
      ASSERT_TRUE(sameBits(actual.velocities[i], expected.velocities[i])) << "velocity " << i;
    }
  }
}

/// Writes `count` particles in chunks of `chunkSize` and reads them back.
void roundTrip(const WriterCase& c, std::size_t count, bool velocity, std::size_t chunkSize) {
  TempDir dir("writers");
  const fs::path path = dir / ("p" + c.extension);
  const ParticleChunk particles = randomParticles(count, velocity, unsigned(count + velocity));
  writeFile(path, particles, WriteOptions{.velocity = velocity}, chunkSize);

  RecognisedInput input = recogniseInput(InputFile(path));
  EXPECT_EQ(input.containers, c.container.empty() ? std::vector<std::string>{} : std::vector<std::string>{c.container});
  auto source = input.format->open(std::move(input.file), {});
  EXPECT_EQ(source->format().substr(0, c.format.size()), c.format) << source->format();
  EXPECT_EQ(source->countHint(), count);
  EXPECT_EQ(source->hasVelocity(), velocity);
  const std::vector<AttributeDesc> attributes = source->attributes();
  if (velocity) {
    ASSERT_EQ(attributes.size(), 1u);
    EXPECT_EQ(attributes[0].type, ValueType::Float32);
    EXPECT_EQ(attributes[0].arity, 3);
  } else {
    EXPECT_TRUE(attributes.empty());
  }
  expectSameParticles(particles, testing::readAll(*source, 4099), velocity);
  // Only the file itself is left: no temporary, no spill.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
}

class WriterRoundTrip : public ::testing::TestWithParam<WriterCase> {};

TEST_P(WriterRoundTrip, ManyChunksWithoutVelocity) { roundTrip(GetParam(), 100'000, false, 7'777); }
TEST_P(WriterRoundTrip, ManyChunksWithVelocity) { roundTrip(GetParam(), 100'000, true, 7'777); }
TEST_P(WriterRoundTrip, OneLargeChunkWithVelocity) { roundTrip(GetParam(), 100'000, true, 100'000); }
TEST_P(WriterRoundTrip, SmallFiles) {
  for (std::size_t count : {1, 2, 1'000})
    for (bool velocity : {false, true}) roundTrip(GetParam(), count, velocity, 333);
}

TEST_P(WriterRoundTrip, NothingLeftBehindWithoutCommit) {
  TempDir dir("writers-nocommit");
  {
    auto writer = createParticleWriter(dir / ("p" + GetParam().extension), WriteOptions{.velocity = true});
    writer->write(randomParticles(50'000, true, 3));
  }
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST_P(WriterRoundTrip, NoParticles) {
  TempDir dir("writers-empty");
  const fs::path path = dir / ("e" + GetParam().extension);
  writeFile(path, ParticleChunk{}, WriteOptions{.velocity = true});
  if (GetParam().extension.find("geo") != std::string::npos) {
    expectFileError([&] { openParticleFile(path); }, {"holds no points (an empty geometry)"});
    return;
  }
  auto source = openParticleFile(path);
  EXPECT_EQ(source->countHint(), 0u);
  ParticleChunk chunk;
  EXPECT_FALSE(source->read(chunk, 100));
}

INSTANTIATE_TEST_SUITE_P(Formats, WriterRoundTrip, ::testing::ValuesIn(kCases),
                         [](const auto& info) { return caseName(info.param); });

/// The scf1 container around geometries whose size is near a multiple of its 1 MiB chunks:
/// the first chunk, stored uncompressed to be patched, and the last, full or not.
TEST(BgeoScWriter, GeometriesAroundTheChunkSize) {
  TempDir dir("bgeo-sc-sizes");
  const ParticleChunk particles = randomParticles(87'500, false, 8);
  for (std::size_t count = 87'340; count <= 87'430; count += 3) {
    ParticleChunk prefix;
    prefix.positions.assign(particles.positions.begin(), particles.positions.begin() + std::ptrdiff_t(count));
    const fs::path path = dir / "p.bgeo.sc";
    writeFile(path, prefix, {}, 10'000);
    expectSameParticles(prefix, testing::readFile(path, 50'000), false);
  }
}

/// Binary .bgeo and .vtk bytes do not depend on how the particles were cut into chunks.
TEST(ParticleWriters, BytesIndependentOfChunking) {
  TempDir dir("writers-chunking");
  const ParticleChunk particles = randomParticles(20'000, true, 4);
  for (const char* extension : {".bgeo", ".bgeo.sc", ".geo", ".vtk"}) {
    writeFile(dir / (std::string("a") + extension), particles, WriteOptions{.velocity = true}, 20'000);
    writeFile(dir / (std::string("b") + extension), particles, WriteOptions{.velocity = true}, 999);
    EXPECT_EQ(testing::readBytes(dir / (std::string("a") + extension)),
              testing::readBytes(dir / (std::string("b") + extension)))
        << extension;
  }
}

TEST(ParticleWriters, VelocitiesOnlyWhenAsked) {
  TempDir dir("writers-novel");
  const ParticleChunk particles = randomParticles(1'000, true, 5);
  for (const WriterCase& c : kCases) {
    const fs::path path = dir / ("p" + c.extension);
    auto writer = createParticleWriter(path);  // the chunk carries velocities, the options say no
    writer->write(particles);
    writer->commit();
    auto source = openParticleFile(path);
    EXPECT_FALSE(source->hasVelocity()) << c.extension;
    EXPECT_TRUE(source->attributes().empty()) << c.extension;
    expectSameParticles(particles, testing::readAll(*source, 300), false);
  }
}

TEST(ParticleWriters, GzipHoudiniGeometryIsRefused) {
  TempDir dir("writers-gz");
  for (const char* name : {"p.bgeo.gz", "p.geo.gz"})
    expectFileError([&] { createParticleWriter(dir / name); }, {name, "gzip", ".bgeo.sc"});
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(ParticleWriters, WritableListNamesTheNewFormats) {
  TempDir dir("writers-list");
  try {
    createParticleWriter(dir / "p.xyz");
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& e) {
    const std::string message = e.what();
    for (const char* extension : {".bgeo", ".geo", ".bgeo.sc", ".prt", ".vtk"})
      EXPECT_NE(message.find(extension), std::string::npos) << message;
    EXPECT_EQ(message.find(".gz"), std::string::npos) << message;
  }
}

TEST(ParticleWriters, VtkHeaderIsTheLegacyLayout) {
  TempDir dir("writers-vtk");
  writeFile(dir / "p.vtk", randomParticles(12, true, 6), WriteOptions{.velocity = true});
  const std::string bytes = testing::readBytes(dir / "p.vtk");
  const std::string header =
      "# vtk DataFile Version 3.0\nflipscope particles\nBINARY\nDATASET POLYDATA\nPOINTS 000000000000012 float\n";
  const std::string pointData = "\nPOINT_DATA 12\nVECTORS velocity float\n";
  EXPECT_EQ(bytes.substr(0, header.size()), header);
  EXPECT_EQ(bytes.substr(header.size() + 12 * 12, pointData.size()), pointData);
  EXPECT_EQ(bytes.size(), header.size() + 12 * 12 + pointData.size() + 12 * 12 + 1);
  EXPECT_EQ(bytes.back(), '\n');
}

}  // namespace
}  // namespace flipscope
