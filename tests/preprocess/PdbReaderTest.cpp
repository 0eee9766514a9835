// The Maya .pdb reader (preprocess/particles/PdbParticles.cpp): the real file (partio's test
// data, the 32-bit layout), both pointer widths and every channel type through the test
// writer, recognition by content, clear refusals, damage.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

#include "DamageTestSupport.h"
#include "ParticleTestSupport.h"
#include "PdbTestWriter.h"
#include "preprocess/particles/ParticleFormatRegistry.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;
using testing::expectFileError;
using testing::makePdb;
using testing::PdbChannelSpec;
using testing::pdbValue;

const fs::path kFile = fs::path(FLIPSCOPE_DATA_DIR) / "formats" / "maya-pdb" / "test.pdb";

std::unique_ptr<ParticleSource> openBytes(const std::string& name, const std::string& bytes, ReadOptions options = {}) {
  return openParticleBytes(name, std::as_bytes(std::span(bytes.data(), bytes.size())), options);
}

/// Every particle of `source`, `chunkSize` at a time, attributes appended column by column.
ParticleChunk readAll(ParticleSource& source, std::size_t chunkSize) {
  ParticleChunk all, chunk;
  while (source.read(chunk, chunkSize)) {
    all.positions.insert(all.positions.end(), chunk.positions.begin(), chunk.positions.end());
    all.velocities.insert(all.velocities.end(), chunk.velocities.begin(), chunk.velocities.end());
    all.attributes.resize(chunk.attributes.size());
    for (std::size_t i = 0; i < chunk.attributes.size(); ++i) {
      all.attributes[i].name = chunk.attributes[i].name;
      all.attributes[i].arity = chunk.attributes[i].arity;
      all.attributes[i].values.insert(all.attributes[i].values.end(), chunk.attributes[i].values.begin(),
                                      chunk.attributes[i].values.end());
    }
  }
  return all;
}

TEST(PdbReader, RealFileOfPartiosTestData) {
  ASSERT_TRUE(fs::exists(kFile)) << kFile;
  ReadOptions options;
  options.allAttributes = true;
  auto source = openParticleFile(kFile, options);
  EXPECT_EQ(source->format(), "Maya particle disk cache (.pdb) version 1, 32-bit layout");
  EXPECT_EQ(source->countHint(), 13u);
  EXPECT_EQ(source->upAxis(), UpAxis::Y);
  EXPECT_TRUE(source->hasVelocity());
  const std::vector<AttributeDesc> expected = {
      {"v", ValueType::Float32, 3},      {"accel", ValueType::Float32, 3},   {"life", ValueType::Float32, 2},
      {"pstate", ValueType::Int32, 1},   {"id", ValueType::Int32, 1},        {"parent", ValueType::Int32, 1},
      {"rotaxis", ValueType::Float32, 3}, {"rotangle", ValueType::Float32, 1}, {"radiusPP", ValueType::Float32, 1}};
  EXPECT_EQ(source->attributes(), expected);
  const ParticleChunk all = readAll(*source, 5);
  ASSERT_EQ(all.size(), 13u);
  // Values decoded independently (Python's struct) from the file's bytes.
  EXPECT_EQ(all.positions.front(), glm::vec3(0.27929607f, 8.92928123f, -1.69961917f));
  EXPECT_EQ(all.positions.back(), glm::vec3(0.8194049f, 0.510001302f, 0.074126929f));
  EXPECT_EQ(all.velocities.front(), glm::vec3(0.0741006285f, 0.662005186f, -0.255374879f));
  EXPECT_EQ(all.velocities.back(), glm::vec3(-0.398547649f, 0.869883657f, 0.219427109f));
  const std::vector<float>& ids = all.attributes[4].values;
  for (std::size_t p = 0; p < ids.size(); ++p) EXPECT_EQ(ids[p], float(p + 1));
  EXPECT_EQ(all.attributes[8].values.front(), 2.0f);
  EXPECT_EQ(all.attributes[8].values.back(), 1.0f);
}

TEST(PdbReader, BothPointerWidthsAndEveryChannelType) {
  const std::vector<PdbChannelSpec> channels = {{"id", 3, 1},       {"position", 1, 3}, {"v", 1, 3},
                                                {"velocity", 1, 3}, {"life", 2, 2},     {"flags", 4, 2},
                                                {"owner", 5, 1},    {"radiusPP", 2, 1}};
  const std::size_t count = 1001;  // no chunk size below divides it
  for (bool pointers64 : {false, true}) {
    SCOPED_TRACE(pointers64 ? "64-bit" : "32-bit");
    const std::string bytes = makePdb(channels, count, pointers64);
    ReadOptions options;
    options.allAttributes = true;
    auto source = openBytes("cache.pdb", bytes, options);
    EXPECT_NE(source->format().find(pointers64 ? "64-bit layout" : "32-bit layout"), std::string::npos)
        << source->format();
    // The positions are not an attribute; a pointer channel is not one either.
    const std::vector<AttributeDesc> expected = {{"id", ValueType::Int32, 1},        {"v", ValueType::Float32, 3},
                                                 {"velocity", ValueType::Float32, 3}, {"life", ValueType::Float32, 2},
                                                 {"flags", ValueType::Int8, 2},      {"radiusPP", ValueType::Float32, 1}};
    EXPECT_EQ(source->attributes(), expected);
    for (std::size_t chunkSize : {std::size_t(7), std::size_t(1) << 20}) {
      source->rewind();
      const ParticleChunk all = readAll(*source, chunkSize);
      ASSERT_EQ(all.size(), count);
      ASSERT_EQ(all.velocities.size(), count) << "'velocity' is preferred to 'v'";
      for (std::size_t p = 0; p < count; ++p) {
        for (int c = 0; c < 3; ++c) {
          ASSERT_EQ(all.positions[p][c], float(pdbValue(p, 1, c))) << "particle " << p;
          ASSERT_EQ(all.velocities[p][c], float(pdbValue(p, 3, c))) << "particle " << p;
        }
        ASSERT_EQ(all.attributes[0].values[p], float(std::int32_t(pdbValue(p, 0, 0) * 2)));
        for (int c = 0; c < 2; ++c) {
          ASSERT_EQ(all.attributes[3].values[2 * p + std::size_t(c)], float(pdbValue(p, 4, c)));
          ASSERT_EQ(all.attributes[4].values[2 * p + std::size_t(c)], float(int(pdbValue(p, 5, c)) % 100));
        }
        ASSERT_EQ(all.attributes[5].values[p], float(pdbValue(p, 7, 0)));
      }
    }
  }
}

TEST(PdbReader, RecognisedByContentWhateverItsName) {
  const std::string bytes = makePdb({{"position", 1, 3}}, 4);
  EXPECT_EQ(openBytes("frame.0001", bytes)->format(), "Maya particle disk cache (.pdb) version 1, 32-bit layout");
  EXPECT_EQ(openBytes("particles.bin", bytes)->countHint(), 4u) << "not read as raw floats";
}

TEST(PdbReader, RefusalsSayWhatIsWrong) {
  const std::string good = makePdb({{"position", 1, 3}, {"v", 1, 3}}, 5);
  expectFileError([&] { openBytes("a.pdb", makePdb({{"p", 1, 3}, {"life", 2, 1}}, 5)); },
                  {"a.pdb", "no vector channel 'position' (channels: p (vector), life (real))"});
  std::string bigEndian = good;
  std::swap(bigEndian[0], bigEndian[3]);
  std::swap(bigEndian[1], bigEndian[2]);
  expectFileError([&] { openBytes("b.pdb", bigEndian); }, {"b.pdb", "big-endian"});
  std::string magic = good;
  magic[0] = 'x';
  expectFileError([&] { openBytes("c.pdb", magic); }, {"c.pdb", "bad magic: not a Maya .pdb (expected 670)"});
  expectFileError([&] { openBytes("d.pdb", good + "tail"); },
                  {"d.pdb", "damaged, in either pointer width", "4 bytes follow the last channel"});
  std::string badType = good;
  badType[60 + 6 + 4] = 9;  // the first channel's type (32-bit layout)
  expectFileError([&] { openBytes("e.pdb", badType); }, {"e.pdb", "channel 0 ('position', type 9)", "not a channel type"});
  // A particle count of 0 leaves any size of values room in the file: the size is bounded still.
  std::string huge = makePdb({{"position", 1, 3}, {"flags", 4, 1}}, 0);
  const std::uint32_t bytes = 0xffffffffu;
  std::memcpy(huge.data() + huge.size() - 20 + 4, &bytes, 4);  // the last data header's bytes a particle
  expectFileError(
      [&] { openBytes("f.pdb", huge); },
      {"f.pdb", "channel 1 ('flags', char)", "4294967295 bytes a particle do not fit its type (at most 1 MiB)"});
}

TEST(PdbReader, TruncatedAtEveryLengthIsRefused) {
  testing::expectEveryTruncationRefused("real.pdb", testing::readBytes(kFile));
  testing::expectEveryTruncationRefused("64.pdb", makePdb({{"position", 1, 3}, {"life", 2, 1}, {"id", 3, 1}}, 3, true));
}

TEST(PdbReader, SingleByteCorruptionsAreReadOrRefused) {
  EXPECT_GT(testing::expectCorruptionsHandled("real.pdb", testing::readBytes(kFile)), 0u);
  EXPECT_GT(testing::expectCorruptionsHandled("64.pdb", makePdb({{"position", 1, 3}, {"flags", 4, 1}}, 3, true)), 0u);
}

}  // namespace
}  // namespace flipscope
