// Properties particular to the `bilateral` filter (depth-adaptive bilateral Gaussian with a
// world-space kernel) on the CPU reference: a depth ramp is a fixed point where the kernel lies
// inside the image. What every filter shares (fixed points, strength and iterations, untouched
// background, depth steps, approach to the analytic surface, registry entry):
// SurfaceFilterPropertiesTest.cpp.
#include <gtest/gtest.h>

#include "smoothing/SmoothingScenes.h"

namespace flipscope {
namespace {

using testing::DepthScene;

TEST(BilateralFilter, PlanarDepthIsAFixedPointAwayFromTheBoundary) {
  // A tilted plane's depth ramp: the kernel is symmetric wherever it lies inside the image.
  const DepthScene s = testing::flatScene(
      96, 72, [](int x, int y) { return 2.0f + 0.002f * x + 0.001f * y; }, false);
  const auto out = testing::smoothOnCpu(s, testing::filterOptions("bilateral", 8.0f));
  EXPECT_LT(testing::worstChange(out, s, 24), 1e-5);
}

}  // namespace
}  // namespace flipscope
