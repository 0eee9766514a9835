// Properties particular to the `rof` filter (Reichl et al. 2014 §3.4) on the CPU reference: a
// depth ramp is a fixed point away from the boundary, and the ROF energy descends. What every
// filter shares (fixed points, strength, untouched background, depth steps, registry entry):
// SurfaceFilterPropertiesTest.cpp.
#include <gtest/gtest.h>

#include <cmath>

#include "smoothing/SmoothingScenes.h"

namespace flipscope {
namespace {

using testing::DepthScene;
using testing::filterOptions;
using testing::smoothOnCpu;

TEST(RofFilter, PlanarDepthIsAFixedPointAwayFromTheBoundary) {
  // A tilted plane's depth ramp: ROF's Neumann boundary flattens only a margin at the edges.
  const DepthScene s = testing::flatScene(
      96, 72, [](int x, int y) { return 4.0f + 0.002f * x + 0.001f * y; }, false);
  EXPECT_LT(testing::worstChange(smoothOnCpu(s, filterOptions("rof", 2.0f)), s, 16), 1e-4);
}

/// The discrete ROF energy of u for data v with the per-pixel lambda^(0) of eq. 7, on the
/// foreground (forward differences, Neumann).
double rofEnergy(const std::vector<glm::vec4>& u, const DepthScene& s, float strength) {
  const std::uint32_t w = s.frame.width, h = s.frame.height;
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
  const DepthScene s = testing::sphereScene(96, 72, 1.0f);
  const float strength = 2.0f;
  double previous = rofEnergy(s.depth, s, strength);
  for (int iterations : {1, 2, 4, 8, 16, 32, 75, 150}) {
    const double energy = rofEnergy(smoothOnCpu(s, filterOptions("rof", strength, iterations)), s, strength);
    EXPECT_LE(energy, previous * (1 + 1e-4)) << iterations << " iterations";
    previous = energy;
  }
  EXPECT_LT(previous, rofEnergy(s.depth, s, strength) * 0.8);
}

}  // namespace
}  // namespace flipscope
