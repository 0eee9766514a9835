// Properties particular to the `narrow-range` filter (Truong and Yuksel 2018) on the CPU
// reference: the clamped silhouette and rim, tilted planes as fixed points (bias correction), and
// small steps smoothed across. What every filter shares (fixed points, strength and iterations,
// untouched background, depth steps, approach to the analytic surface, registry entry):
// SurfaceFilterPropertiesTest.cpp.
#include <gtest/gtest.h>

#include <cmath>

#include "smoothing/SmoothingScenes.h"

namespace flipscope {
namespace {

using testing::DepthScene;
using testing::smoothOnCpu;

SmoothingOptions narrowRange(float strength = -1, int iterations = -1) {
  return testing::filterOptions("narrow-range", strength, iterations);
}

TEST(NarrowRangeFilter, SilhouetteIsPulledBackByAtMostMu) {
  // A constant disk on the background: the background counts as depth + mu (mu = one particle
  // radius), so the rim bends away from the eye by less than mu; the inside, further from the
  // rim than the kernel reaches, keeps its depth.
  const DepthScene s = testing::flatScene(
      64, 48, [](int, int) { return 1.0f; }, true);
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
    const DepthScene s = testing::flatScene(96, 72, ramp, false);
    EXPECT_LT(testing::worstChange(smoothOnCpu(s, narrowRange(16.0f)), s), 2e-5) << "slope " << slope;
  }
}

TEST(NarrowRangeFilter, SmallDepthStepIsSmoothedAcross) {
  // A step well inside the range (2 particle radii) is surface noise to the filter.
  const DepthScene s = testing::flatScene(
      96, 72, [](int x, int) { return x < 48 ? 3.0f : 3.04f; }, false);
  const auto out = smoothOnCpu(s, narrowRange(16.0f));
  for (int y = 8; y < 64; ++y) EXPECT_LT(out[y * 96 + 48].x - out[y * 96 + 47].x, 0.02f) << "row " << y;
}

TEST(NarrowRangeFilter, RimEndsAboutAParticleRadiusOffTheAnalyticDepth) {
  // A sphere 27 pixels in radius, particles of 0.7 pixel, on the background. Where it faces the
  // eye (unit normal z from 0.8) the filter approaches the analytic surface (SurfaceFilterProperties.
  // SmoothedSphereComesCloserToTheAnalyticDepth). In the band outside (the outer 5 pixels) the
  // analytic depth itself is aliased: single silhouette pixels that catch the limb lie up to 6
  // particle radii behind their inner neighbours, and the filter smooths those spikes away (it
  // takes them for surface detail: they are inside the depth range), so there the result ends
  // about one particle radius off the analytic depth (RMS).
  for (float roughnessRadii : {0.5f, 1.0f}) {
    const DepthScene s = testing::sphereScene(96, 72, roughnessRadii);
    const auto out = smoothOnCpu(s, narrowRange());
    EXPECT_LT(testing::rmsError(out, s, -1.0f, 0.8f), 1.5 * s.frame.particleRadius) << "roughness " << roughnessRadii;
  }
}

}  // namespace
}  // namespace flipscope
