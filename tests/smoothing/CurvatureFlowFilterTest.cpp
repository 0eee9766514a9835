// Properties of the `curvature-flow` filter (van der Laan, Green, Sainz 2009) on the CPU
// reference: fixed points, untouched background, smoothing towards the exact surface, more
// smoothing with more or larger steps, stability at the largest settings, preserved depth steps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "smoothing/SmoothingScenes.h"

namespace flipscope {
namespace {

using testing::DepthScene;
using testing::kBackgroundDepth;
using testing::smoothOnCpu;
using testing::sphereScene;
using testing::testFrame;

DepthScene flatScene(std::uint32_t w, std::uint32_t h, auto depthAt, bool disk) {
  DepthScene s;
  s.frame = testFrame(w, h);
  s.depth.assign(std::size_t(w) * h, glm::vec4(kBackgroundDepth, 0, 0, 0));
  for (int y = 0; y < int(h); ++y)
    for (int x = 0; x < int(w); ++x) {
      const float dx = x - w / 2.0f, dy = y - h / 2.0f;
      if (disk && dx * dx + dy * dy > 0.16f * h * h) continue;
      s.depth[std::size_t(y) * w + x] = glm::vec4(depthAt(x, y), 1, 0, 0);
    }
  return s;
}

SmoothingOptions flow(float strength = -1, int iterations = -1) { return {"curvature-flow", iterations, strength}; }

/// Mean |5-point Laplacian| of the depth's deviation from the exact depth (the noise, not the
/// sphere's own curvature) over the pixels of a continuous surface: whose four neighbours are
/// foreground with exact depths within 0.05 (2.5 particle radii) of theirs.
double roughness(const std::vector<glm::vec4>& d, const DepthScene& s) {
  const std::uint32_t w = s.frame.size.x, h = s.frame.size.y;
  double sum = 0;
  int count = 0;
  for (std::uint32_t y = 1; y + 1 < h; ++y)
    for (std::uint32_t x = 1; x + 1 < w; ++x) {
      const std::size_t i = y * w + x;
      bool continuous = s.depth[i].y > 0.5f;
      for (std::size_t j : {i - 1, i + 1, i - w, i + w})
        continuous = continuous && s.depth[j].y > 0.5f && std::abs(s.exactDepth[j] - s.exactDepth[i]) < 0.05f;
      if (!continuous) continue;
      auto e = [&](std::size_t j) { return double(d[j].x) - s.exactDepth[j]; };
      sum += std::abs(4 * e(i) - e(i - 1) - e(i + 1) - e(i - w) - e(i + w));
      ++count;
    }
  return sum / count;
}

/// RMS of depth - exact depth over the pixels where the exact surface faces the camera within
/// 60 degrees (near the rim, where view rays graze the sphere, a depth error is no surface error).
double errorToExact(const std::vector<glm::vec4>& d, const DepthScene& s) {
  double sum = 0;
  int count = 0;
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (s.depth[i].y < 0.5f || s.normals[i].z < 0.5f) continue;
    const double e = d[i].x - s.exactDepth[i];
    sum += e * e;
    ++count;
  }
  return std::sqrt(sum / count);
}

TEST(CurvatureFlowFilter, ConstantDepthIsAFixedPoint) {
  for (bool disk : {false, true}) {
    const DepthScene s = flatScene(64, 48, [](int, int) { return 5.0f; }, disk);
    for (float strength : {0.5f, 1.0f}) {
      const auto out = smoothOnCpu(s, flow(strength, 100));
      for (std::size_t i = 0; i < out.size(); ++i) {
        ASSERT_EQ(out[i].x, s.depth[i].x) << i;
        ASSERT_EQ(out[i].y, s.depth[i].y) << i;
      }
    }
  }
}

TEST(CurvatureFlowFilter, BackgroundPixelsAreNeverWritten) {
  const DepthScene s = sphereScene(96, 72, 1.0f);
  const auto out = smoothOnCpu(s, flow(1.0f, 200));
  int background = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    EXPECT_EQ(out[i].y, s.depth[i].y);
    if (s.depth[i].y < 0.5f) {
      ++background;
      ASSERT_EQ(out[i].x, kBackgroundDepth) << i;
    }
  }
  EXPECT_GT(background, 1000);
}

TEST(CurvatureFlowFilter, RoughSphereGetsSmootherAndCloserToTheExactDepth) {
  // 160 x 120: a sphere of about 90 pixels across, bumps of one particle radius (~1.1 pixels).
  const DepthScene s = sphereScene(160, 120, 1.0f);
  const auto out = smoothOnCpu(s, flow());
  const double before = roughness(s.depth, s), after = roughness(out, s);
  const double errorBefore = errorToExact(s.depth, s), errorAfter = errorToExact(out, s);
  EXPECT_LT(after, before * 0.3);
  EXPECT_LT(errorAfter, errorBefore * 0.7);
}

TEST(CurvatureFlowFilter, MoreStepsAndLargerStepsSmoothMore) {
  // A plane facing the camera at depth 3, roughened by one particle radius with features of
  // two pixels: the flow's fixed point is the plane itself, so the roughness keeps falling.
  DepthScene s = flatScene(96, 72, [](int x, int y) { return 3.0f - 0.02f * testing::bumps(x, y, 2.0f, 3); }, false);
  s.exactDepth.assign(s.depth.size(), 3.0f);
  double previous = roughness(s.depth, s);
  for (int iterations : {5, 20, 60, 200}) {
    const double r = roughness(smoothOnCpu(s, flow(0.5f, iterations)), s);
    EXPECT_LT(r, previous * 0.8) << iterations << " iterations";
    previous = r;
  }
  previous = roughness(s.depth, s);
  for (float strength : {0.1f, 0.3f, 0.6f, 1.0f}) {
    const double r = roughness(smoothOnCpu(s, flow(strength, 20)), s);
    EXPECT_LT(r, previous * 0.8) << "strength " << strength;
    previous = r;
  }
}

TEST(CurvatureFlowFilter, StableAtTheDefaultAndTheLargestSettings) {
  const SurfaceFilterInfo* info = nullptr;
  for (const SurfaceFilterInfo& i : surfaceFilters())
    if (i.name == "curvature-flow") info = &i;
  ASSERT_NE(info, nullptr);
  // A rough sphere in front of a rough plane: silhouettes, steep rims and pixel-sized noise.
  const DepthScene s = sphereScene(128, 72, 2.0f, 3.0f, 0.8f, 5.0f);
  float lo = std::numeric_limits<float>::max(), hi = 0;
  for (const glm::vec4& d : s.depth)
    if (d.y > 0.5f) lo = std::min(lo, d.x), hi = std::max(hi, d.x);
  const double rough = roughness(s.depth, s);
  for (const SmoothingOptions& options : {flow(), flow(info->maxStrength, info->maxIterations)}) {
    const auto out = smoothOnCpu(s, options);
    float outLo = std::numeric_limits<float>::max(), outHi = 0;
    for (std::size_t i = 0; i < out.size(); ++i) {
      ASSERT_TRUE(std::isfinite(out[i].x)) << i;
      if (s.depth[i].y < 0.5f) continue;
      outLo = std::min(outLo, out[i].x), outHi = std::max(outHi, out[i].x);
    }
    EXPECT_GE(outLo, lo - 0.01f) << options.iterations;
    EXPECT_LE(outHi, hi + 0.01f) << options.iterations;
    EXPECT_LT(roughness(out, s), rough * 0.5) << options.iterations;
  }
}

TEST(CurvatureFlowFilter, PixelNoiseOnASteepPlaneDecaysAtTheLargestStep) {
  // Independent noise of two particle radii per pixel (the mode an explicit step amplifies
  // first) on a plane whose depth rises by 0.02 per pixel, at the stability limit.
  DepthScene s = flatScene(
      64, 48, [](int x, int y) { return 3.0f + 0.02f * x + 0.04f * testing::bumps(x, y, 1.0f, 5); }, false);
  s.exactDepth.resize(s.depth.size());
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) s.exactDepth[y * 64 + x] = 3.0f + 0.02f * x;
  const double before = roughness(s.depth, s);
  double previous = before;
  for (int iterations : {1, 10, 100, 1000}) {
    const auto out = smoothOnCpu(s, flow(1.0f, iterations));
    for (const glm::vec4& d : out) ASSERT_TRUE(std::isfinite(d.x) && d.x > 2.9f && d.x < 4.4f) << iterations;
    const double r = roughness(out, s);
    // falls to the level of the flow's own deformation of the plane, and stays there
    EXPECT_LT(r, std::max(previous, before * 0.01)) << iterations << " iterations";
    previous = r;
  }
  EXPECT_LT(previous, before * 0.1);
}

TEST(CurvatureFlowFilter, DepthStepBetweenTwoSurfacesSurvives) {
  // Two noisy planes, at depth 3 (left) and 3.5 (right): 25 particle radii apart.
  DepthScene s = flatScene(96, 72, [](int x, int) { return x < 48 ? 3.0f : 3.5f; }, false);
  for (int y = 0; y < 72; ++y)
    for (int x = 0; x < 96; ++x) s.depth[y * 96 + x].x -= 0.02f * testing::bumps(x, y, 3.0f, 7);
  const auto out = smoothOnCpu(s, flow(1.0f, 200));
  for (int y = 0; y < 72; ++y) EXPECT_GT(out[y * 96 + 48].x - out[y * 96 + 47].x, 0.45f) << "row " << y;
}

TEST(CurvatureFlowFilter, OptionsDefaultsAndRanges) {
  const SmoothingOptions defaults = resolve({"curvature-flow"});
  EXPECT_EQ(defaults.iterations, 60);
  EXPECT_EQ(defaults.strength, 0.5f);
  EXPECT_NO_THROW(resolve(flow(1.0f, 1000)));
  EXPECT_THROW(resolve(flow(-1, 1001)), InputError);
  EXPECT_THROW(resolve(flow(1.5f)), InputError);
}

}  // namespace
}  // namespace flipscope
