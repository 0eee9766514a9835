// `flipscope bench scale` on a small frame: each stage runs in a child of its own, and the report
// adds up: the store holds the particles synth wrote, the first image touched some of the
// frame's bricks, and a second run reuses the frame of --work-dir.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "TestSupport.h"

namespace {

TEST(BenchScale, ReportsEveryStageOfASmallFrameAndReusesItsWorkDirectory) {
  flipscope::testing::TempDir dir("bench-scale");
  const std::string command =
      "bench scale --particles 300k --mem 64M --size 96x54 --orbit-frames 2 --json --work-dir '" + dir.path().string() +
      "'";
  const flipscope::testing::CommandRun run = flipscope::testing::runFlipscope(command);
  ASSERT_EQ(run.exitCode, 0) << run.output;
  const auto j = nlohmann::json::parse(run.output);
  const auto particles = j["particles"].get<std::uint64_t>();
  EXPECT_EQ(j["raw_bytes"].get<std::uint64_t>(), 12 * particles) << "the store holds every particle synth wrote";
  EXPECT_GT(particles, 290000u);
  EXPECT_GT(j["synth_s"].get<double>(), 0.0);
  EXPECT_GT(j["convert_peak_rss_bytes"].get<double>(), 0.0);
  EXPECT_GT(j["render_peak_rss_bytes"].get<double>(), 0.0);
  EXPECT_GT(j["store_bytes"].get<std::uint64_t>(), 0u);
  EXPECT_NEAR(j["store_bits_per_particle"].get<double>(), 8.0 * j["store_bytes"].get<double>() / double(particles),
              1e-9);
  EXPECT_GT(j["bricks_touched"].get<std::uint64_t>(), 0u);
  EXPECT_LE(j["bricks_touched"].get<std::uint64_t>(), j["frame_bricks"].get<std::uint64_t>());
  EXPECT_EQ(j["warm_frame_ms"].size(), 2u);
  EXPECT_EQ(j["render_device"].get<std::string>().rfind("CPU", 0), 0u) << j["render_device"];
  EXPECT_TRUE(std::filesystem::exists(dir / "scale_render.png"));

  const flipscope::testing::CommandRun again = flipscope::testing::runFlipscope(command);
  ASSERT_EQ(again.exitCode, 0) << again.output;
  const auto k = nlohmann::json::parse(again.output);
  EXPECT_TRUE(k["synth_s"].is_null()) << "the frame of --work-dir is reused";
  EXPECT_EQ(k["particles"], j["particles"]);
}

TEST(BenchScale, AFailingStageIsNamedWithItsLog) {
  flipscope::testing::TempDir dir("bench-scale-fail");
  const flipscope::testing::CommandRun run = flipscope::testing::runFlipscope(
      "bench scale --particles 100k --mem 1k --size 32x18 --work-dir '" + dir.path().string() + "'");
  EXPECT_NE(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("the convert stage failed"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("convert.log"), std::string::npos) << run.output;
}

}  // namespace
