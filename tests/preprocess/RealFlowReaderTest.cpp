// The RealFlow .bin reader (preprocess/particles/RealFlowParticles.cpp): the real sequence
// (frames 0 to 5, the count growing), every version's record layout through the test writer,
// the trailing section as different writers make it, recognition by content (never as raw
// floats, which share the ".bin" name), damage.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

#include "DamageTestSupport.h"
#include "ParticleTestSupport.h"
#include "RealFlowTestWriter.h"
#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleFormatRegistry.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;
using testing::expectFileError;
using testing::TempDir;

const fs::path kRealFlowFolder = fs::path(FLIPSCOPE_DATA_DIR) / "formats" / "realflow-bin";

struct Columns {
  ParticleChunk particles;
  std::vector<std::vector<float>> attributes;
};

Columns readColumns(ParticleSource& source, std::size_t chunkSize) {
  Columns all;
  ParticleChunk chunk;
  while (source.read(chunk, chunkSize)) {
    all.particles.positions.insert(all.particles.positions.end(), chunk.positions.begin(), chunk.positions.end());
    all.particles.velocities.insert(all.particles.velocities.end(), chunk.velocities.begin(), chunk.velocities.end());
    all.attributes.resize(chunk.attributes.size());
    for (std::size_t i = 0; i < chunk.attributes.size(); ++i)
      all.attributes[i].insert(all.attributes[i].end(), chunk.attributes[i].values.begin(),
                               chunk.attributes[i].values.end());
  }
  return all;
}

std::size_t attributeIndex(const ParticleSource& source, const std::string& name) {
  const auto attributes = source.attributes();
  for (std::size_t i = 0; i < attributes.size(); ++i)
    if (attributes[i].name == name) return i;
  ADD_FAILURE() << "no attribute " << name;
  return 0;
}

TEST(RealFlowReader, RealSequence) {
  ASSERT_TRUE(fs::is_directory(kRealFlowFolder)) << kRealFlowFolder;
  int files = 0;
  for (const auto& entry : fs::directory_iterator(kRealFlowFolder)) {
    SCOPED_TRACE(entry.path().filename().string());
    const std::string bytes = testing::readBytes(entry.path());
    std::int32_t declared;
    std::memcpy(&declared, bytes.data() + 276, 4);
    ReadOptions options;
    options.allAttributes = true;
    auto source = openParticleFile(entry.path(), options);
    EXPECT_EQ(source->format(), "RealFlow particle .bin version 11 (fluid 'Circle01')");
    EXPECT_EQ(source->countHint(), std::uint64_t(declared));
    EXPECT_TRUE(source->hasVelocity());
    EXPECT_EQ(source->attributes().size(), 15u);
    EXPECT_EQ(readColumns(*source, 50).particles.size(), std::size_t(declared));
    ++files;
  }
  EXPECT_GE(files, 2);
  // Frame 0 is empty (the emitter starts), frame 1 holds 62 particles, frame 5 155.
  EXPECT_EQ(testing::readFile(kRealFlowFolder / "Circle01_00000.bin").size(), 0u);
  ReadOptions options;
  options.allAttributes = true;
  auto source = openParticleFile(kRealFlowFolder / "Circle01_00001.bin", options);
  const Columns one = readColumns(*source, 10);
  ASSERT_EQ(one.particles.size(), 62u);
  EXPECT_EQ(one.particles.positions[0], glm::vec3(-0.0296834391f, 0.966666639f, 0.385534704f));
  EXPECT_EQ(one.particles.velocities[0], glm::vec3(0.0442675054f, -1.f, -0.582063496f));
  EXPECT_EQ(one.attributes[attributeIndex(*source, "normal")][2], 0.604107857f);
  EXPECT_EQ(one.attributes[attributeIndex(*source, "neighbors")][0], 8.f);
  EXPECT_EQ(one.attributes[attributeIndex(*source, "density")][0], 627.090088f);
  EXPECT_EQ(one.attributes[attributeIndex(*source, "temperature")][61], 300.f);
  EXPECT_EQ(one.attributes[attributeIndex(*source, "id")][0], 62.f);
  EXPECT_EQ(one.attributes[attributeIndex(*source, "id")][61], 1.f);
  if (fs::exists(kRealFlowFolder / "Circle01_00005.bin")) {
    auto five = openParticleFile(kRealFlowFolder / "Circle01_00005.bin", options);
    const Columns all = readColumns(*five, 1000);
    ASSERT_EQ(all.particles.size(), 155u);
    EXPECT_EQ(all.particles.positions[154], glm::vec3(-5.53168757e-05f, 0.83448267f, -2.78298066e-05f));
    EXPECT_EQ(all.attributes[attributeIndex(*five, "pressure")][154], 3239.89282f);
  }
}

TEST(RealFlowReader, NeverReadAsRawFloats) {
  TempDir dir("realflow-raw");
  // Every real frame, and a frame whose size is a multiple of 12 (which the raw reader would
  // accept): recognised by the magic number, whatever the name.
  for (const auto& entry : fs::directory_iterator(kRealFlowFolder)) {
    const RecognisedInput input = recogniseInput(InputFile(entry.path()));
    EXPECT_EQ(input.format->name, "realflow-bin") << entry.path();
  }
  std::size_t count = 0;
  while (testing::makeRealFlowBin(11, count).size() % 12 != 0) ++count;
  ASSERT_GT(count, 0u);
  for (const char* name : {"Fluid_00001.bin", "fluid.raw", "fluid"}) {
    testing::writeBytes(dir / name, testing::makeRealFlowBin(11, count));
    auto source = openParticleFile(dir / name);
    EXPECT_EQ(source->format().rfind("RealFlow particle .bin version 11", 0), 0u) << name << ": " << source->format();
    EXPECT_EQ(testing::readAll(*source, 7).size(), count) << name;
  }
  // Raw floats named .bin stay raw floats.
  testing::writeBytes(dir / "raw.bin", std::string(24, '\0'));
  auto raw = openParticleFile(dir / "raw.bin");
  EXPECT_EQ(raw->format(), "raw little-endian float32 xyz");
  EXPECT_EQ(testing::readAll(*raw, 7).size(), 2u);
}

TEST(RealFlowReader, EveryVersionsLayout) {
  TempDir dir("realflow-versions");
  for (int version : {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}) {
    SCOPED_TRACE("version " + std::to_string(version));
    const std::size_t count = 1234;
    testing::writeBytes(dir / "v.bin", testing::makeRealFlowBin(version, count));
    ReadOptions options;
    options.allAttributes = true;
    auto source = openParticleFile(dir / "v.bin", options);
    const std::size_t expectedAttributes = 10 + (version >= 9) + (version >= 3) + (version >= 4) + 2 * (version >= 5);
    ASSERT_EQ(source->attributes().size(), expectedAttributes);
    EXPECT_EQ(source->attributes().back().type, version >= 12 ? ValueType::Int64 : ValueType::Int32);
    const Columns all = readColumns(*source, 100);
    ASSERT_EQ(all.particles.size(), count);
    for (std::size_t p = 0; p < count; p += 97) {
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(all.particles.positions[p][c], testing::realFlowValue(p, 0, c));
        EXPECT_EQ(all.particles.velocities[p][c], testing::realFlowValue(p, 1, c));
        EXPECT_EQ(all.attributes[attributeIndex(*source, "force")][3 * p + c], testing::realFlowValue(p, 2, c));
        if (version >= 3) {
          EXPECT_EQ(all.attributes[attributeIndex(*source, "normal")][3 * p + c], testing::realFlowValue(p, 4, c));
        }
        if (version >= 5) {
          EXPECT_EQ(all.attributes[attributeIndex(*source, "texture")][3 * p + c], testing::realFlowValue(p, 6, c));
        }
      }
      if (version >= 4) {
        EXPECT_EQ(all.attributes[attributeIndex(*source, "neighbors")][p], float(p % 30));
      }
      if (version >= 5) {
        EXPECT_EQ(all.attributes[attributeIndex(*source, "info")][p], float(p % 3));
      }
      EXPECT_EQ(all.attributes[attributeIndex(*source, "age")][p], testing::realFlowValue(p, 7, 0));
      EXPECT_EQ(all.attributes[attributeIndex(*source, "temperature")][p], testing::realFlowValue(p, 13, 0));
      EXPECT_EQ(all.attributes[attributeIndex(*source, "id")][p], float(version >= 12 ? p * 1000 + 1 : p + 1));
    }
  }
}

TEST(RealFlowReader, TrailingSectionsOfDifferentWriters) {
  TempDir dir("realflow-tail");
  auto read = [&](int version, const std::string& tail) {
    testing::writeBytes(dir / "t.bin", testing::makeRealFlowBin(version, 5, tail));
    return testing::readFile(dir / "t.bin").size();
  };
  EXPECT_EQ(read(9, testing::kRealFlowTail5), 5u);   // Krakatoa
  EXPECT_EQ(read(11, testing::kRealFlowTail6), 5u);  // 6 bytes
  EXPECT_EQ(read(11, testing::kRealFlowTail10), 5u);
  EXPECT_EQ(read(8, ""), 5u);  // older versions: no trailing section
  expectFileError([&] { read(11, testing::kRealFlowTail5); }, {"t.bin", "RF5 internal data flag"});
  expectFileError([&] { read(9, ""); }, {"t.bin", "additional data count"});
  expectFileError([&] { read(11, testing::kRealFlowTail6 + "x"); }, {"t.bin", "1 bytes of trailing garbage"});
  expectFileError([&] { read(11, std::string("\0\0\0\0\2\0", 6)); }, {"t.bin", "RF4 internal data flag", "is 2"});
  expectFileError([&] { read(11, std::string("\xff\xff\xff\xff\0\0", 6)); }, {"t.bin", "negative count -1"});
  testing::writeBytes(dir / "v13.bin", testing::makeRealFlowBin(13, 1));
  expectFileError([&] { testing::readFile(dir / "v13.bin"); }, {"v13.bin", "version 13", "1 to 12"});
}

TEST(RealFlowReader, TruncatedAtEveryLengthIsRefused) {
  // From 1 byte on: an empty file named .bin is an empty raw float file (no magic to tell).
  testing::expectEveryTruncationRefused("Circle01_00000.bin",
                                        testing::readBytes(kRealFlowFolder / "Circle01_00000.bin"), 1);
  testing::expectEveryTruncationRefused("Circle01_00001.bin",
                                        testing::readBytes(kRealFlowFolder / "Circle01_00001.bin"), 1);
  testing::expectEveryTruncationRefused("v12.bin", testing::makeRealFlowBin(12, 3), 1);
}

TEST(RealFlowReader, SingleByteCorruptionsAreReadOrRefused) {
  EXPECT_GT(testing::expectCorruptionsHandled("Circle01_00000.bin",
                                              testing::readBytes(kRealFlowFolder / "Circle01_00000.bin")),
            0u);
  EXPECT_GT(testing::expectCorruptionsHandled("v11.bin", testing::makeRealFlowBin(11, 2)), 0u);
}

}  // namespace
}  // namespace flipscope
