// The farm end to end, as a user runs it: `farm convert` of an 8-frame synth sequence equals a
// serial convert, `farm render` equals a local render, a corrupted input frame is named in the
// summary and `--resume` completes the store once it is fixed. Run against whatever scheduler
// the environment provides: the real one-node Slurm of tests/farm/run-slurm.sh
// (FarmSlurmTest.cpp), or stand-in sbatch/squeue that run each job at once (FarmCommandTest.cpp).
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "StoreComparison.h"
#include "TestSupport.h"

namespace flipscope::testing {

class FarmScenario {
 public:
  explicit FarmScenario(const std::string& tag) : mTemp(tag) {
    std::filesystem::create_directories(mTemp / "in");
    const CommandRun synth = runFlipscope("synth -o " + path("in/in_####.bin") + " --particles 20k --frames 1-8");
    EXPECT_EQ(synth.exitCode, 0) << synth.output;
    const CommandRun serial = runFlipscope("convert " + path("in/in_####.bin") + " -o " + path("serial") + " -q");
    EXPECT_EQ(serial.exitCode, 0) << serial.output;
  }
  std::string path(const std::string& name) const { return (mTemp.path() / name).string(); }

  static std::string readText(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }

  void convertEqualsSerial() {
    const CommandRun farm =
        runFlipscope("farm convert " + path("in/in_####.bin") + " -o " + path("farm") + " --chunk 2 --wait");
    ASSERT_EQ(farm.exitCode, 0) << farm.output;
    EXPECT_NE(farm.output.find("8 of 8 frames done, complete"), std::string::npos) << farm.output;
    expectSameFrames(path("serial"), path("farm"));
    const CommandRun verify = runFlipscope("info --verify " + path("farm"));
    EXPECT_EQ(verify.exitCode, 0) << verify.output;
  }

  /// After convertEqualsSerial().
  void renderEqualsLocal() {
    const std::string options = " --size 64x36 --device cpu";
    const CommandRun local =
        runFlipscope("render " + path("farm") + " --frames 1-8 -o " + path("local_####.png") + options + " -q");
    ASSERT_EQ(local.exitCode, 0) << local.output;
    const CommandRun farm = runFlipscope("farm render " + path("farm") + " --frames 1-8 -o " + path("farm_####.png") +
                                         " --chunk 3" + options + " --wait");
    ASSERT_EQ(farm.exitCode, 0) << farm.output;
    for (int f = 1; f <= 8; ++f) {
      const std::string name = "_000" + std::to_string(f) + ".png";
      const std::string a = readText(path("local" + name)), b = readText(path("farm" + name));
      EXPECT_FALSE(a.empty()) << name;
      EXPECT_TRUE(a == b) << "frame " << f << ": the farm's image differs from the local render";
    }
  }

  void aFailedFrameIsNamedAndResumeCompletes() {
    // Frame 5 damaged: 7 bytes are no float32 xyz triple.
    const std::filesystem::path frame5 = path("in/in_0005.bin");
    const std::string good = readText(frame5);
    std::ofstream(frame5, std::ios::binary | std::ios::trunc) << "7 bytes";
    const CommandRun farm =
        runFlipscope("farm convert " + path("in/in_####.bin") + " -o " + path("resumed") + " --chunk 3 --wait");
    EXPECT_EQ(farm.exitCode, 1) << farm.output;
    const std::string summary = readText(path("resumed/farm/convert/summary.txt"));
    EXPECT_NE(summary.find("7 of 8 frames done, 1 missing or failed"), std::string::npos) << summary;
    EXPECT_NE(summary.find("frame 5: flipscope: error: " + frame5.string()), std::string::npos) << summary;
    // Fixed, then resumed: only frame 5 is submitted, and the store is complete.
    std::ofstream(frame5, std::ios::binary | std::ios::trunc) << good;
    const CommandRun resume = runFlipscope("farm convert --resume -o " + path("resumed") + " --wait");
    EXPECT_EQ(resume.exitCode, 0) << resume.output;
    EXPECT_NE(resume.output.find("farm convert: 1 frames"), std::string::npos) << resume.output;
    EXPECT_NE(resume.output.find("8 of 8 frames done, complete"), std::string::npos) << resume.output;
    const CommandRun verify = runFlipscope("info --verify " + path("resumed"));
    EXPECT_EQ(verify.exitCode, 0) << verify.output;
  }

 private:
  TempDir mTemp;
};

}  // namespace flipscope::testing
