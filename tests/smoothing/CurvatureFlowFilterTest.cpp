// Properties particular to the `curvature-flow` filter (van der Laan, Green, Sainz 2009) on the
// CPU reference: the explicit steps stay stable at the largest step on pixel noise. What every
// filter shares (fixed points, untouched background, smoothing towards the exact surface, more
// smoothing with more or larger steps, stability at the largest settings, depth steps, registry
// entry): SurfaceFilterPropertiesTest.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "smoothing/SmoothingScenes.h"

namespace flipscope {
namespace {

using testing::DepthScene;
using testing::noiseRoughness;

TEST(CurvatureFlowFilter, PixelNoiseOnASteepPlaneDecaysAtTheLargestStep) {
  // Independent noise of two particle radii per pixel (the mode an explicit step amplifies
  // first) on a plane whose depth rises by 0.02 per pixel, at the stability limit.
  DepthScene s = testing::flatScene(
      64, 48, [](int x, int y) { return 3.0f + 0.02f * x + 0.04f * testing::bumps(x, y, 1.0f, 5); }, false);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) s.exactDepth[y * 64 + x] = 3.0f + 0.02f * x;
  const double before = noiseRoughness(s.depth, s);
  double previous = before;
  for (int iterations : {1, 10, 100, 1000}) {
    const auto out = testing::smoothOnCpu(s, testing::filterOptions("curvature-flow", 1.0f, iterations));
    for (const glm::vec4& d : out) ASSERT_TRUE(std::isfinite(d.x) && d.x > 2.9f && d.x < 4.4f) << iterations;
    const double r = noiseRoughness(out, s);
    // falls to the level of the flow's own deformation of the plane, and stays there
    EXPECT_LT(r, std::max(previous, before * 0.01)) << iterations << " iterations";
    previous = r;
  }
  EXPECT_LT(previous, before * 0.1);
}

}  // namespace
}  // namespace flipscope
