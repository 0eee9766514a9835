// The frame pipeline on the CPU reference: a ball of particles through ray-casting, smoothing,
// normals and shading.
#include <gtest/gtest.h>

#include <cmath>

#include "TestSupport.h"
#include "core/Error.h"
#include "pipeline/FramePipeline.h"
#include "raycast/RaycastScenes.h"

namespace flipscope {
namespace {

FrameOutput renderBall(const std::string& smoothing, ShadingMode mode = ShadingMode::Liquid) {
  testing::TempDir dir("pipeline");
  const testing::BallScene ball;
  SurfaceSettings surface;
  surface.smoothing.name = smoothing;
  surface.shading.mode = mode;
  FramePipeline pipeline(ball.makeStore(dir.path() / "store"), DeviceChoice::Cpu, ball.settings(), surface);
  return pipeline.render(0, ball.camera());
}

TEST(FramePipeline, BallGivesDepthThicknessAndNormalsOnTheDisk) {
  const testing::BallScene ball;
  const FrameOutput out = renderBall("rof");
  const RenderImage& image = out.image;
  ASSERT_EQ(image.width, 128u);
  ASSERT_EQ(image.depth.size(), 128u * 72u);
  const Camera camera = ball.camera();
  int disk = 0, thick = 0;
  for (std::uint32_t y = 0; y < image.height; ++y)
    for (std::uint32_t x = 0; x < image.width; ++x) {
      const std::size_t i = y * image.width + x;
      EXPECT_EQ(image.rgba[i].a, 1.0f);
      if (!std::isfinite(image.depth[i])) {
        EXPECT_EQ(image.thickness[i], 0.0f);
        EXPECT_FALSE(std::isfinite(image.unsmoothedDepth[i]));
        continue;
      }
      ++disk;
      EXPECT_TRUE(std::isfinite(image.unsmoothedDepth[i]));
      const glm::dvec3 ray = camera.pixelRay(x, y, image.width, image.height);
      EXPECT_LT(glm::dot(glm::dvec3(image.normal[i]), ray), 0.0) << "normal faces the camera at " << x << "," << y;
      // The thickness march samples kThicknessCells cells behind the hit; the ball is full (rays
      // that graze the silhouette may meet no set cell).
      thick += image.thickness[i] > 0.0f;
      EXPECT_GE(image.thickness[i], 0.0f);
      EXPECT_LE(image.thickness[i], float(kThicknessCells) + 1e-3f);
    }
  EXPECT_GT(disk, 500);
  EXPECT_GT(thick, disk * 9 / 10);
  // At the disk's centre the ray crosses 52 cells of ball: the march saturates (48 cells, ~all set).
  const std::size_t centre = 36 * 128 + 64;
  EXPECT_GT(image.thickness[centre], 40.0f);
  // The centre's normal points back at the camera (+z).
  EXPECT_GT(image.normal[centre].z, 0.95f);
}

TEST(FramePipeline, SmoothingChangesTheDepthButNotTheMask) {
  const FrameOutput none = renderBall("none");
  const FrameOutput rof = renderBall("rof");
  double changed = 0;
  for (std::size_t i = 0; i < none.image.depth.size(); ++i) {
    ASSERT_EQ(std::isfinite(none.image.depth[i]), std::isfinite(rof.image.depth[i])) << i;
    if (!std::isfinite(none.image.depth[i])) continue;
    EXPECT_EQ(none.image.depth[i], none.image.unsmoothedDepth[i]);
    EXPECT_EQ(rof.image.unsmoothedDepth[i], none.image.unsmoothedDepth[i]);
    changed = std::max(changed, double(std::abs(rof.image.depth[i] - none.image.depth[i])));
  }
  EXPECT_GT(changed, 1e-3);
}

TEST(FramePipeline, ShadingModesGiveDifferentLooks) {
  const FrameOutput liquid = renderBall("rof", ShadingMode::Liquid);
  const FrameOutput spheres = renderBall("rof", ShadingMode::Spheres);
  const std::size_t centre = 36 * 128 + 64, corner = 0;
  EXPECT_GT(glm::length(glm::vec3(liquid.image.rgba[centre] - spheres.image.rgba[centre])), 0.02f);
  // The background is the environment, the same in both.
  EXPECT_EQ(liquid.image.rgba[corner], spheres.image.rgba[corner]);
}

TEST(FramePipeline, EnvironmentMapErrorsNameTheFile) {
  testing::TempDir dir("pipeline");
  const testing::BallScene ball;
  SurfaceSettings surface;
  surface.environment = dir.path() / "missing.exr";
  try {
    FramePipeline pipeline(ball.makeStore(dir.path() / "store"), DeviceChoice::Cpu, ball.settings(), surface);
    FAIL();
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.exr"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace flipscope
