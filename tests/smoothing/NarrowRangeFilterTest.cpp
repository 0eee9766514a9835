// Properties of the `narrow-range` filter (Truong and Yuksel 2018) on the CPU reference: fixed
// points (bias correction keeps planes exact), strength and iterations, untouched background,
// the clamped silhouette, preserved depth steps, and a result closer to the analytic surface than
// its rough input.
#include <gtest/gtest.h>

#include <cmath>

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
  s.exactDepth.assign(std::size_t(w) * h, kBackgroundDepth);
  for (int y = 0; y < int(h); ++y)
    for (int x = 0; x < int(w); ++x) {
      const float dx = x - w / 2.0f, dy = y - h / 2.0f;
      if (disk && dx * dx + dy * dy > 0.16f * h * h) continue;
      s.depth[std::size_t(y) * w + x] = glm::vec4(depthAt(x, y), 1, 0, 0);
      s.exactDepth[std::size_t(y) * w + x] = depthAt(x, y);
    }
  return s;
}

SmoothingOptions narrowRange(float strength = -1, int iterations = -1) {
  return {"narrow-range", iterations, strength};
}

/// Mean absolute discrete Laplacian of the depth over pixels whose 4-neighbourhood is foreground.
double roughness(const std::vector<glm::vec4>& d, std::uint32_t w, std::uint32_t h) {
  double sum = 0;
  int count = 0;
  for (std::uint32_t y = 1; y + 1 < h; ++y)
    for (std::uint32_t x = 1; x + 1 < w; ++x) {
      const std::size_t i = y * w + x;
      if (d[i].y < 0.5f || d[i - 1].y < 0.5f || d[i + 1].y < 0.5f || d[i - w].y < 0.5f || d[i + w].y < 0.5f) continue;
      sum += std::abs(4 * d[i].x - d[i - 1].x - d[i + 1].x - d[i - w].x - d[i + w].x);
      ++count;
    }
  return sum / count;
}

/// Root mean square distance of the depth to the scene's analytic depth on the foreground where
/// the z of the analytic unit normal lies in (minFacing, maxFacing].
double rmsError(const std::vector<glm::vec4>& d, const DepthScene& s, float minFacing, float maxFacing) {
  double sum = 0;
  int count = 0;
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (s.depth[i].y < 0.5f || s.normals[i].z <= minFacing || s.normals[i].z > maxFacing) continue;
    const double e = d[i].x - s.exactDepth[i];
    sum += e * e;
    ++count;
  }
  return std::sqrt(sum / count);
}

TEST(NarrowRangeFilter, ConstantDepthIsAFixedPoint) {
  const DepthScene s = flatScene(64, 48, [](int, int) { return 5.0f; }, false);
  for (int iterations : {1, 4}) {
    const auto out = smoothOnCpu(s, narrowRange(8.0f, iterations));
    for (std::size_t i = 0; i < out.size(); ++i) ASSERT_NEAR(out[i].x, s.depth[i].x, 2e-6f) << i;
  }
}

TEST(NarrowRangeFilter, SilhouetteIsPulledBackByAtMostMu) {
  // A constant disk on the background: the background counts as depth + mu (mu = one particle
  // radius), so the rim bends away from the eye by less than mu; the inside, further from the
  // rim than the kernel reaches, keeps its depth.
  const DepthScene s = flatScene(64, 48, [](int, int) { return 1.0f; }, true);
  const float mu = s.frame.particleRadius;
  const auto out = smoothOnCpu(s, narrowRange(4.0f, 1));  // one 2D pass of radius <= 4 pixels
  bool rimMoved = false;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) {
      const std::size_t i = std::size_t(y) * 64 + x;
      if (s.depth[i].y < 0.5f) continue;
      ASSERT_GE(out[i].x, 1.0f - 1e-6f) << x << ", " << y;
      ASSERT_LT(out[i].x, 1.0f + mu) << x << ", " << y;
      const float dx = x - 32.0f, dy = y - 24.0f;
      if (std::sqrt(dx * dx + dy * dy) < 0.4f * 48 - 6) {
        ASSERT_NEAR(out[i].x, 1.0f, 2e-6f) << x << ", " << y;
      }
      rimMoved = rimMoved || out[i].x > 1.0f + 0.1f * mu;
    }
  EXPECT_TRUE(rimMoved);
}

TEST(NarrowRangeFilter, TiltedPlanesAreFixedPoints) {
  // Bias correction keeps the kernel symmetric (a sample ignored ignores its mirror image too,
  // also at the image border), so a depth ramp stays exact, gentle or steep enough to leave the
  // initial depth range within the kernel.
  for (float slope : {0.002f, 0.05f}) {
    const auto ramp = [slope](int x, int y) { return 2.0f + slope * x + 0.5f * slope * y; };
    const DepthScene s = flatScene(96, 72, ramp, false);
    const auto out = smoothOnCpu(s, narrowRange(16.0f));
    double worst = 0;
    for (std::size_t i = 0; i < out.size(); ++i) worst = std::max(worst, double(std::abs(out[i].x - s.depth[i].x)));
    EXPECT_LT(worst, 2e-5) << "slope " << slope;
  }
}

TEST(NarrowRangeFilter, LargerStrengthSmoothsMore) {
  const DepthScene s = sphereScene(96, 72, 1.0f);
  double previous = roughness(s.depth, 96, 72);
  for (float strength : {3.0f, 6.0f, 12.0f}) {
    const double r = roughness(smoothOnCpu(s, narrowRange(strength)), 96, 72);
    EXPECT_LT(r, previous * 0.9) << "strength " << strength;
    previous = r;
  }
}

TEST(NarrowRangeFilter, MoreIterationsSmoothMore) {
  const DepthScene s = sphereScene(96, 72, 1.0f);
  double previous = roughness(s.depth, 96, 72);
  for (int iterations : {1, 2, 4, 8}) {
    const double r = roughness(smoothOnCpu(s, narrowRange(-1, iterations)), 96, 72);
    EXPECT_LT(r, previous * 0.95) << iterations << " iterations";
    previous = r;
  }
}

TEST(NarrowRangeFilter, ZeroStrengthOrIterationsLeaveTheDepth) {
  const DepthScene s = sphereScene(96, 72, 1.0f);
  for (const SmoothingOptions& options : {narrowRange(0.0f), narrowRange(-1, 0)}) {
    const auto out = smoothOnCpu(s, options);
    for (std::size_t i = 0; i < out.size(); ++i) ASSERT_EQ(out[i].x, s.depth[i].x) << i;
  }
}

TEST(NarrowRangeFilter, BackgroundPixelsAreNeverWritten) {
  const DepthScene s = sphereScene(96, 72, 1.0f);
  const auto out = smoothOnCpu(s, narrowRange(8.0f, 6));
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

TEST(NarrowRangeFilter, DepthStepBetweenTwoSurfacesSurvives) {
  // Two noisy planes, at depth 3 (left) and 3.5 (right): 25 particle radii apart, beyond the
  // range (delta = 10.5 radii). The rear plane ignores the front one entirely; the front plane
  // counts the rear one as its own depth + mu, so its edge bends back a little at the step.
  const DepthScene base = flatScene(96, 72, [](int x, int) { return x < 48 ? 3.0f : 3.5f; }, false);
  DepthScene s = base;
  for (int y = 0; y < 72; ++y)
    for (int x = 0; x < 96; ++x) s.depth[y * 96 + x].x -= 0.02f * testing::bumps(x, y, 3.0f, 7);
  const float mu = s.frame.particleRadius;
  for (const SmoothingOptions& options : {narrowRange(), narrowRange(16.0f, 8)}) {
    const auto out = smoothOnCpu(s, options);
    for (int y = 8; y < 64; ++y) {
      const float left = out[y * 96 + 47].x, right = out[y * 96 + 48].x;
      EXPECT_GT(right - left, 0.45f) << "row " << y;
      // Every pass moves the front edge back by a part of mu: a few mu after 8 iterations.
      EXPECT_GT(left, 3.0f - 0.02f) << "row " << y;
      EXPECT_LT(left, 3.0f + 0.02f + 3 * mu) << "row " << y;
      EXPECT_NEAR(right, 3.5f, 0.02f) << "row " << y;
    }
  }
}

TEST(NarrowRangeFilter, SmallDepthStepIsSmoothedAcross) {
  // A step well inside the range (2 particle radii) is surface noise to the filter.
  const DepthScene s = flatScene(96, 72, [](int x, int) { return x < 48 ? 3.0f : 3.04f; }, false);
  const auto out = smoothOnCpu(s, narrowRange(16.0f));
  for (int y = 8; y < 64; ++y) EXPECT_LT(out[y * 96 + 48].x - out[y * 96 + 47].x, 0.02f) << "row " << y;
}

TEST(NarrowRangeFilter, ResultIsCloserToTheAnalyticSurfaceWhereItFacesTheEye) {
  // A sphere 27 pixels in radius, particles of 0.7 pixel, on the background. Where it faces the
  // eye (unit normal z above 0.8) the filter must approach the analytic surface. In the band
  // outside (the outer 5 pixels) the analytic depth itself is aliased: single silhouette pixels
  // that catch the limb lie up to 6 particle radii behind their inner neighbours, and the filter
  // smooths those spikes away (it takes them for surface detail: they are inside the depth
  // range), so there the result ends about one particle radius off the analytic depth (RMS).
  const float r = 0.02f;
  for (float roughnessRadii : {0.5f, 1.0f}) {
    const DepthScene s = sphereScene(96, 72, roughnessRadii);
    const auto out = smoothOnCpu(s, narrowRange());
    const double before = rmsError(s.depth, s, 0.8f, 2.0f), after = rmsError(out, s, 0.8f, 2.0f);
    EXPECT_LT(after, before * 0.7) << "roughness " << roughnessRadii;
    EXPECT_LT(rmsError(out, s, -1.0f, 0.8f), 1.5 * r) << "roughness " << roughnessRadii;
  }
}

TEST(NarrowRangeFilter, RegistryDefaultsAndRanges) {
  const SmoothingOptions defaults = resolve({"narrow-range"});
  EXPECT_EQ(defaults.iterations, 4);
  EXPECT_EQ(defaults.strength, 3.0f);
  EXPECT_NO_THROW(resolve({"narrow-range", 20}));
  EXPECT_THROW(resolve({"narrow-range", 21}), InputError);
  EXPECT_THROW(resolve({"narrow-range", -1, 17.0f}), InputError);
}

}  // namespace
}  // namespace flipscope
