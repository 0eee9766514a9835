// --env: an equirectangular EXR environment replaces the procedural sky, behind the liquid and
// in its reflection and refraction.
#include <gtest/gtest.h>

#include <cmath>

#include "TestSupport.h"
#include "pipeline/FramePipeline.h"
#include "raycast/RaycastScenes.h"

namespace flipscope {
namespace {

/// An environment of one colour above the horizon (the top half, the up direction) and another
/// below it.
std::filesystem::path writeEnvironment(const std::filesystem::path& path, glm::vec3 sky, glm::vec3 ground) {
  RenderImage image;
  image.width = 16;
  image.height = 8;
  for (std::uint32_t y = 0; y < image.height; ++y)
    for (std::uint32_t x = 0; x < image.width; ++x) image.rgba.push_back(glm::vec4(y < 4 ? sky : ground, 1));
  writeExr(path, image);
  return path;
}

TEST(Environment, MapIsTheBackgroundAndTintsTheLiquid) {
  testing::TempDir dir("environment");
  const testing::BallScene ball;
  const BrickStore store = ball.makeStore(dir.path() / "store");
  SurfaceSettings red;
  red.environment = writeEnvironment(dir.path() / "red.exr", {1, 0, 0}, {0.5f, 0, 0});
  SurfaceSettings green = red;
  green.environment = writeEnvironment(dir.path() / "green.exr", {0, 1, 0}, {0, 0.5f, 0});
  // The ball seen from +z, up +y: the background is the horizon's colours.
  const FrameOutput a = FramePipeline(store, DeviceChoice::Cpu, ball.settings(), red).render(0, ball.camera());
  const FrameOutput b = FramePipeline(store, DeviceChoice::Cpu, ball.settings(), green).render(0, ball.camera());
  const std::size_t corner = 0, centre = 36 * 128 + 64;
  ASSERT_FALSE(std::isfinite(a.image.depth[corner]));
  EXPECT_GT(a.image.rgba[corner].r, 0.45f);
  EXPECT_EQ(a.image.rgba[corner].g, 0.0f);
  EXPECT_EQ(b.image.rgba[corner].r, 0.0f);
  EXPECT_GT(b.image.rgba[corner].g, 0.45f);
  // The liquid reflects and transmits the environment: red in one, green in the other.
  ASSERT_TRUE(std::isfinite(a.image.depth[centre]));
  EXPECT_GT(a.image.rgba[centre].r - b.image.rgba[centre].r, 0.01f);
  EXPECT_GT(b.image.rgba[centre].g - a.image.rgba[centre].g, 0.01f);
}

}  // namespace
}  // namespace flipscope
