// Particle kinds from the command line: convert of Blender Mantaflow's FLIP and secondary files,
// info (text and --json) with the cells of each kind, inspect naming the kind attribute, and
// the exit codes and messages of --kind-attribute.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;

using flipscope::testing::CommandRun;
using flipscope::testing::runFlipscope;

const std::string kFlip30 = flipscope::testing::mantaflowFile("data", "fluid_data_0030.vdb").string();
const std::string kSecondary30 = flipscope::testing::mantaflowFile("particles", "fluid_particles_0030.vdb").string();

class KindsCli : public ::testing::Test {
 protected:
  std::string path(const std::string& name) const { return (dir / name).string(); }
  flipscope::testing::TempDir temp{"kinds-cli"};
  const fs::path& dir = temp.path();
};

TEST_F(KindsCli, ConvertOfFlipAndSecondaryFilesStoresKindsAndInfoCountsThem) {
  const CommandRun convert =
      runFlipscope("convert '" + kFlip30 + "' '" + kSecondary30 + "' -o " + path("store") + " --resolution 100");
  ASSERT_EQ(convert.exitCode, 0) << convert.output;
  EXPECT_NE(convert.output.find("particle kinds"), std::string::npos) << convert.output;
  const CommandRun json = runFlipscope("info --json --verify " + path("store"));
  ASSERT_EQ(json.exitCode, 0) << json.output;
  const auto j = nlohmann::json::parse(json.output);
  EXPECT_EQ(j["particle_kinds"], true);
  const auto& cells = j["total"]["kind_cells"];
  std::uint64_t sum = 0;
  for (const char* kind : {"liquid", "foam", "spray", "bubble"}) {
    ASSERT_TRUE(cells.contains(kind)) << json.output;
    EXPECT_GT(cells[kind].get<std::uint64_t>(), 0u) << kind;
    sum += cells[kind].get<std::uint64_t>();
  }
  EXPECT_EQ(j["frames"][0]["kind_cells"], cells);
  EXPECT_EQ(sum, j["frames"][0]["occupied_cells"].get<std::uint64_t>()) << "every occupied cell has one kind";
  const CommandRun text = runFlipscope("info " + path("store"));
  ASSERT_EQ(text.exitCode, 0) << text.output;
  const std::string counts = "liquid " + std::to_string(cells["liquid"].get<std::uint64_t>()) + ", foam " +
                             std::to_string(cells["foam"].get<std::uint64_t>());
  EXPECT_NE(text.output.find("kinds      a particle kind per cell; cells over the frames: " + counts),
            std::string::npos)
      << text.output;

  // --kind-attribute none: no kinds, and info says so.
  ASSERT_EQ(
      runFlipscope("convert '" + kFlip30 + "' '" + kSecondary30 + "' -o " + path("none") + " --kind-attribute none -q")
          .exitCode,
      0);
  const auto none = nlohmann::json::parse(runFlipscope("info --json " + path("none")).output);
  EXPECT_EQ(none["particle_kinds"], false);
  EXPECT_TRUE(none["total"]["kind_cells"].is_null());
  EXPECT_NE(runFlipscope("info " + path("none")).output.find("kinds      none"), std::string::npos);
}

TEST_F(KindsCli, InspectNamesTheKindAttributeOfTheSecondaryFileOnly) {
  const CommandRun secondary = runFlipscope("inspect '" + kSecondary30 + "'");
  ASSERT_EQ(secondary.exitCode, 0) << secondary.output;
  EXPECT_NE(secondary.output.find("kinds       U: particle types"), std::string::npos) << secondary.output;
  const CommandRun flip = runFlipscope("inspect --json '" + kFlip30 + "'");
  ASSERT_EQ(flip.exitCode, 0) << flip.output;
  EXPECT_TRUE(nlohmann::json::parse(flip.output)[0]["kind_attribute"].is_null()) << "U of the FLIP grid 'particles'";
}

TEST_F(KindsCli, KindAttributeErrorsExitWithTheirCodesNamingOptionAndFile) {
  const CommandRun unknown =
      runFlipscope("convert '" + kFlip30 + "' '" + kSecondary30 + "' -o " + path("a") + " --kind-attribute nosuch -q");
  EXPECT_EQ(unknown.exitCode, 3) << unknown.output;
  EXPECT_NE(unknown.output.find("--kind-attribute"), std::string::npos) << unknown.output;
  EXPECT_NE(unknown.output.find(kFlip30), std::string::npos) << unknown.output;
  EXPECT_NE(unknown.output.find("'nosuch'"), std::string::npos) << unknown.output;
  const CommandRun floating =
      runFlipscope("convert '" + kSecondary30 + "' -o " + path("b") + " --kind-attribute particles_life_secondary -q");
  EXPECT_EQ(floating.exitCode, 3) << floating.output;
  EXPECT_NE(floating.output.find("--kind-attribute: attribute 'particles_life_secondary' is float32"), std::string::npos)
      << floating.output;
  EXPECT_NE(floating.output.find(kSecondary30), std::string::npos) << floating.output;
  const CommandRun empty = runFlipscope("convert '" + kSecondary30 + "' -o " + path("c") + " --kind-attribute '' -q");
  EXPECT_EQ(empty.exitCode, 2) << empty.output;
  EXPECT_NE(empty.output.find("--kind-attribute"), std::string::npos) << empty.output;
  EXPECT_FALSE(fs::exists(dir / "a") || fs::exists(dir / "b") || fs::exists(dir / "c"));
}

}  // namespace
