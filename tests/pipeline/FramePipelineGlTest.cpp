// The GPU frame pipeline (ray-caster and screen-space stages in one OpenGL context, Mesa llvmpipe
// here) against the CPU reference, image for image.
#include <gtest/gtest.h>

#include "GlTestSupport.h"

#include <cmath>

#include "OutputLayerChecks.h"
#include "TestSupport.h"
#include "core/Error.h"
#include "pipeline/FramePipeline.h"
#include "raycast/RaycastScenes.h"

namespace flipscope {
namespace {

TEST(FramePipelineGl, EqualsTheCpuReference) {
  testing::TempDir dir("pipeline");
  const testing::BallScene ball;
  RenderSettings settings = ball.settings();
  settings.jitter = 0.25f;
  const BrickStore store = ball.makeStore(dir.path() / "store");
  std::optional<FramePipeline> gpu;
  try {
    gpu.emplace(store, DeviceChoice::Gpu, settings, SurfaceSettings{});
  } catch (const gl::Unavailable& e) {
    FLIPSCOPE_SKIP_WITHOUT_GL(e.what());
  }
  FramePipeline cpu(store, DeviceChoice::CpuReference, settings, SurfaceSettings{});
  Camera camera = ball.camera();
  camera.eye += glm::dvec3(40, 30, 0);  // an oblique view: silhouettes, grazing normals
  const FrameOutput a = gpu->render(0, camera), b = cpu.render(0, camera);
  ASSERT_EQ(a.image.rgba.size(), b.image.rgba.size());
  int differentMask = 0;
  double depth = 0, colour = 0, thickness = 0;
  for (std::size_t i = 0; i < a.image.rgba.size(); ++i) {
    if (std::isfinite(a.image.depth[i]) != std::isfinite(b.image.depth[i])) {
      ++differentMask;
      continue;
    }
    colour = std::max(colour, double(glm::length(glm::vec3(a.image.rgba[i] - b.image.rgba[i]))));
    if (!std::isfinite(a.image.depth[i])) continue;
    depth = std::max(depth, double(std::abs(a.image.depth[i] - b.image.depth[i])));
    thickness = std::max(thickness, double(std::abs(a.image.thickness[i] - b.image.thickness[i])));
  }
  // Float rounding may flip a grazing ray; everything else agrees.
  EXPECT_LE(differentMask, 3);
  EXPECT_LT(depth, 2e-2);  // depths are ~150 world units
  EXPECT_LT(thickness, 1.5);  // one cell
  EXPECT_LT(colour, 0.05);
}

TEST(FramePipelineGl, TheColourAloneIsTheColourOfAllLayersAndLeavesTheOthersEmpty) {
  try {
    testing::expectTheColourAloneIsTheColourOfAllLayers(DeviceChoice::Gpu);
  } catch (const gl::Unavailable& e) {
    FLIPSCOPE_SKIP_WITHOUT_GL(e.what());
  }
}

}  // namespace
}  // namespace flipscope
