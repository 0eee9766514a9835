// Per-particle attributes end to end through the flipscope command: convert --attribute NAME of a
// PLY with an extra property (info and info --json show its name and range), the error for a
// name the file lacks, render --color-by / --color-map changing the pixels, the EXR's attribute
// channel, and the exit code 2 with the valid values for bad colour options.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <glm/geometric.hpp>

#include "TestSupport.h"
#include "pipeline/ImageWriter.h"

namespace {

namespace fs = std::filesystem;
using flipscope::testing::CommandRun;
using flipscope::testing::runFlipscope;

/// temperature of the particle at x: 10 x - 3 (x in 0.025 .. 0.975).
float temperatureAt(float x) { return 10.0f * x - 3.0f; }

class AttributeCli : public ::testing::Test {
 protected:
  void SetUp() override {
    // A slab of liquid, 40 x 8 x 40 particles 0.025 apart, with a float `temperature` growing
    // along x and an int `id`.
    std::ofstream ply(path("slab.ply"));
    const int nx = 40, ny = 8, nz = 40;
    ply << "ply\nformat ascii 1.0\nelement vertex " << nx * ny * nz
        << "\nproperty float x\nproperty float y\nproperty float z\nproperty float temperature\nproperty int id\n"
           "end_header\n";
    int id = 0;
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          const float x = 0.025f * float(i) + 0.0125f;
          char line[128];
          std::snprintf(line, sizeof line, "%.9g %.9g %.9g %.9g %d\n", x, 0.025 * j + 0.0125, 0.025 * k + 0.0125,
                        double(temperatureAt(x)), id++);
          ply << line;
        }
  }
  std::string path(const std::string& name) const { return (dir / name).string(); }
  flipscope::testing::TempDir temp{"attr-cli"};
  const fs::path& dir = temp.path();
};

TEST_F(AttributeCli, ConvertStoresTheNamedAttributeAndInfoShowsItsNameAndRange) {
  CommandRun convert =
      runFlipscope("convert " + path("slab.ply") + " -o " + path("store") + " --attribute temperature");
  ASSERT_EQ(convert.exitCode, 0) << convert.output;
  EXPECT_NE(convert.output.find("attribute temperature (scalar)"), std::string::npos) << convert.output;

  CommandRun info = runFlipscope("info --json " + path("store"));
  ASSERT_EQ(info.exitCode, 0) << info.output;
  const auto j = nlohmann::json::parse(info.output);
  EXPECT_EQ(j["attribute"], "temperature");
  EXPECT_EQ(j["attribute_kind"], "scalar");
  EXPECT_EQ(j["version"].get<std::uint32_t>(), 7u);
  const float lo = temperatureAt(0.0125f), hi = temperatureAt(0.025f * 39 + 0.0125f);
  ASSERT_TRUE(j["attribute_range"].is_array()) << info.output;
  EXPECT_EQ(j["attribute_range"][0].get<float>(), lo);
  EXPECT_EQ(j["attribute_range"][1].get<float>(), hi);
  EXPECT_EQ(j["frames"][0]["attribute_range"][0].get<float>(), lo);

  CommandRun text = runFlipscope("info " + path("store"));
  ASSERT_EQ(text.exitCode, 0) << text.output;
  EXPECT_NE(text.output.find("attribute  temperature (scalar), -2.875 to 6.875 over the frames"), std::string::npos)
      << text.output;

  // No velocities: auto stores none.
  ASSERT_EQ(runFlipscope("convert " + path("slab.ply") + " -o " + path("plain") + " -q").exitCode, 0);
  EXPECT_EQ(nlohmann::json::parse(runFlipscope("info --json " + path("plain")).output)["attribute"], "none");
}

TEST_F(AttributeCli, ANameTheInputLacksExitsWith3NamingTheFileAndItsAttributes) {
  CommandRun convert = runFlipscope("convert " + path("slab.ply") + " -o " + path("store") + " --attribute pscale");
  EXPECT_EQ(convert.exitCode, 3) << convert.output;
  EXPECT_NE(convert.output.find("slab.ply: has no attribute 'pscale' (it holds: temperature, id)"), std::string::npos)
      << convert.output;
  EXPECT_FALSE(fs::exists(path("store")));
  CommandRun speed = runFlipscope("convert " + path("slab.ply") + " -o " + path("store") + " --attribute speed");
  EXPECT_EQ(speed.exitCode, 3) << speed.output;
  EXPECT_NE(speed.output.find("no attribute 'speed'"), std::string::npos) << speed.output;
}

TEST_F(AttributeCli, RenderColoursByTheAttributeAndTheExrCarriesIt) {
  ASSERT_EQ(
      runFlipscope("convert " + path("slab.ply") + " -o " + path("store") + " --attribute temperature -q").exitCode, 0);
  const auto render = [&](const std::string& name, const std::string& options) {
    CommandRun r =
        runFlipscope("render " + path("store") + " -o " + path(name) + " --size 96x54 --device cpu " + options);
    EXPECT_EQ(r.exitCode, 0) << options << "\n" << r.output;
    return flipscope::readExr(path(name));
  };
  const auto plain = render("none.exr", "--color-by none");
  const auto viridis = render("viridis.exr", "--color-by attribute");
  const auto magma = render("magma.exr", "--color-by attribute --color-map magma");
  const auto spheres = render("spheres.exr", "--shading spheres --color-map coolwarm --color-range -3,7");
  const auto differing = [](const flipscope::ExrContents& a, const flipscope::ExrContents& b) {
    int pixels = 0;
    for (std::size_t i = 0; i < a.image.rgba.size(); ++i)
      pixels += glm::length(glm::vec3(a.image.rgba[i] - b.image.rgba[i])) > 0.05f;
    return pixels;
  };
  int covered = 0;
  for (float d : plain.image.depth) covered += std::isfinite(d);
  ASSERT_GT(covered, 500) << "the default camera frames the slab";
  EXPECT_GT(differing(plain, viridis), covered / 2);
  EXPECT_GT(differing(viridis, magma), covered / 2);
  EXPECT_GT(differing(viridis, spheres), covered / 2);

  // The EXR's `temperature` channel: the attribute's values where the slab is, 0 elsewhere.
  EXPECT_EQ(plain.others.count("temperature"), 1u) << "an EXR keeps the attribute without colour by it";
  ASSERT_EQ(viridis.others.count("temperature"), 1u);
  const auto& values = viridis.others.at("temperature");
  ASSERT_EQ(values.size(), viridis.image.rgba.size());
  float lowest = INFINITY, highest = -INFINITY;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(viridis.image.depth[i])) {
      EXPECT_EQ(values[i], 0.0f);
      continue;
    }
    EXPECT_GE(values[i], -2.875f - 1e-3f);
    EXPECT_LE(values[i], 6.875f + 1e-3f);
    lowest = std::min(lowest, values[i]);
    highest = std::max(highest, values[i]);
  }
  EXPECT_LT(lowest, 0.0f);
  EXPECT_GT(highest, 5.0f);
}

TEST_F(AttributeCli, APngThatShowsNoAttributeReadsNone) {
  // The attribute read, or not, shows in the pool the log line reports: its values take a ring
  // of their own. A PNG holds only the look: without colour by the attribute, none is read.
  ASSERT_EQ(
      runFlipscope("convert " + path("slab.ply") + " -o " + path("store") + " --attribute temperature -q").exitCode, 0);
  const auto pool = [&](const std::string& name, const std::string& options) {
    const CommandRun r =
        runFlipscope("render " + path("store") + " -o " + path(name) + " --size 96x54 --device cpu " + options);
    EXPECT_EQ(r.exitCode, 0) << options << "\n" << r.output;
    const std::size_t at = r.output.find("(pool ");
    EXPECT_NE(at, std::string::npos) << r.output;
    return at == std::string::npos ? std::string() : r.output.substr(at, r.output.find(')', at) - at);
  };
  const std::string exr = pool("a.exr", ""), png = pool("a.png", ""), coloured = pool("c.png", "--color-by attribute");
  EXPECT_NE(png, exr);
  EXPECT_EQ(coloured, exr);
  EXPECT_EQ(pool("s.png", "--shading attribute"), exr);
}

TEST_F(AttributeCli, BadColourOptionsExitWith2ListingTheValidValues) {
  ASSERT_EQ(
      runFlipscope("convert " + path("slab.ply") + " -o " + path("store") + " --attribute temperature -q").exitCode, 0);
  ASSERT_EQ(runFlipscope("convert " + path("slab.ply") + " -o " + path("plain") + " --attribute none -q").exitCode, 0);
  const auto expectError = [&](const std::string& store, const std::string& options, const std::string& needle) {
    CommandRun r = runFlipscope("render " + path(store) + " -o " + path("x.png") + " --size 32x18 " + options);
    EXPECT_EQ(r.exitCode, 2) << options << "\n" << r.output;
    EXPECT_NE(r.output.find(needle), std::string::npos) << options << "\n" << r.output;
  };
  expectError("store", "--color-map jet", "valid values: viridis, magma, coolwarm, blues");
  expectError("store", "--color-by speed", "valid values: attribute, none");
  expectError("store", "--color-range 3,1", "A must be less than B");
  expectError("store", "--color-range 2,2", "A must be less than B");
  expectError("store", "--color-range 1", "valid values: A,B with A < B");
  expectError("store", "--color-range a,2", "'a' is not a number");
  expectError("store", "--color-range 1,2,3", "expected two numbers");
  expectError("store", "--color-range 0,inf", "not finite");
  expectError("plain", "--color-by attribute", "no per-particle attribute");
  expectError("plain", "--color-map magma", "no per-particle attribute");
  EXPECT_FALSE(fs::exists(path("x.png")));
  // --shading attribute on a store without one stays the plain lit surface.
  CommandRun lit =
      runFlipscope("render " + path("plain") + " -o " + path("lit.png") + " --size 32x18 --shading attribute");
  EXPECT_EQ(lit.exitCode, 0) << lit.output;
}

}  // namespace
