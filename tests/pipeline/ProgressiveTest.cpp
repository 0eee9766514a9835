// Progressive frames for the viewer (FramePipeline::begin/advance, FrameRenderer::advance): a
// slice never waits for brick conversion, rays still waiting for bricks keep the image shown
// before, and a frame advanced to the end is the frame render() gives.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "ProgressiveScenes.h"
#include "core/Elapsed.h"
#include "core/Error.h"
#include "pipeline/ImageWriter.h"
#include "raycast/CpuRaycaster.h"

namespace flipscope {
namespace {

using testing::GatedBrickSource;

FramePipeline cpuPipeline(std::shared_ptr<BrickSource> source) {
  return FramePipeline(std::move(source), std::make_unique<CpuRaycaster>(), GatedBrickSource::settings(),
                       SurfaceSettings{});
}

std::span<const RayHit> hitsOf(FramePipeline& pipeline) {
  return static_cast<CpuRaycaster&>(pipeline.renderer().device()).hits();
}

TEST(ProgressiveFrames, AdvancedToTheEndEqualsRender) {
  auto source = std::make_shared<GatedBrickSource>();
  FramePipeline reference = cpuPipeline(source);
  const FrameOutput expected = reference.render(1, GatedBrickSource::camera());
  ASSERT_TRUE(expected.stats.converged);
  ASSERT_GT(expected.stats.bricksUploaded, 0u) << "a cold frame needs bricks streamed in";

  FramePipeline progressive = cpuPipeline(source);
  progressive.begin(1, GatedBrickSource::camera());
  EXPECT_GT(testing::advanceToEnd(progressive), 0);
  ASSERT_TRUE(progressive.finished());
  const FrameOutput out = progressive.readOutput();
  ASSERT_EQ(out.image.rgba.size(), expected.image.rgba.size());
  for (std::size_t i = 0; i < out.image.rgba.size(); ++i) {
    ASSERT_EQ(out.image.rgba[i], expected.image.rgba[i]) << "pixel " << i;
    ASSERT_EQ(out.image.depth[i], expected.image.depth[i]) << "pixel " << i;
  }
  // The display is the shaded image, sRGB-encoded as the PNG writer encodes it.
  const std::vector<glm::vec4> display = progressive.downloadDisplay();
  ASSERT_EQ(display.size(), out.image.rgba.size());
  int hits = 0;
  for (std::size_t i = 0; i < display.size(); ++i) {
    const glm::vec4 c = out.image.rgba[i];
    for (int k = 0; k < 3; ++k)
      ASSERT_NEAR(display[i][k] * 255.0f, float(linearToSrgb8(c[k] / c.a)), 0.51f) << "pixel " << i;
    EXPECT_EQ(display[i].a, 1.0f);
    hits += std::isfinite(out.image.depth[i]);
  }
  EXPECT_GT(hits, int(display.size()) / 4) << "the camera sees the water";
}

TEST(ProgressiveFrames, AdvanceNeverWaitsForConversion) {
  auto source = std::make_shared<GatedBrickSource>();
  FramePipeline pipeline = cpuPipeline(source);
  source->setOpen(false);  // every brick read now blocks a Streamer worker
  pipeline.begin(0, GatedBrickSource::camera());
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 5; ++i) {
    const FramePipeline::Progress p = pipeline.advance(1.0);
    EXPECT_EQ(p.changed, i == 0) << "only the first slice has anything to trace";
    EXPECT_EQ(p.stats.passes, 1);
    EXPECT_FALSE(pipeline.finished());
  }
  const double ms = msSince(start);
  EXPECT_LT(ms, 20000.0) << "(a slice that waited would never return: the gate is closed)";
  int pending = 0;
  for (const RayHit& hit : hitsOf(pipeline)) pending += hit.status == kRayPending;
  EXPECT_GT(pending, 0);
  source->setOpen(true);
  testing::advanceToEnd(pipeline);
  EXPECT_TRUE(pipeline.finished());
  EXPECT_TRUE(pipeline.advance(1.0).stats.converged);
  for (const RayHit& hit : hitsOf(pipeline)) ASSERT_NE(hit.status, kRayPending);
}

TEST(ProgressiveFrames, PendingRaysKeepThePreviousImage) {
  auto source = std::make_shared<GatedBrickSource>();
  FramePipeline pipeline = cpuPipeline(source);
  const Camera camera = GatedBrickSource::camera();
  pipeline.begin(0, camera);
  testing::advanceToEnd(pipeline);
  const std::vector<glm::vec4> before = pipeline.downloadDisplay();

  source->setOpen(false);  // frame 2's bricks cannot arrive
  pipeline.begin(2, camera);
  const FramePipeline::Progress p = pipeline.advance(1.0);
  ASSERT_TRUE(p.changed);
  const std::vector<glm::vec4> after = pipeline.downloadDisplay();
  const std::span<const RayHit> hits = hitsOf(pipeline);
  int pending = 0, finished = 0;
  for (std::size_t i = 0; i < hits.size(); ++i) {
    if (hits[i].status == kRayPending) {
      ++pending;
      ASSERT_EQ(after[i], before[i]) << "pending pixel " << i << " changed";
    } else {
      ++finished;
    }
  }
  EXPECT_GT(pending, 0);
  EXPECT_GT(finished, 0) << "rays that miss the tank finish at once";
  source->setOpen(true);
  testing::advanceToEnd(pipeline);
  EXPECT_NE(pipeline.downloadDisplay(), before) << "frame 2 moved the water";
}

TEST(ProgressiveFrames, AdvanceBeforeBeginIsALogicError) {
  auto source = std::make_shared<GatedBrickSource>();
  FramePipeline pipeline = cpuPipeline(source);
  EXPECT_THROW(pipeline.advance(1.0), LogicError);
  EXPECT_THROW(pipeline.begin(7, GatedBrickSource::camera()), InputError);
}

}  // namespace
}  // namespace flipscope
