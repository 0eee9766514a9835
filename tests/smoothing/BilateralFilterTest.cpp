// Properties of the `bilateral` filter (depth-adaptive bilateral Gaussian with a world-space
// kernel) on the CPU reference: fixed points, strength and iterations, untouched background,
// preserved depth steps, and a result closer to the analytic surface than its rough input.
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

SmoothingOptions bilateral(float strength = -1, int iterations = -1) { return {"bilateral", iterations, strength}; }

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

/// Root mean square distance of the depth to the scene's analytic depth on the foreground.
double rmsError(const std::vector<glm::vec4>& d, const DepthScene& s) {
  double sum = 0;
  int count = 0;
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (s.depth[i].y < 0.5f) continue;
    const double e = d[i].x - s.exactDepth[i];
    sum += e * e;
    ++count;
  }
  return std::sqrt(sum / count);
}

TEST(BilateralFilter, ConstantDepthIsAFixedPoint) {
  for (bool disk : {false, true}) {
    const DepthScene s = flatScene(64, 48, [](int, int) { return 5.0f; }, disk);
    for (int iterations : {1, 3}) {
      const auto out = smoothOnCpu(s, bilateral(8.0f, iterations));
      for (std::size_t i = 0; i < out.size(); ++i) ASSERT_NEAR(out[i].x, s.depth[i].x, 2e-6f) << i;
    }
  }
}

TEST(BilateralFilter, PlanarDepthIsAFixedPointAwayFromTheBoundary) {
  // A tilted plane's depth ramp: the kernel is symmetric wherever it lies inside the image.
  const DepthScene s = flatScene(96, 72, [](int x, int y) { return 2.0f + 0.002f * x + 0.001f * y; }, false);
  const auto out = smoothOnCpu(s, bilateral(8.0f));
  double worst = 0;
  for (int y = 24; y < 72 - 24; ++y)
    for (int x = 24; x < 96 - 24; ++x)
      worst = std::max(worst, double(std::abs(out[y * 96 + x].x - s.depth[y * 96 + x].x)));
  EXPECT_LT(worst, 1e-5);
}

TEST(BilateralFilter, LargerStrengthSmoothsMore) {
  const DepthScene s = sphereScene(96, 72, 1.0f);
  double previous = roughness(s.depth, 96, 72);
  for (float strength : {2.0f, 4.0f, 8.0f}) {
    const double r = roughness(smoothOnCpu(s, bilateral(strength)), 96, 72);
    EXPECT_LT(r, previous * 0.9) << "strength " << strength;
    previous = r;
  }
}

TEST(BilateralFilter, MoreIterationsSmoothMore) {
  const DepthScene s = sphereScene(96, 72, 1.0f);
  double previous = roughness(s.depth, 96, 72);
  for (int iterations : {1, 2, 4}) {
    const double r = roughness(smoothOnCpu(s, bilateral(-1, iterations)), 96, 72);
    EXPECT_LT(r, previous * 0.9) << iterations << " iterations";
    previous = r;
  }
}

TEST(BilateralFilter, ZeroStrengthOrIterationsLeaveTheDepth) {
  const DepthScene s = sphereScene(96, 72, 1.0f);
  for (const SmoothingOptions& options : {bilateral(0.0f), bilateral(-1, 0)}) {
    const auto out = smoothOnCpu(s, options);
    for (std::size_t i = 0; i < out.size(); ++i) ASSERT_EQ(out[i].x, s.depth[i].x) << i;
  }
}

TEST(BilateralFilter, BackgroundPixelsAreNeverWritten) {
  const DepthScene s = sphereScene(96, 72, 1.0f);
  const auto out = smoothOnCpu(s, bilateral(8.0f, 3));
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

TEST(BilateralFilter, DepthStepBetweenTwoSurfacesSurvives) {
  // Two noisy planes, at depth 3 (left) and 3.5 (right): 25 particle radii apart, far outside
  // the range Gaussian (sigma 2 radii).
  const DepthScene base = flatScene(96, 72, [](int x, int) { return x < 48 ? 3.0f : 3.5f; }, false);
  DepthScene s = base;
  for (int y = 0; y < 72; ++y)
    for (int x = 0; x < 96; ++x) s.depth[y * 96 + x].x -= 0.02f * testing::bumps(x, y, 3.0f, 7);
  const auto out = smoothOnCpu(s, bilateral(8.0f, 3));
  for (int y = 8; y < 64; ++y) {
    const float left = out[y * 96 + 47].x, right = out[y * 96 + 48].x;
    EXPECT_GT(right - left, 0.45f) << "row " << y;
    EXPECT_NEAR(left, 3.0f, 0.02f) << "row " << y;
    EXPECT_NEAR(right, 3.5f, 0.02f) << "row " << y;
  }
}

TEST(BilateralFilter, ResultIsCloserToTheAnalyticSurface) {
  for (float roughnessRadii : {0.5f, 1.0f}) {
    const DepthScene s = sphereScene(96, 72, roughnessRadii, 3.0f, 0.8f, 5.0f);
    const double before = rmsError(s.depth, s);
    const double after = rmsError(smoothOnCpu(s, bilateral()), s);
    EXPECT_LT(after, before * 0.7) << "roughness " << roughnessRadii;
  }
}

TEST(BilateralFilter, RegistryDefaultsAndRanges) {
  const SmoothingOptions defaults = resolve({"bilateral"});
  EXPECT_EQ(defaults.iterations, 1);
  EXPECT_EQ(defaults.strength, 4.0f);
  EXPECT_NO_THROW(resolve({"bilateral", 10}));
  EXPECT_THROW(resolve({"bilateral", 11}), InputError);
  EXPECT_THROW(resolve({"bilateral", -1, 17.0f}), InputError);
}

}  // namespace
}  // namespace flipscope
