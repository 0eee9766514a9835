// The flipscope command end to end: synth -> convert -> info, exit codes and messages.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;

using flipscope::testing::CommandRun;
CommandRun run(const std::string& args) { return flipscope::testing::runFlipscope(args); }

class Cli : public ::testing::Test {
 protected:
  std::string path(const std::string& name) const { return (dir / name).string(); }
  flipscope::testing::TempDir temp{"cli"};
  const fs::path& dir = temp.path();
};

TEST_F(Cli, SynthConvertInfoRoundTrip) {
  CommandRun synth = run("synth -o " + path("fluid_####.ply") + " --particles 20k --frames 1-2 --velocity");
  ASSERT_EQ(synth.exitCode, 0) << synth.output;
  CommandRun convert = run("convert " + path("fluid_####.ply") + " -o " + path("store") + " --resolution 128 --brick-size 32");
  ASSERT_EQ(convert.exitCode, 0) << convert.output;
  EXPECT_NE(convert.output.find("frame 2"), std::string::npos) << convert.output;

  CommandRun info = run("info --json --verify " + path("store"));
  ASSERT_EQ(info.exitCode, 0) << info.output;
  auto j = nlohmann::json::parse(info.output);
  ASSERT_EQ(j["frames"].size(), 2u);
  for (const auto& f : j["frames"]) {
    EXPECT_GT(f["particles"].get<std::uint64_t>(), 18000u);
    EXPECT_GT(f["bricks"].get<std::uint32_t>(), 0u);
    EXPECT_GT(f["bits_per_particle"].get<double>(), 0.0);
  }
  EXPECT_EQ(j["attribute"], "speed");
  EXPECT_TRUE(j["verified"].get<bool>());

  // Appending a third frame keeps the store's domain.
  ASSERT_EQ(run("synth -o " + path("extra.ply") + " --particles 20k --frames 3 --velocity").exitCode, 0);
  CommandRun append = run("convert " + path("extra.ply") + " -o " + path("store"));
  EXPECT_EQ(append.exitCode, 0) << append.output;
}

TEST_F(Cli, DamagedStoreFailsVerifyNamingFileAndBrick) {
  ASSERT_EQ(run("synth -o " + path("f.bin") + " --particles 5k").exitCode, 0);
  ASSERT_EQ(run("convert " + path("f.bin") + " -o " + path("store") + " --resolution 64 --brick-size 32 -q").exitCode,
            0);
  const fs::path frame = dir / "store" / "frame_000000.fsf";
  ASSERT_TRUE(fs::exists(frame));
  {
    std::fstream f(frame, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(20);
    f.put('\x7f');
  }
  EXPECT_EQ(run("info " + path("store")).exitCode, 0);  // the index is intact
  CommandRun verify = run("info --verify " + path("store"));
  EXPECT_EQ(verify.exitCode, 1) << verify.output;
  EXPECT_NE(verify.output.find("frame_000000.fsf: brick 0"), std::string::npos) << verify.output;

  // A truncated frame file is refused by plain info, with exit code 3 (bad input).
  fs::resize_file(frame, fs::file_size(frame) - 5);
  CommandRun info = run("info " + path("store"));
  EXPECT_EQ(info.exitCode, 3) << info.output;
  EXPECT_NE(info.output.find("frame_000000.fsf"), std::string::npos) << info.output;
}

TEST_F(Cli, BadInputsGiveClearErrorsAndExitCodes) {
  std::ofstream(path("odd.bin"), std::ios::binary) << "12345678901234";  // 14 bytes: not a multiple of 12
  CommandRun odd = run("convert " + path("odd.bin") + " -o " + path("s1"));
  EXPECT_EQ(odd.exitCode, 3) << odd.output;
  EXPECT_NE(odd.output.find("odd.bin"), std::string::npos) << odd.output;
  EXPECT_FALSE(fs::exists(dir / "s1" / "frame_000000.fsf"));

  CommandRun missing = run("convert " + path("nothing.ply") + " -o " + path("s2"));
  EXPECT_NE(missing.exitCode, 0);
  EXPECT_NE(missing.output.find("nothing.ply"), std::string::npos) << missing.output;

  CommandRun badMem = run("convert " + path("odd.bin") + " -o " + path("s3") + " --mem lots");
  EXPECT_EQ(badMem.exitCode, 2) << badMem.output;
  EXPECT_NE(badMem.output.find("--mem"), std::string::npos) << badMem.output;

  CommandRun notStore = run("info " + path(""));
  EXPECT_EQ(notStore.exitCode, 3) << notStore.output;
  EXPECT_NE(notStore.output.find("store.fsh missing"), std::string::npos) << notStore.output;

  EXPECT_EQ(run("frobnicate").exitCode, 2);
}

TEST_F(Cli, OutOfCoreConvertMatchesInCore) {
  ASSERT_EQ(run("synth -o " + path("big.bin") + " --particles 600k").exitCode, 0);
  ASSERT_EQ(run("convert " + path("big.bin") + " -o " + path("a") + " --resolution 256 -q").exitCode, 0);
  CommandRun out = run("convert " + path("big.bin") + " -o " + path("b") + " --resolution 256 --mem 2M");
  ASSERT_EQ(out.exitCode, 0) << out.output;
  EXPECT_NE(out.output.find("out of core"), std::string::npos) << out.output;
  auto bytes = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  EXPECT_EQ(bytes(dir / "a" / "frame_000000.fsf"), bytes(dir / "b" / "frame_000000.fsf"));
}

}  // namespace
