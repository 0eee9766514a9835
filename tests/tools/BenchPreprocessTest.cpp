// `flipscope bench preprocess --disk-runs N` on a small synth frame: each run's converts from
// disk are held against that run's disk read, and the summary's medians, ranges and counts are
// of the runs' own numbers; the first run's figures stay at the top of the JSON.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <string>
#include <vector>

#include "TestSupport.h"

namespace {

TEST(BenchPreprocess, EachDiskRunsConvertsAreHeldAgainstItsOwnDiskRead) {
  flipscope::testing::TempDir dir("bench-preprocess");
  const flipscope::testing::CommandRun run = flipscope::testing::runFlipscope(
      "bench preprocess --particles 200k --disk-runs 3 --json --work-dir '" + dir.path().string() + "'");
  ASSERT_EQ(run.exitCode, 0) << run.output;
  const auto j = nlohmann::json::parse(run.output);
  ASSERT_TRUE(j.contains("disk_runs") && j.contains("disk_summary")) << run.output;
  const auto& runs = j.at("disk_runs");
  ASSERT_EQ(runs.size(), 3u) << run.output;
  ASSERT_EQ(j.at("disk_summary").at("runs"), 3) << run.output;
  for (const char* convert : {"convert_from_disk_in_core", "convert_from_disk_one_read",
                              "convert_from_disk_out_of_core", "convert_from_disk_one_read_out_of_core"}) {
    const std::string seconds = std::string(convert) + "_s";
    // The top-level figures are the first run's.
    EXPECT_EQ(j.at(seconds), runs.at(0).at(seconds)) << convert;
    std::vector<double> ratios;
    for (std::size_t r = 0; r < runs.size(); ++r) {
      const auto& one = runs.at(r);
      const double disk = one.at("disk_read_s").get<double>();
      EXPECT_DOUBLE_EQ(disk, std::min({one.at("disk_read_16m_s").get<double>(), one.at("disk_read_2m_s").get<double>(),
                                       one.at("disk_read_2m_small_pages_s").get<double>()}))
          << "the fastest read is the disk's";
      EXPECT_GT(one.at(seconds).get<double>(), 0.0) << convert << " run " << r;
      ratios.push_back(one.at(seconds).get<double>() / disk);
    }
    const auto& summary = j.at("disk_summary").at(std::string(convert) + "_x_disk_read");
    for (std::size_t r = 0; r < runs.size(); ++r)
      EXPECT_DOUBLE_EQ(summary.at("per_run").at(r).get<double>(), ratios[r]) << convert << " run " << r;
    std::sort(ratios.begin(), ratios.end());
    EXPECT_DOUBLE_EQ(summary.at("median").get<double>(), ratios[1]) << convert;
    EXPECT_DOUBLE_EQ(summary.at("min").get<double>(), ratios[0]) << convert;
    EXPECT_DOUBLE_EQ(summary.at("max").get<double>(), ratios[2]) << convert;
    EXPECT_EQ(summary.at("met_runs").get<int>(),
              std::count_if(ratios.begin(), ratios.end(), [](double x) { return x <= 1.25; }))
        << convert;
  }
  // The converts' stores are gone; the input and the first convert's store stay.
  std::vector<std::string> left;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path()))
    left.push_back(entry.path().filename().string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"store", "synth.bin"}));
}

TEST(BenchPreprocess, OneDiskRunByDefaultWhoseFiguresAreAlsoAtTheTop) {
  flipscope::testing::TempDir dir("bench-preprocess-one");
  const flipscope::testing::CommandRun run = flipscope::testing::runFlipscope(
      "bench preprocess --particles 100k --json --work-dir '" + dir.path().string() + "'");
  ASSERT_EQ(run.exitCode, 0) << run.output;
  const auto j = nlohmann::json::parse(run.output);
  ASSERT_EQ(j.at("disk_runs").size(), 1u) << run.output;
  const auto& only = j.at("disk_runs").at(0);
  for (const auto& [key, value] : only.items()) EXPECT_EQ(j.at(key), value) << key;
  for (const char* key :
       {"disk_read_s", "disk_read_16m_s", "disk_read_2m_s", "disk_read_2m_small_pages_s", "disk_read_direct",
        "convert_from_disk_in_core_s", "convert_from_disk_one_read_out_of_core_s"})
    EXPECT_TRUE(only.contains(key)) << key;
  const auto& inCore = j.at("disk_summary").at("convert_from_disk_in_core_x_disk_read");
  EXPECT_DOUBLE_EQ(inCore.at("median").get<double>(),
                   only.at("convert_from_disk_in_core_s").get<double>() / only.at("disk_read_s").get<double>());
}

}  // namespace
