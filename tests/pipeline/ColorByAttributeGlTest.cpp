// Colouring by attribute through the GPU frame pipeline (Mesa llvmpipe here) against the CPU
// reference: the colour and the image's attribute channel.
#include <gtest/gtest.h>

#include "GlTestSupport.h"

#include <cmath>

#include "TestSupport.h"
#include "core/Error.h"
#include "pipeline/FramePipeline.h"
#include "raycast/RaycastScenes.h"

namespace flipscope {
namespace {

TEST(ColorByAttributeGl, EqualsTheCpuReference) {
  testing::TempDir dir("color-gl");
  const testing::BallScene ball;
  const auto particles = testing::ballParticles(ball.centre, ball.radius);
  std::vector<glm::vec3> velocities;
  for (const auto& p : particles) velocities.emplace_back(0.0f, p.y / 16.0f, 1.0f);
  const BrickStore store = testing::makeStore(dir.path() / "store", {particles}, 96.0f, 32, {velocities});
  SurfaceSettings surface;
  surface.shading.colorByAttribute = true;
  surface.shading.colorMap = ColorMap::Magma;
  std::optional<FramePipeline> gpu;
  try {
    gpu.emplace(store, DeviceChoice::Gpu, ball.settings(), surface);
  } catch (const gl::Unavailable& e) {
    FLIPSCOPE_SKIP_WITHOUT_GL(e.what());
  }
  FramePipeline cpu(store, DeviceChoice::CpuReference, ball.settings(), surface);
  const FrameOutput a = gpu->render(0, ball.camera()), b = cpu.render(0, ball.camera());
  ASSERT_EQ(a.image.attribute.size(), b.image.attribute.size());
  int differentMask = 0, compared = 0;
  double colour = 0, attribute = 0;
  for (std::size_t i = 0; i < a.image.rgba.size(); ++i) {
    if (std::isfinite(a.image.depth[i]) != std::isfinite(b.image.depth[i])) {
      ++differentMask;
      continue;
    }
    colour = std::max(colour, double(glm::length(glm::vec3(a.image.rgba[i] - b.image.rgba[i]))));
    attribute = std::max(attribute, double(std::abs(a.image.attribute[i] - b.image.attribute[i])));
    compared += std::isfinite(a.image.depth[i]);
  }
  EXPECT_GT(compared, 500);
  EXPECT_LE(differentMask, 3);
  EXPECT_LT(colour, 0.05);
  EXPECT_LT(attribute, 1e-5);  // the same hit cells, the same 16-bit values
}

}  // namespace
}  // namespace flipscope
