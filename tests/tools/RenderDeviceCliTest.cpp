// `render --device cpu` (the fast CPU ray-caster) against `--device cpu-reference` on the
// Mantaflow sample with default settings: each names its device, and their images agree within
// TiledCpuRaycaster's tolerance (tests/raycast/TiledCpuRaycasterTest.cpp holds the detailed one).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "TestSupport.h"
#include "pipeline/ImageWriter.h"

namespace {

namespace fs = std::filesystem;
using flipscope::testing::runFlipscope;

TEST(RenderDeviceCli, TheFastCpuDeviceRendersTheReferencesImage) {
  flipscope::testing::TempDir dir("device");
  const fs::path vdb = flipscope::testing::mantaflowFile("data", "fluid_data_0030.vdb");
  const auto store = (dir.path() / "store").string();
  ASSERT_EQ(runFlipscope("convert '" + vdb.string() + "' -o " + store + " -q").exitCode, 0);
  flipscope::RenderImage images[2];
  const char* devices[2] = {"cpu", "cpu-reference"};
  const char* names[2] = {"render: CPU (", "render: CPU reference ("};
  for (int i = 0; i < 2; ++i) {
    const auto out = dir.path() / (std::string(devices[i]) + ".exr");
    const auto render = runFlipscope("render " + store + " -o '" + out.string() + "' --size 128x72 --device " + devices[i]);
    ASSERT_EQ(render.exitCode, 0) << render.output;
    EXPECT_NE(render.output.find(names[i]), std::string::npos) << render.output;
    images[i] = flipscope::readExr(out).image;
  }
  const auto& fast = images[0].unsmoothedDepth;
  const auto& reference = images[1].unsmoothedDepth;
  ASSERT_EQ(fast.size(), reference.size());
  int hits = 0, apart = 0;
  for (std::size_t i = 0; i < fast.size(); ++i) {
    if (std::isinf(reference[i]) != std::isinf(fast[i])) {
      ++apart;
      continue;
    }
    if (std::isinf(reference[i])) continue;
    ++hits;
    apart += std::abs(fast[i] - reference[i]) > 1e-4f * std::max(1.0f, std::abs(reference[i]));
  }
  EXPECT_GT(hits, int(fast.size()) / 10) << "the water fills the default view";
  EXPECT_LE(apart, int(fast.size()) / 200);
}

std::string lineStartingWith(const std::string& text, const std::string& prefix) {
  for (std::size_t at = 0; at < text.size();) {
    std::size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    if (text.compare(at, prefix.size(), prefix) == 0) return text.substr(at, end - at);
    at = end + 1;
  }
  return {};
}

// `devices` names what --device gpu gets and what auto picks: the CPU ray-caster, with its
// reason, whenever OpenGL is missing or software (llvmpipe here), else OpenGL.
TEST(RenderDeviceCli, DevicesNamesTheOpenGlContextAndWhatAutoPicks) {
  const auto run = runFlipscope("devices");
  ASSERT_EQ(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("EGL devices:\n"), std::string::npos) << run.output;
  const std::string gpu = lineStartingWith(run.output, "--device gpu: ");
  const std::string automatic = lineStartingWith(run.output, "--device auto: ");
  ASSERT_FALSE(gpu.empty()) << run.output;
  ASSERT_FALSE(automatic.empty()) << run.output;
  const bool hardware = gpu.find("unavailable") == std::string::npos && gpu.find("llvmpipe") == std::string::npos &&
                        gpu.find("softpipe") == std::string::npos;
  if (hardware) {
    EXPECT_EQ(automatic.rfind("--device auto: OpenGL (", 0), 0u) << run.output;
  } else {
    EXPECT_EQ(automatic.rfind("--device auto: CPU (", 0), 0u) << run.output;
    EXPECT_NE(automatic.find(", because "), std::string::npos) << run.output;
  }
}

}  // namespace
