// The flipscope command end to end: synth -> convert -> info, exit codes and messages.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <array>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;

using flipscope::testing::CommandRun;
using flipscope::testing::runFlipscope;

/// A frame file's bytes but for the store id (random per store) and the index checksum over it:
/// the footer's bytes 40 to 24 and 16 to 8 from the end of the file, zeroed. `id`: what was there.
std::string frameBytesWithoutStoreId(const fs::path& frameFile, std::string* id = nullptr) {
  std::ifstream in(frameFile, std::ios::binary);
  std::string bytes(std::istreambuf_iterator<char>(in), {});
  if (bytes.size() < 40) return bytes;
  if (id) *id = bytes.substr(bytes.size() - 40, 16);
  bytes.replace(bytes.size() - 40, 16, 16, '\0');
  bytes.replace(bytes.size() - 16, 8, 8, '\0');
  return bytes;
}

class Cli : public ::testing::Test {
 protected:
  std::string path(const std::string& name) const { return (dir / name).string(); }
  flipscope::testing::TempDir temp{"cli"};
  const fs::path& dir = temp.path();
};

TEST_F(Cli, SynthConvertInfoRoundTrip) {
  CommandRun synth = runFlipscope("synth -o " + path("fluid_####.ply") + " --particles 20k --frames 1-2 --velocity");
  ASSERT_EQ(synth.exitCode, 0) << synth.output;
  CommandRun convert =
      runFlipscope("convert " + path("fluid_####.ply") + " -o " + path("store") + " --resolution 128 --brick-size 32");
  ASSERT_EQ(convert.exitCode, 0) << convert.output;
  EXPECT_NE(convert.output.find("frame 2"), std::string::npos) << convert.output;

  CommandRun info = runFlipscope("info --json --verify " + path("store"));
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
  ASSERT_EQ(runFlipscope("synth -o " + path("extra.ply") + " --particles 20k --frames 3 --velocity").exitCode, 0);
  CommandRun append = runFlipscope("convert " + path("extra.ply") + " -o " + path("store"));
  EXPECT_EQ(append.exitCode, 0) << append.output;
  CommandRun after = runFlipscope("info --json " + path("store"));
  ASSERT_EQ(after.exitCode, 0) << after.output;
  const auto k = nlohmann::json::parse(after.output);
  EXPECT_EQ(k["frames"].size(), 3u);
  for (const char* key : {"cell_size", "origin", "brick_grid", "store_id", "brick_size"})
    EXPECT_EQ(k[key], j[key]) << key;
}

TEST_F(Cli, DefaultConvertOfMantaflowMakesOneCellPerParticleSpacingAndInfoShowsIt) {
  const fs::path vdb = flipscope::testing::mantaflowFile("data", "fluid_data_0030.vdb");
  ASSERT_TRUE(fs::exists(vdb)) << vdb;
  CommandRun convert = runFlipscope("convert '" + vdb.string() + "' -o " + path("store"));
  ASSERT_EQ(convert.exitCode, 0) << convert.output;
  EXPECT_NE(convert.output.find("(one cell per particle spacing)"), std::string::npos) << convert.output;
  EXPECT_NE(convert.output.find("(1.00 cells), from frame 0: OpenVDB grid 'particles'"), std::string::npos)
      << convert.output;
  EXPECT_EQ(convert.output.find("warning"), std::string::npos) << convert.output;

  CommandRun info = runFlipscope("info --json " + path("store"));
  ASSERT_EQ(info.exitCode, 0) << info.output;
  auto j = nlohmann::json::parse(info.output);
  ASSERT_TRUE(j["particle_spacing"].is_number()) << info.output;
  const double spacing = j["particle_spacing"].get<double>();
  EXPECT_GT(spacing, 0.03);
  EXPECT_LT(spacing, 0.05);
  EXPECT_EQ(spacing, j["cell_size"].get<double>());
  EXPECT_DOUBLE_EQ(j["particle_spacing_cells"].get<double>(), 1.0);
  EXPECT_EQ(j["version"].get<std::uint32_t>(), 7u);
  EXPECT_EQ(j["particle_kinds"], false) << "a FLIP file alone";

  CommandRun text = runFlipscope("info " + path("store"));
  ASSERT_EQ(text.exitCode, 0) << text.output;
  EXPECT_NE(text.output.find("particle spacing"), std::string::npos) << text.output;
  EXPECT_NE(text.output.find("= 1.00 cells of"), std::string::npos) << text.output;

  // With --cell-size the spacing is still measured and recorded.
  ASSERT_EQ(runFlipscope("convert '" + vdb.string() + "' -o " + path("coarse") + " --cell-size 0.1 -q").exitCode, 0);
  auto coarse = nlohmann::json::parse(runFlipscope("info --json " + path("coarse")).output);
  EXPECT_EQ(coarse["cell_size"].get<double>(), 0.1);
  EXPECT_EQ(coarse["particle_spacing"].get<double>(), spacing);
  EXPECT_NEAR(coarse["particle_spacing_cells"].get<double>(), spacing / 0.1, 1e-12);
}

TEST_F(Cli, AGivenParticleSpacingIsRecordedAndSkipsItsReadAndWithADomainConvertReadsOnce) {
  ASSERT_EQ(runFlipscope("synth -o " + path("s.ply") + " --particles 30k --velocity").exitCode, 0);
  CommandRun measured = runFlipscope("convert " + path("s.ply") + " -o " + path("measured") + " --cell-size 0.02");
  ASSERT_EQ(measured.exitCode, 0) << measured.output;
  EXPECT_NE(measured.output.find("particle spacing of frame 0"), std::string::npos) << measured.output;
  const auto j = nlohmann::json::parse(runFlipscope("info --json " + path("measured")).output);
  const double spacing = j["particle_spacing"].get<double>();
  ASSERT_GT(spacing, 0.0);
  char exact[32];
  std::snprintf(exact, sizeof exact, "%.17g", spacing);

  // Given the spacing it measured: the same store, without the spacing's read of the frame.
  CommandRun given = runFlipscope("convert " + path("s.ply") + " -o " + path("given") +
                                  " --cell-size 0.02 --particle-spacing " + exact);
  ASSERT_EQ(given.exitCode, 0) << given.output;
  EXPECT_EQ(given.output.find("particle spacing of frame"), std::string::npos) << given.output;
  EXPECT_NE(given.output.find("scan bounds"), std::string::npos) << "the domain still takes a read: " << given.output;
  EXPECT_NE(given.output.find("from --particle-spacing"), std::string::npos) << given.output;
  EXPECT_EQ(frameBytesWithoutStoreId(dir / "given" / "frame_000000.fsf"),
            frameBytesWithoutStoreId(dir / "measured" / "frame_000000.fsf"));

  // With the domain as well, the frame is read once: by the binning.
  std::string domain;
  for (const auto& v : j["origin"]) domain += std::to_string(v.get<double>() - 0.01) + ",";
  domain += "1.1,1.1,1.1";
  CommandRun once = runFlipscope("convert " + path("s.ply") + " -o " + path("once") + " --domain " + domain +
                                 " --cell-size 0.02 --particle-spacing " + exact);
  ASSERT_EQ(once.exitCode, 0) << once.output;
  EXPECT_EQ(once.output.find("particle spacing of frame"), std::string::npos) << once.output;
  EXPECT_EQ(once.output.find("scan bounds"), std::string::npos) << once.output;
  const auto k = nlohmann::json::parse(runFlipscope("info --json " + path("once")).output);
  EXPECT_EQ(k["particle_spacing"].get<double>(), spacing);
  EXPECT_EQ(k["frames"][0]["particles"], j["frames"][0]["particles"]);

  // 0: unknown, not measured; the cell size then falls back to the default resolution.
  CommandRun unknown = runFlipscope("convert " + path("s.ply") + " -o " + path("unknown") + " --particle-spacing 0");
  ASSERT_EQ(unknown.exitCode, 0) << unknown.output;
  EXPECT_NE(unknown.output.find("particle spacing unknown (not measured (--particle-spacing 0))"), std::string::npos)
      << unknown.output;
  EXPECT_NE(unknown.output.find("1024 cells along the longest axis"), std::string::npos) << unknown.output;
  EXPECT_TRUE(
      nlohmann::json::parse(runFlipscope("info --json " + path("unknown")).output)["particle_spacing"].is_null());

  // An existing store keeps its spacing: another is refused, naming both.
  CommandRun other = runFlipscope("convert " + path("s.ply") + " -o " + path("measured") + " --particle-spacing 0.5");
  EXPECT_EQ(other.exitCode, 2) << other.output;
  EXPECT_NE(other.output.find("the store's particle spacing is"), std::string::npos) << other.output;
  EXPECT_NE(other.output.find("not 0.5 (--particle-spacing)"), std::string::npos) << other.output;
  CommandRun unknownOther =
      runFlipscope("convert " + path("s.ply") + " -o " + path("unknown") + " --particle-spacing 0.5");
  EXPECT_EQ(unknownOther.exitCode, 2) << unknownOther.output;
  EXPECT_NE(unknownOther.output.find("particle spacing is unknown (0), not 0.5"), std::string::npos)
      << unknownOther.output;
  CommandRun same =
      runFlipscope("convert " + path("s.ply") + " -o " + path("measured") + " --particle-spacing " + exact);
  EXPECT_EQ(same.exitCode, 0) << same.output;
  CommandRun negative = runFlipscope("convert " + path("s.ply") + " -o " + path("neg") + " --particle-spacing -1");
  EXPECT_EQ(negative.exitCode, 2) << negative.output;
  EXPECT_FALSE(fs::exists(dir / "neg"));
}

TEST_F(Cli, TheStoresUpAxisOrientsRenderUnlessGivenUp) {
  const fs::path vdb = flipscope::testing::mantaflowFile("data", "fluid_data_0030.vdb");
  CommandRun inspect = runFlipscope("inspect '" + vdb.string() + "'");
  ASSERT_EQ(inspect.exitCode, 0) << inspect.output;
  EXPECT_NE(inspect.output.find("up axis     z (the file's conventions"), std::string::npos) << inspect.output;
  CommandRun convert = runFlipscope("convert '" + vdb.string() + "' -o " + path("store"));
  ASSERT_EQ(convert.exitCode, 0) << convert.output;
  EXPECT_NE(convert.output.find("up axis z (the conventions of"), std::string::npos) << convert.output;
  EXPECT_EQ(nlohmann::json::parse(runFlipscope("info --json " + path("store")).output)["up_axis"], "z");
  EXPECT_NE(runFlipscope("info " + path("store")).output.find("up axis    z"), std::string::npos);

  const auto cameraUp = [&](const std::string& options) {
    CommandRun render = runFlipscope("render " + path("store") + " -o " + path("a.png") +
                                     " --size 64x36 -q --save-camera " + path("cam.json") + " " + options);
    EXPECT_EQ(render.exitCode, 0) << render.output;
    std::ifstream in(path("cam.json"));
    return nlohmann::json::parse(in)["up"];
  };
  EXPECT_EQ(cameraUp(""), nlohmann::json::array({0.0, 0.0, 1.0})) << "the store's";
  EXPECT_EQ(cameraUp("--up auto"), nlohmann::json::array({0.0, 0.0, 1.0}));
  EXPECT_EQ(cameraUp("--up y"), nlohmann::json::array({0.0, 1.0, 0.0})) << "--up wins";

  CommandRun bad = runFlipscope("convert '" + vdb.string() + "' -o " + path("other") + " --up w");
  EXPECT_EQ(bad.exitCode, 2) << bad.output;
  EXPECT_NE(bad.output.find("--up: expected auto, x, y or z, got 'w'"), std::string::npos) << bad.output;
  // A store of files that say nothing records nothing, and renders take y.
  ASSERT_EQ(runFlipscope("synth -o " + path("s.ply") + " --particles 2k").exitCode, 0);
  ASSERT_EQ(runFlipscope("convert " + path("s.ply") + " -o " + path("plain") + " -q").exitCode, 0);
  EXPECT_TRUE(nlohmann::json::parse(runFlipscope("info --json " + path("plain")).output)["up_axis"].is_null());
  CommandRun plain = runFlipscope("render " + path("plain") + " -o " + path("p.png") +
                                  " --size 64x36 -q --save-camera " + path("cam.json"));
  ASSERT_EQ(plain.exitCode, 0) << plain.output;
  std::ifstream in(path("cam.json"));
  EXPECT_EQ(nlohmann::json::parse(in)["up"], nlohmann::json::array({0.0, 1.0, 0.0}));
}

TEST_F(Cli, DamagedStoreFailsVerifyNamingFileAndBrick) {
  ASSERT_EQ(runFlipscope("synth -o " + path("f.bin") + " --particles 5k").exitCode, 0);
  ASSERT_EQ(runFlipscope("convert " + path("f.bin") + " -o " + path("store") + " --resolution 64 --brick-size 32 -q")
                .exitCode,
            0);
  const fs::path frame = dir / "store" / "frame_000000.fsf";
  ASSERT_TRUE(fs::exists(frame));
  {
    std::fstream f(frame, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(20);
    f.put('\x7f');
  }
  EXPECT_EQ(runFlipscope("info " + path("store")).exitCode, 0);  // the index is intact
  CommandRun verify = runFlipscope("info --verify " + path("store"));
  EXPECT_EQ(verify.exitCode, 1) << verify.output;
  EXPECT_NE(verify.output.find("frame_000000.fsf: brick 0"), std::string::npos) << verify.output;

  // A truncated frame file is refused by plain info, with exit code 3 (bad input).
  fs::resize_file(frame, fs::file_size(frame) - 5);
  CommandRun info = runFlipscope("info " + path("store"));
  EXPECT_EQ(info.exitCode, 3) << info.output;
  EXPECT_NE(info.output.find("frame_000000.fsf"), std::string::npos) << info.output;
}

TEST_F(Cli, BadInputsGiveClearErrorsAndExitCodes) {
  std::ofstream(path("odd.bin"), std::ios::binary) << "12345678901234";  // 14 bytes: not a multiple of 12
  CommandRun odd = runFlipscope("convert " + path("odd.bin") + " -o " + path("s1"));
  EXPECT_EQ(odd.exitCode, 3) << odd.output;
  EXPECT_NE(odd.output.find("odd.bin"), std::string::npos) << odd.output;
  EXPECT_FALSE(fs::exists(dir / "s1" / "frame_000000.fsf"));

  CommandRun missing = runFlipscope("convert " + path("nothing.ply") + " -o " + path("s2"));
  EXPECT_EQ(missing.exitCode, 3) << missing.output;
  EXPECT_NE(missing.output.find("nothing.ply"), std::string::npos) << missing.output;

  CommandRun badMem = runFlipscope("convert " + path("odd.bin") + " -o " + path("s3") + " --mem lots");
  EXPECT_EQ(badMem.exitCode, 2) << badMem.output;
  EXPECT_NE(badMem.output.find("--mem"), std::string::npos) << badMem.output;

  // Numbers out of range are named plainly, without CLI11's range up to the largest double, and
  // a usage error reads as every other error.
  for (const auto& [option, value, expected] :
       std::vector<std::array<std::string, 3>>{{"--cell-size", "abc", "a number above 0"},
                                               {"--cell-size", "0", "a number above 0"},
                                               {"--cell-size", "1e400", "a number above 0"},
                                               {"--resolution", "-3", "a whole number from 1 to 2147483647"},
                                               {"--resolution", "2.5", "a whole number from 1 to 2147483647"},
                                               {"--resolution", "2147483648", "a whole number from 1 to 2147483647"},
                                               {"--resolution", "0x10", "a whole number from 1 to 2147483647"},
                                               {"--particle-spacing", "-1", "a number of 0 or more"},
                                               {"--particle-spacing", "inf", "a number of 0 or more"},
                                               {"--particle-spacing", "nan", "a number of 0 or more"},
                                               {"--particle-spacing", "1.5x", "a number of 0 or more"}}) {
    CommandRun bad = runFlipscope("convert " + path("odd.bin") + " -o " + path("s4") + " " + option + " " + value);
    EXPECT_EQ(bad.exitCode, 2) << bad.output;
    EXPECT_NE(bad.output.find("flipscope: error: " + option + ": expected " + expected + ", got '" + value + "'"),
              std::string::npos)
        << bad.output;
    EXPECT_EQ(bad.output.find("1797"), std::string::npos) << bad.output;
    EXPECT_FALSE(fs::exists(dir / "s4"));
  }

  // Counts are decimal: "010" is 10 cells, as "10" (CLI11 alone reads it in octal, as 8).
  ASSERT_EQ(runFlipscope("synth -o " + path("few.ply") + " --particles 1k").exitCode, 0);
  auto cellSizeLine = [&](const std::string& resolution, const std::string& store) {
    const CommandRun run =
        runFlipscope("convert " + path("few.ply") + " -o " + path(store) + " --resolution " + resolution);
    EXPECT_EQ(run.exitCode, 0) << run.output;
    const auto at = run.output.find("cell size");
    return at == std::string::npos ? std::string() : run.output.substr(at, run.output.find(' ', at + 10) - at);
  };
  const std::string ten = cellSizeLine("10", "r10");
  EXPECT_FALSE(ten.empty());
  EXPECT_EQ(cellSizeLine("010", "r010"), ten);
  EXPECT_EQ(cellSizeLine("+10", "rplus10"), ten);
  EXPECT_NE(cellSizeLine("8", "r8"), ten);
  // So is every integer option: render's --frame 010 asks for frame 10, not 8.
  const CommandRun frame = runFlipscope("render " + path("r10") + " -o " + path("f.png") + " --frame 010");
  EXPECT_EQ(frame.exitCode, 2) << frame.output;
  EXPECT_NE(frame.output.find("has no frame 10 "), std::string::npos) << frame.output;

  CommandRun notStore = runFlipscope("info " + path(""));
  EXPECT_EQ(notStore.exitCode, 3) << notStore.output;
  EXPECT_NE(notStore.output.find("store.fsh missing"), std::string::npos) << notStore.output;

  EXPECT_EQ(runFlipscope("frobnicate").exitCode, 2);
}

TEST_F(Cli, OutOfCoreConvertMatchesInCore) {
  ASSERT_EQ(runFlipscope("synth -o " + path("big.bin") + " --particles 600k").exitCode, 0);
  ASSERT_EQ(runFlipscope("convert " + path("big.bin") + " -o " + path("a") + " --resolution 256 -q").exitCode, 0);
  CommandRun out = runFlipscope("convert " + path("big.bin") + " -o " + path("b") + " --resolution 256 --mem 2M");
  ASSERT_EQ(out.exitCode, 0) << out.output;
  // The frame's line says how much went to the spill files (SpillBucketsTest checks the count).
  EXPECT_TRUE(std::regex_search(
      out.output, std::regex(R"(\(out of core: [1-9][0-9.]* [kM] bytes spilled to [1-9][0-9]* buckets\))")))
      << out.output;
  std::string idA, idB;
  const std::string a = frameBytesWithoutStoreId(dir / "a" / "frame_000000.fsf", &idA);
  const std::string b = frameBytesWithoutStoreId(dir / "b" / "frame_000000.fsf", &idB);
  ASSERT_GT(a.size(), 40u);
  EXPECT_NE(idA, idB) << "two stores with the same id";
  EXPECT_EQ(a, b);
}

// Huge page advice (core/HugePageAdvice.h) changes where memory comes from, never a byte of a
// store; a value of FLIPSCOPE_HUGE_PAGES that is none of on, off, auto is a usage error of the
// commands that choose (not of --help, nor of info).
TEST_F(Cli, HugePageAdviceOnOrOffWritesTheSameStore) {
  ASSERT_EQ(runFlipscope("synth -o " + path("f.bin") + " --particles 600k").exitCode, 0);
  ::setenv("FLIPSCOPE_HUGE_PAGES", "on", 1);
  const CommandRun on = runFlipscope("convert " + path("f.bin") + " -o " + path("on") + " --resolution 256 -q");
  ::setenv("FLIPSCOPE_HUGE_PAGES", "off", 1);
  const CommandRun off = runFlipscope("convert " + path("f.bin") + " -o " + path("off") + " --resolution 256 -q");
  ::setenv("FLIPSCOPE_HUGE_PAGES", "maybe", 1);
  const CommandRun bad = runFlipscope("convert " + path("f.bin") + " -o " + path("bad") + " --resolution 256 -q");
  // Commands that allocate little never choose, so never read the variable.
  const CommandRun help = runFlipscope("convert --help");
  const CommandRun info = runFlipscope("info " + path("on"));
  ::unsetenv("FLIPSCOPE_HUGE_PAGES");
  EXPECT_EQ(help.exitCode, 0) << help.output;
  EXPECT_EQ(info.exitCode, 0) << info.output;
  ASSERT_EQ(on.exitCode, 0) << on.output;
  ASSERT_EQ(off.exitCode, 0) << off.output;
  EXPECT_EQ(bad.exitCode, 2) << bad.output;
  EXPECT_NE(bad.output.find("FLIPSCOPE_HUGE_PAGES: on, off or auto, not 'maybe'"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(dir / "bad"));
  const std::string a = frameBytesWithoutStoreId(dir / "on" / "frame_000000.fsf");
  ASSERT_GT(a.size(), 40u);
  EXPECT_EQ(a, frameBytesWithoutStoreId(dir / "off" / "frame_000000.fsf"));
}

// `convert --help` names what convert reads, from the format table: endings that no other line
// of the help mentions.
TEST_F(Cli, ConvertHelpNamesEveryFormatItReads) {
  const CommandRun help = runFlipscope("convert --help");
  ASSERT_EQ(help.exitCode, 0) << help.output;
  for (const char* ending : {".bgeo.sc", ".geo.sc", ".prt", ".pdb", ".vtk", ".vtu", ".vtp"})
    EXPECT_NE(help.output.find(ending), std::string::npos) << ending << " in " << help.output;
}

// Issue 12, list item 8: every kind of failure has its exit code and a message naming the file.
TEST_F(Cli, ExitCodesAndMessagesForEveryKindOfFailure) {
  ASSERT_EQ(runFlipscope("synth -o " + path("f.ply") + " --particles 20k").exitCode, 0);
  ASSERT_EQ(runFlipscope("convert " + path("f.ply") + " -o " + path("store") + " -q").exitCode, 0);
  auto expectRun = [&](const std::string& args, int code, const std::string& says) {
    const CommandRun r = runFlipscope(args);
    EXPECT_EQ(r.exitCode, code) << args << "\n" << r.output;
    EXPECT_NE(r.output.find(says), std::string::npos) << args << "\n" << r.output;
  };
  // Inputs that are not particle files.
  fs::create_directories(dir / "folder.ply");
  expectRun("convert " + path("folder.ply") + " -o " + path("s1"), 3, "folder.ply: is a directory");
  expectRun("convert /dev/null -o " + path("s2"), 3, "/dev/null: is not a regular file");
  expectRun("convert " + path("none.vdb") + " -o " + path("s3"), 3, "none.vdb: no such file");
  // Outputs that cannot be created: exit 4, naming them.
  expectRun("convert " + path("f.ply") + " -o /proc/flipscope-no/store", 4, "/proc/flipscope-no/store");
  expectRun("render " + path("store") + " -o " + path("no/such/dir/x.png") + " --size 32x18 --device cpu", 4,
            "no/such/dir/x.png");
  // Sizes beyond 32 bits are refused, not wrapped.
  expectRun("render " + path("store") + " -o " + path("x.png") + " --size 4294967360x4294967332", 2, "--size");
  // A render stopped by its pass limit writes its image and says so with exit 5: a frame of 33
  // bricks, more in view than a pool of 1 MB holds, so that its first pass cannot have them all.
  ASSERT_EQ(runFlipscope("convert " + path("f.ply") + " -o " + path("bricks") + " --resolution 256 -q").exitCode, 0);
  expectRun("render " + path("bricks") + " -o " + path("limit.png") +
                " --size 64x36 --device cpu --max-passes 1 --gpu-mem 1M",
            5, "--max-passes");
  EXPECT_TRUE(fs::exists(dir / "limit.png"));
  // Data far from the origin renders when doubles can frame it, and otherwise says why plainly.
  auto writeRaw = [&](const std::string& name, float step) {
    std::ofstream out(path(name), std::ios::binary);
    for (int i = 0; i < 1000; ++i) {
      const float p[3] = {1e30f, 1e30f + float(i % 10) * step, 1e30f};
      out.write(reinterpret_cast<const char*>(p), sizeof p);
    }
  };
  writeRaw("far.bin", 1e23f);
  writeRaw("tiny.bin", 0);
  for (const char* name : {"far", "tiny"})
    ASSERT_EQ(runFlipscope("convert " + path(std::string(name) + ".bin") + " -o " + path(name) + " -q").exitCode, 0)
        << name;
  const CommandRun far =
      runFlipscope("render " + path("far") + " -o " + path("far.png") + " --size 32x18 --device cpu");
  EXPECT_EQ(far.exitCode, 0) << far.output;
  expectRun("render " + path("tiny") + " -o " + path("tiny.png") + " --size 32x18 --device cpu", 3,
            "too far from the origin for its size");
  // info --json on a store whose path is not UTF-8: valid JSON, exit 0.
  const fs::path odd = dir / "store-\xff\xfe";
  fs::copy(dir / "store", odd, fs::copy_options::recursive);
  const CommandRun info = runFlipscope("info --json '" + odd.string() + "'");
  EXPECT_EQ(info.exitCode, 0) << info.output;
  EXPECT_TRUE(nlohmann::json::accept(info.output)) << info.output;
}

}  // namespace
