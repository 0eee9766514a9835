// `flipscope synth` end to end: the files it writes read back as SynthFluid's particles, and
// bad arguments fail with exit code 2 and a message naming the problem.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "preprocess/particles/ParticleSource.h"
#include "preprocess/SynthFluid.h"
#include "TestSupport.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;

using testing::CommandRun;

CommandRun synth(const fs::path& dir, const std::string& arguments) {
  return testing::runFlipscope("synth " + arguments, dir);
}

class SynthCommand : public ::testing::Test {
 protected:
  testing::TempDir mTemp{"synth-command"};
  const fs::path& mDir = mTemp.path();
};

TEST_F(SynthCommand, PlySequenceReadsBackAsTheGeneratedParticles) {
  CommandRun run = synth(mDir, "-o f_####.ply --particles 5k --frames 2-3 --seed 9 --velocity");
  ASSERT_EQ(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("--cell-size"), std::string::npos) << run.output;
  for (int frame : {2, 3}) {
    SynthOptions options;
    options.particles = 5000;
    options.seed = 9;
    options.frame = frame;
    SynthFluid expected(options);
    auto file = openParticleFile(mDir / ("f_000" + std::to_string(frame) + ".ply"));
    ASSERT_TRUE(file->hasVelocity());
    ASSERT_EQ(file->countHint(), expected.count());
    ParticleChunk chunk;
    std::uint64_t index = 0;
    while (file->read(chunk, 777)) {
      for (std::size_t i = 0; i < chunk.size(); ++i, ++index) {
        glm::vec3 p, v;
        expected.particle(index, p, &v);
        ASSERT_EQ(chunk.positions[i], p) << "frame " << frame << " particle " << index;
        ASSERT_EQ(chunk.velocities[i], v) << "frame " << frame << " particle " << index;
      }
    }
    EXPECT_EQ(index, expected.count());
  }
}

TEST_F(SynthCommand, HoudiniPrtAndVtkReadBackAsTheGeneratedParticles) {
  SynthOptions options;
  options.particles = 5000;
  options.seed = 4;
  SynthFluid expected(options);
  for (const std::string extension : {".bgeo", ".bgeo.sc", ".geo", ".prt", ".vtk"}) {
    const std::string name = "f" + extension;
    CommandRun run = synth(mDir, "-o " + name + " --particles 5k --seed 4 --velocity");
    ASSERT_EQ(run.exitCode, 0) << name << ": " << run.output;
    auto file = openParticleFile(mDir / name);
    ASSERT_TRUE(file->hasVelocity()) << name;
    ASSERT_EQ(file->countHint(), expected.count()) << name;
    ParticleChunk chunk;
    std::uint64_t index = 0;
    while (file->read(chunk, 1234)) {
      for (std::size_t i = 0; i < chunk.size(); ++i, ++index) {
        glm::vec3 p, v;
        expected.particle(index, p, &v);
        ASSERT_EQ(chunk.positions[i], p) << name << " particle " << index;
        ASSERT_EQ(chunk.velocities[i], v) << name << " particle " << index;
      }
    }
    EXPECT_EQ(index, expected.count()) << name;
  }
}

TEST_F(SynthCommand, BgeoScConvertsToAStore) {
  CommandRun run = synth(mDir, "-o x.bgeo.sc --particles 20k --velocity");
  ASSERT_EQ(run.exitCode, 0) << run.output;
  CommandRun convert = testing::runFlipscope("convert x.bgeo.sc -o store", mDir);
  ASSERT_EQ(convert.exitCode, 0) << convert.output;
  SynthOptions options;
  options.particles = 20'000;
  const std::string particles = std::to_string(SynthFluid(options).count());
  EXPECT_NE(convert.output.find("frame 0: " + particles + " particles"), std::string::npos) << convert.output;
  EXPECT_NE(convert.output.find("attribute speed"), std::string::npos) << convert.output;  // from the velocities
  EXPECT_EQ(convert.output.find("warning"), std::string::npos) << convert.output;
  CommandRun info = testing::runFlipscope("info store", mDir);
  ASSERT_EQ(info.exitCode, 0) << info.output;
  EXPECT_NE(info.output.find(particles), std::string::npos) << info.output;
}

TEST_F(SynthCommand, BadArgumentsFailWithAMessage) {
  struct Case {
    std::string arguments, message;
  };
  for (const Case& c :
       {Case{"-o f.bin --particles 2G", "1k to 1G"}, Case{"-o f.bin --particles 999", "1k to 1G"},
        Case{"-o f.bin --particles 12x", "--particles: cannot read"},
        Case{"-o f.bin --particles 1k --frames 0-4", "frame pattern"}, Case{"-o f.vdb --particles 60M", "VDB"}}) {
    CommandRun run = synth(mDir, c.arguments);
    EXPECT_EQ(run.exitCode, 2) << c.arguments << ": " << run.output;
    EXPECT_NE(run.output.find(c.message), std::string::npos) << c.arguments << ": " << run.output;
  }
  EXPECT_FALSE(fs::exists(mDir / "f.bin"));
  EXPECT_FALSE(fs::exists(mDir / "f.vdb"));
}

}  // namespace
}  // namespace flipscope
