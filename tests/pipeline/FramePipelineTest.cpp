// The frame pipeline on the CPU reference: a ball of particles through ray-casting, smoothing,
// normals and shading.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "OutputLayerChecks.h"
#include "TestSupport.h"
#include "core/Error.h"
#include "pipeline/FramePipeline.h"
#include "raycast/RaycastScenes.h"
#include "streaming/SyntheticBrickSource.h"

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
      // The thickness trace sums the cells' density behind the hit until absorption saturates;
      // the ball is full (rays that graze the silhouette may meet no set cell).
      thick += image.thickness[i] > 0.0f;
      EXPECT_GE(image.thickness[i], 0.0f);
      EXPECT_LE(image.thickness[i], thicknessSaturationCells(ShadingOptions{}) + 1.0f);
    }
  EXPECT_GT(disk, 500);
  EXPECT_GT(thick, disk * 9 / 10);
  // At the disk's centre the ray crosses 52 cells of ball, all set (4^3 blocks at its surface are
  // partly outside it); saturation is at 77 cells.
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

TEST(FramePipeline, TheOutputReadsTheSameAgainAndAfterTheNextFrame) {
  // On the CPU the shaded pixels move into the output (no copy): reading it again, rendering
  // again and rendering progressively must all give the same image.
  testing::TempDir dir("pipeline");
  const testing::BallScene ball;
  FramePipeline pipeline(ball.makeStore(dir.path() / "store"), DeviceChoice::Cpu, ball.settings(), SurfaceSettings{});
  const std::vector<glm::vec4> first = pipeline.render(0, ball.camera()).image.rgba;
  ASSERT_FALSE(first.empty());
  EXPECT_GT(std::count_if(first.begin(), first.end(), [](const glm::vec4& c) { return c.a == 1.0f && c.r > 0; }), 1000);
  EXPECT_EQ(pipeline.readOutput().image.rgba, first);
  EXPECT_EQ(pipeline.readOutput().image.rgba, first);
  Camera farther = ball.camera();
  farther.eye = farther.target + (farther.eye - farther.target) * 1.5;
  const std::vector<glm::vec4> second = pipeline.render(0, farther).image.rgba;
  EXPECT_NE(second, first);
  EXPECT_EQ(pipeline.readOutput().image.rgba, second);
  EXPECT_EQ(pipeline.render(0, ball.camera()).image.rgba, first);
  pipeline.begin(0, ball.camera());
  for (int i = 0; i < 100 && !pipeline.finished(); ++i) pipeline.advance(1000.0);
  ASSERT_TRUE(pipeline.finished());
  EXPECT_EQ(pipeline.readOutput().image.rgba, first);
  EXPECT_EQ(pipeline.readOutput().image.rgba, first);
}

TEST(FramePipeline, TheColourAloneIsTheColourOfAllLayersAndLeavesTheOthersEmpty) {
  testing::expectTheColourAloneIsTheColourOfAllLayers(DeviceChoice::Cpu);
}

TEST(FramePipeline, ShadingModesGiveDifferentLooks) {
  const FrameOutput liquid = renderBall("rof", ShadingMode::Liquid);
  const FrameOutput spheres = renderBall("rof", ShadingMode::Spheres);
  const std::size_t centre = 36 * 128 + 64, corner = 0;
  EXPECT_GT(glm::length(glm::vec3(liquid.image.rgba[centre] - spheres.image.rgba[centre])), 0.02f);
  // The background is the environment, the same in both.
  EXPECT_EQ(liquid.image.rgba[corner], spheres.image.rgba[corner]);
}

TEST(FramePipeline, OnlyTheLiquidShadingTracesTheThicknessAndSpheresKeepTheirNormals) {
  const FrameOutput liquid = renderBall("none", ShadingMode::Liquid);
  ASSERT_EQ(liquid.image.thickness.size(), liquid.image.depth.size());
  for (ShadingMode mode : {ShadingMode::Spheres, ShadingMode::Normals})
    EXPECT_TRUE(renderBall("none", mode).image.thickness.empty()) << int(mode);
  // The spheres shading's normals are the spheres' (unit, facing the camera), not the
  // reconstructed surface's: they differ from the liquid's at most pixels of the ball.
  const FrameOutput spheres = renderBall("none", ShadingMode::Spheres);
  const Camera camera = testing::BallScene().camera();
  int hits = 0, differ = 0;
  for (std::size_t i = 0; i < spheres.image.depth.size(); ++i) {
    if (!std::isfinite(spheres.image.depth[i])) continue;
    ++hits;
    const glm::vec3 n = spheres.image.normal[i];
    EXPECT_NEAR(glm::length(n), 1.0f, 1e-4f) << i;
    const glm::dvec3 ray = camera.pixelRay(std::uint32_t(i % 128), std::uint32_t(i / 128), 128, 72);
    EXPECT_LT(glm::dot(glm::dvec3(n), ray), 0.0) << i;
    differ += glm::length(n - liquid.image.normal[i]) > 1e-3f;
  }
  EXPECT_GT(hits, 500);
  EXPECT_GT(differ, hits / 2);
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

TEST(FramePipeline, RendersASyntheticSourceWithoutAStore) {
  // The wave tank (128 x 128 cells, 64 high, water 16..42 cells deep) seen straight down from
  // above its centre: the water is a square in the middle of the image, the sky on either side.
  auto source = std::make_shared<SyntheticBrickSource>(32, glm::uvec3(4, 4, 2), 1, 0.3);
  const StoreHeader& h = source->header();
  const double cell = h.cellSize;
  const glm::dvec3 lo = h.origin, hi = h.domainMax();
  SurfaceSettings surface;
  surface.up = {0, 0, 1};
  RenderSettings settings = testing::smallSettings();
  // Cells are set with probability 0.3 and the spheres have radius 1: at that density the
  // classification takes many cells for foam, and this test is about the surface.
  settings.foam.mode = FoamMode::Keep;
  FramePipeline pipeline(source, DeviceChoice::Cpu, settings, surface);
  Camera camera;
  camera.target = glm::dvec3(0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), 0);
  camera.eye = camera.target + glm::dvec3(0, 0, 3.0);
  camera.up = {0, 1, 0};
  const FrameOutput out = pipeline.render(0, camera);
  ASSERT_TRUE(out.stats.converged);
  const RenderImage& image = out.image;
  ASSERT_EQ(image.depth.size(), std::size_t(settings.width) * settings.height);

  // Slab test: does the ray from the eye along `dir` cross the box [a, b]?
  const auto crosses = [&](glm::dvec3 dir, glm::dvec3 a, glm::dvec3 b) {
    double near = 0, far = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      if (dir[k] == 0) {
        if (camera.eye[k] < a[k] || camera.eye[k] > b[k]) return false;
        continue;
      }
      double t0 = (a[k] - camera.eye[k]) / dir[k], t1 = (b[k] - camera.eye[k]) / dir[k];
      if (t0 > t1) std::swap(t0, t1);
      near = std::max(near, t0);
      far = std::min(far, t1);
    }
    return near <= far;
  };
  const glm::dvec3 margin(4 * cell);
  int water = 0, inner = 0;
  for (std::uint32_t y = 0; y < image.height; ++y)
    for (std::uint32_t x = 0; x < image.width; ++x) {
      const std::size_t i = y * image.width + x;
      const glm::dvec3 dir = camera.pixelRay(x, y, image.width, image.height);
      const bool foreground = std::isfinite(image.depth[i]);
      water += foreground;
      // Where the water lies at least 14 cells deep along the ray (it is 16 cells deep or more
      // everywhere), every ray meets a particle's sphere.
      const glm::dvec3 at = camera.eye + dir * ((2 * cell - camera.eye.z) / dir.z);  // 2 cells above the floor
      if (at.x > lo.x + margin.x && at.x < hi.x - margin.x && at.y > lo.y + margin.y && at.y < hi.y - margin.y) {
        ++inner;
        EXPECT_TRUE(foreground) << "pixel " << x << "," << y << " over the water";
      }
      // A ray that misses the tank (grown by a few cells) sees the sky.
      if (!crosses(dir, lo - margin, hi + margin)) {
        EXPECT_FALSE(foreground) << "pixel " << x << "," << y << " beside the tank";
      }
      if (!foreground) {
        EXPECT_FALSE(std::isfinite(image.unsmoothedDepth[i])) << x << "," << y;
        continue;
      }
      EXPECT_TRUE(std::isfinite(image.unsmoothedDepth[i])) << x << "," << y;
      EXPECT_TRUE(std::isfinite(image.normal[i].x) && std::isfinite(image.normal[i].y) &&
                  std::isfinite(image.normal[i].z))
          << x << "," << y;
      // The hit lies on the analytic surface: below its wave crest plus a sphere (and jitter),
      // and not far under it.
      const glm::dvec3 hit = camera.eye + dir * (double(image.unsmoothedDepth[i]) / glm::dot(dir, camera.forward()));
      const glm::dvec3 hitCell = (hit - h.origin) / cell;
      const double height = source->surfaceHeight(0, std::floor(hitCell.x), std::floor(hitCell.y));
      EXPECT_LE(hitCell.z, height + 3.0) << x << "," << y;
      EXPECT_GE(hitCell.z, height - 16.0) << x << "," << y;
    }
  EXPECT_GT(inner, 1500);
  EXPECT_GE(water, inner);
  EXPECT_LT(water, int(image.width * image.height) / 2);
}

}  // namespace
}  // namespace flipscope
