// Properties of the `rof` filter (Reichl et al. 2014 §3.4) on the CPU reference: fixed points,
// energy descent, strength, untouched background, preserved depth steps.
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
  for (int y = 0; y < int(h); ++y)
    for (int x = 0; x < int(w); ++x) {
      const float dx = x - w / 2.0f, dy = y - h / 2.0f;
      if (disk && dx * dx + dy * dy > 0.16f * h * h) continue;
      s.depth[std::size_t(y) * w + x] = glm::vec4(depthAt(x, y), 1, 0, 0);
    }
  return s;
}

SmoothingOptions rof(float strength = -1, int iterations = -1) { return {"rof", iterations, strength}; }

TEST(RofFilter, ConstantDepthIsAFixedPoint) {
  for (bool disk : {false, true}) {
    const DepthScene s = flatScene(64, 48, [](int, int) { return 5.0f; }, disk);
    const auto out = smoothOnCpu(s, rof(8.0f));
    for (std::size_t i = 0; i < out.size(); ++i) ASSERT_FLOAT_EQ(out[i].x, s.depth[i].x) << i;
  }
}

TEST(RofFilter, PlanarDepthIsAFixedPointAwayFromTheBoundary) {
  // A tilted plane's depth ramp: ROF's Neumann boundary flattens only a margin at the edges.
  const DepthScene s = flatScene(96, 72, [](int x, int y) { return 4.0f + 0.002f * x + 0.001f * y; }, false);
  const auto out = smoothOnCpu(s, rof(2.0f));
  double worst = 0;
  for (int y = 16; y < 72 - 16; ++y)
    for (int x = 16; x < 96 - 16; ++x) worst = std::max(worst, double(std::abs(out[y * 96 + x].x - s.depth[y * 96 + x].x)));
  EXPECT_LT(worst, 1e-4);
}

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

/// The discrete ROF energy of u for data v with the per-pixel lambda^(0) of eq. 7, on the
/// foreground (forward differences, Neumann).
double rofEnergy(const std::vector<glm::vec4>& u, const DepthScene& s, float strength) {
  const std::uint32_t w = s.frame.size.x, h = s.frame.size.y;
  const float r = s.frame.particleRadius;
  const double lambda0 = strength * s.frame.focalPixels * r * r;
  double e = 0;
  for (std::uint32_t y = 0; y < h; ++y)
    for (std::uint32_t x = 0; x < w; ++x) {
      const std::size_t i = y * w + x;
      if (s.depth[i].y < 0.5f) continue;
      const double gx = x + 1 < w && s.depth[i + 1].y > 0.5f ? u[i + 1].x - u[i].x : 0.0;
      const double gy = y + 1 < h && s.depth[i + w].y > 0.5f ? u[i + w].x - u[i].x : 0.0;
      const double lambda = lambda0 / (s.depth[i].x + r);
      const double diff = u[i].x - s.depth[i].x;
      e += std::sqrt(gx * gx + gy * gy) + diff * diff / (2 * lambda);
    }
  return e;
}

TEST(RofFilter, EnergyDoesNotIncreaseOverIterations) {
  const DepthScene s = sphereScene(96, 72, 1.0f);
  const float strength = 2.0f;
  double previous = rofEnergy(s.depth, s, strength);
  for (int iterations : {1, 2, 4, 8, 16, 32, 75, 150}) {
    const double energy = rofEnergy(smoothOnCpu(s, rof(strength, iterations)), s, strength);
    EXPECT_LE(energy, previous * (1 + 1e-4)) << iterations << " iterations";
    previous = energy;
  }
  EXPECT_LT(previous, rofEnergy(s.depth, s, strength) * 0.8);
}

TEST(RofFilter, LargerLambdaSmoothsMore) {
  const DepthScene s = sphereScene(96, 72, 1.0f);
  double previous = roughness(s.depth, 96, 72);
  for (float strength : {0.5f, 2.0f, 8.0f}) {
    const double r = roughness(smoothOnCpu(s, rof(strength)), 96, 72);
    EXPECT_LT(r, previous * 0.9) << "strength " << strength;
    previous = r;
  }
}

TEST(RofFilter, BackgroundPixelsAreNeverWritten) {
  const DepthScene s = sphereScene(96, 72, 1.0f);
  const auto out = smoothOnCpu(s, rof(8.0f));
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

TEST(RofFilter, DepthStepBetweenTwoSurfacesSurvives) {
  // Two noisy planes, at depth 3 (left) and 3.5 (right): 25 particle radii apart.
  const DepthScene base = flatScene(96, 72, [](int x, int) { return x < 48 ? 3.0f : 3.5f; }, false);
  DepthScene s = base;
  for (int y = 0; y < 72; ++y)
    for (int x = 0; x < 96; ++x) s.depth[y * 96 + x].x -= 0.02f * testing::bumps(x, y, 3.0f, 7);
  const auto out = smoothOnCpu(s, rof());
  for (int y = 8; y < 64; ++y) {
    const float left = out[y * 96 + 46].x, right = out[y * 96 + 49].x;
    EXPECT_GT(right - left, 0.4f) << "row " << y;
  }
}

TEST(SurfaceFilterOptions, UnknownNamesAndOutOfRangeValuesListTheValidOnes) {
  try {
    resolve({"gaussian"});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--smoothing: unknown filter 'gaussian'; valid values: rof"), std::string::npos)
        << e.what();
  }
  try {
    resolve({"rof", 20000});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--smoothing-iterations: 20000 is out of range for rof; valid values: 0..10000"),
              std::string::npos)
        << e.what();
  }
  try {
    resolve({"rof", -1, -3.0f});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--smoothing-strength: -3 is out of range for rof"), std::string::npos)
        << e.what();
  }
  const SmoothingOptions defaults = resolve({"rof"});
  EXPECT_EQ(defaults.iterations, 75);
  EXPECT_GT(defaults.strength, 0);
}

}  // namespace
}  // namespace flipscope
