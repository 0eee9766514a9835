// Round trips: random particles through every writer, then back through the readers.
#include <gtest/gtest.h>

#include <cstring>

#include "ParticleTestSupport.h"

namespace flipscope {
namespace {

using testing::randomParticles;
using testing::readFile;
using testing::sameBits;
using testing::TempDir;
using testing::writeFile;

void expectIdentical(const ParticleChunk& expected, const ParticleChunk& actual) {
  ASSERT_EQ(actual.size(), expected.size());
  ASSERT_EQ(actual.velocities.size(), expected.velocities.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    ASSERT_TRUE(sameBits(actual.positions[i], expected.positions[i])) << "particle " << i;
    if (!expected.velocities.empty()) {
      ASSERT_TRUE(sameBits(actual.velocities[i], expected.velocities[i])) << i;
    }
  }
}

struct PlyCase {
  PlyEncoding encoding;
  bool velocity;
};

class PlyRoundTrip : public ::testing::TestWithParam<PlyCase> {};

TEST_P(PlyRoundTrip, ReadsBackTheSameBits) {
  TempDir dir("ply-roundtrip");
  auto [encoding, velocity] = GetParam();
  auto particles = randomParticles(2017, velocity, 11 + int(encoding) * 2 + velocity);
  WriteOptions options;
  options.velocity = velocity;
  options.plyEncoding = encoding;
  writeFile(dir / "p.ply", particles, options);
  auto source = openParticleFile(dir / "p.ply");
  EXPECT_EQ(source->hasVelocity(), velocity);
  EXPECT_EQ(source->countHint(), particles.size());
  expectIdentical(particles, testing::readAll(*source, 1000));
}

INSTANTIATE_TEST_SUITE_P(Encodings, PlyRoundTrip,
                         ::testing::Values(PlyCase{PlyEncoding::Ascii, false}, PlyCase{PlyEncoding::Ascii, true},
                                           PlyCase{PlyEncoding::BinaryLittleEndian, false},
                                           PlyCase{PlyEncoding::BinaryLittleEndian, true},
                                           PlyCase{PlyEncoding::BinaryBigEndian, false},
                                           PlyCase{PlyEncoding::BinaryBigEndian, true}));

TEST(PlyWriter, VelocityIgnoredWhenNotAsked) {
  TempDir dir("ply-novel");
  auto particles = randomParticles(100, true, 5);
  writeFile(dir / "p.ply", particles, WriteOptions{});
  auto source = openParticleFile(dir / "p.ply");
  EXPECT_FALSE(source->hasVelocity());
  auto read = testing::readAll(*source, 64);
  particles.velocities.clear();
  expectIdentical(particles, read);
}

TEST(PlyWriter, EmptyFileReadsAsNoParticles) {
  TempDir dir("ply-empty");
  for (auto encoding : {PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian, PlyEncoding::BinaryBigEndian}) {
    WriteOptions options;
    options.plyEncoding = encoding;
    writeFile(dir / "e.ply", ParticleChunk{}, options);
    EXPECT_EQ(readFile(dir / "e.ply").size(), 0u);
  }
}

TEST(RawWriter, ReadsBackTheSameBitsWithoutVelocity) {
  TempDir dir("raw-roundtrip");
  auto particles = randomParticles(1234, true, 7);
  WriteOptions options;
  options.velocity = true;  // raw stores positions only
  writeFile(dir / "p.bin", particles, options);
  EXPECT_EQ(std::filesystem::file_size(dir / "p.bin"), 1234u * 12u);
  auto source = openParticleFile(dir / "p.bin");
  EXPECT_FALSE(source->hasVelocity());
  particles.velocities.clear();
  expectIdentical(particles, testing::readAll(*source, 100));
}

TEST(ParticleWriter, NothingLeftBehindWithoutCommit) {
  TempDir dir("writer-abort");
  for (const char* name : {"a.bin", "a.ply", "a.vdb"}) {
    auto writer = createParticleWriter(dir / name);
    writer->write(randomParticles(10, false, 1));
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(ParticleWriter, UnknownExtensionAndUnwritablePath) {
  TempDir dir("writer-errors");
  testing::expectFileError([&] { createParticleWriter(dir / "a.xyz"); }, {"a.xyz", "cannot write this particle format", ".vdb", ".ply"});
  testing::expectFileError([&] { createParticleWriter(dir / "missing" / "a.ply"); }, {"missing"});
}

/// Each read particle matched to the nearest written one (VDB reorders particles by leaf).
void expectSameParticleSet(const ParticleChunk& expected, const ParticleChunk& actual, float tolerance) {
  ASSERT_EQ(actual.size(), expected.size());
  std::vector<bool> used(expected.size(), false);
  for (std::size_t i = 0; i < actual.size(); ++i) {
    std::size_t best = 0;
    float bestDistance = INFINITY;
    for (std::size_t j = 0; j < expected.size(); ++j) {
      glm::vec3 d = actual.positions[i] - expected.positions[j];
      float distance = std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
      if (distance < bestDistance) bestDistance = distance, best = j;
    }
    ASSERT_LE(bestDistance, tolerance) << "particle " << i;
    ASSERT_FALSE(used[best]) << "particle " << best << " read twice";
    used[best] = true;
    if (!expected.velocities.empty()) {
      ASSERT_TRUE(sameBits(actual.velocities[i], expected.velocities[best])) << i;
    }
  }
}

class VdbRoundTrip : public ::testing::TestWithParam<bool> {};

TEST_P(VdbRoundTrip, ReadsBackTheSameParticles) {
  TempDir dir("vdb-roundtrip");
  bool velocity = GetParam();
  auto particles = randomParticles(1500, velocity, 21 + velocity);
  for (float voxelSize : {0.f, 0.7f}) {
    WriteOptions options;
    options.velocity = velocity;
    options.vdbVoxelSize = voxelSize;
    writeFile(dir / "p.vdb", particles, options);
    auto source = openParticleFile(dir / "p.vdb");
    EXPECT_EQ(source->hasVelocity(), velocity);
    EXPECT_EQ(source->countHint(), particles.size());
    expectSameParticleSet(particles, testing::readAll(*source, 100), 1e-4f);
    ReadOptions byName;
    byName.grids = {"particles"};
    byName.velocity = false;
    auto named = openParticleFile(dir / "p.vdb", byName);
    EXPECT_FALSE(named->hasVelocity());
    EXPECT_EQ(testing::readAll(*named, 1000).size(), particles.size());
  }
}

INSTANTIATE_TEST_SUITE_P(Velocity, VdbRoundTrip, ::testing::Bool());

TEST(VdbWriter, EmptyFileReadsAsNoParticles) {
  TempDir dir("vdb-empty");
  writeFile(dir / "e.vdb", ParticleChunk{}, WriteOptions{});
  auto source = openParticleFile(dir / "e.vdb");
  EXPECT_EQ(source->countHint(), 0u);
  EXPECT_EQ(testing::readAll(*source, 10).size(), 0u);
}

TEST(VdbWriter, RejectsNonFinitePositions) {
  TempDir dir("vdb-nan");
  auto particles = randomParticles(10, false, 3);
  particles.positions[4].y = NAN;
  auto writer = createParticleWriter(dir / "n.vdb");
  try {
    writer->write(particles);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("particle 4"), std::string::npos) << e.what();
  }
}

TEST(VdbWriter, APositionBeyondTheGridsReachIsAnErrorNamingTheFile) {
  // The writer is a module (preprocess/vdbwriter/): its refusal comes back as the file's error,
  // and nothing is left behind.
  TempDir dir("vdb-far");
  auto particles = randomParticles(10, true, 4);
  particles.positions[6] = {1e30f, 0.0f, 0.0f};
  WriteOptions options;
  options.vdbVoxelSize = 1.0f;
  try {
    writeFile(dir / "far.vdb", particles, options);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("far.vdb"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("too far from the origin for voxel size 1"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

}  // namespace
}  // namespace flipscope
