// flipscope inspect on real files of other applications: the format, the point count, bounds,
// attributes with types and ranges, the frames of a pattern; --header-only reads no data.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "TestSupport.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;

const fs::path kFormats = fs::path(FLIPSCOPE_DATA_DIR) / "formats";

nlohmann::json inspect(const std::string& args) {
  const auto run = testing::runFlipscope("inspect --json " + args);
  EXPECT_EQ(run.exitCode, 0) << run.output;
  return nlohmann::json::parse(run.output, nullptr, false);
}

const nlohmann::json* attribute(const nlohmann::json& file, const std::string& name) {
  for (const auto& a : file["attributes"])
    if (a["name"] == name) return &a;
  return nullptr;
}

TEST(Inspect, HoudiniParticlesWithTheirAttributesAndRanges) {
  const auto all = inspect("'" + (kFormats / "houdini-modern" / "simple_partanim.0017.bgeo").string() + "'");
  ASSERT_EQ(all.size(), 1u);
  const auto& file = all[0]["input"];
  EXPECT_EQ(file["format"], "bgeo");
  EXPECT_NE(file["format_description"].get<std::string>().find("Houdini 13"), std::string::npos);
  EXPECT_EQ(file["points"], 10);
  EXPECT_EQ(file["points_declared"], 10);
  EXPECT_TRUE(file["velocity"].get<bool>());
  const auto* id = attribute(file, "id");
  ASSERT_NE(id, nullptr);
  EXPECT_EQ((*id)["type"], "int32");
  EXPECT_EQ((*id)["min"][0], 0.0);
  EXPECT_EQ((*id)["max"][0], 9.0);
  const auto* v = attribute(file, "v");
  ASSERT_NE(v, nullptr);
  EXPECT_EQ((*v)["arity"], 3);
  EXPECT_LT((*v)["min"][0].get<double>(), (*v)["max"][0].get<double>());
  // Bounds hold every point: x spans about -12 to 18.7 in this file.
  EXPECT_NEAR(file["bounds"]["min"][0].get<double>(), -12.0478, 1e-3);
  EXPECT_NEAR(file["bounds"]["max"][0].get<double>(), 18.6682, 1e-3);
}

TEST(Inspect, ContainersPatternsAndHeaderOnly) {
  const auto sc = inspect("'" + (kFormats / "houdini-bgeo-sc" / "labs_star.1.bgeo.sc").string() + "'");
  ASSERT_EQ(sc.size(), 1u);
  EXPECT_EQ(sc[0]["input"]["containers"], nlohmann::json::array({"scf1"}));
  EXPECT_EQ(sc[0]["input"]["points"], 10);

  const auto sequence = inspect("'" + (kFormats / "realflow-bin" / "Circle01_#####.bin").string() + "'");
  ASSERT_EQ(sequence.size(), 1u);
  EXPECT_GE(sequence[0]["frames"].size(), 3u);
  EXPECT_EQ(sequence[0]["frames"][0], 0);
  EXPECT_EQ(sequence[0]["input"]["format"], "realflow-bin");

  const auto header = inspect("--header-only '" + (kFormats / "vtk" / "bunny_frame_14_7705_particles.vtk").string() + "'");
  ASSERT_EQ(header.size(), 1u);
  EXPECT_EQ(header[0]["input"]["points_declared"], 7706);
  EXPECT_FALSE(header[0]["input"].contains("points")) << "--header-only reads no data";
  ASSERT_NE(attribute(header[0]["input"], "velocity"), nullptr);
  EXPECT_FALSE(attribute(header[0]["input"], "velocity")->contains("min"));
}

TEST(Inspect, AFileWithoutPointsIsAnErrorNamingIt) {
  const fs::path empty = kFormats / "houdini-modern" / "empty.bgeo";
  const auto run = testing::runFlipscope("inspect '" + empty.string() + "'");
  EXPECT_EQ(run.exitCode, 3) << run.output;
  EXPECT_NE(run.output.find("empty.bgeo: holds no points"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace flipscope
