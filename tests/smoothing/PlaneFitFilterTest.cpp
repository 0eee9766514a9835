// Properties particular to the `plane-fit` filter (iterative MLS plane fitting, Imai, Kanamori,
// Mitani 2016) on the CPU reference: a plane in eye space is a fixed point, edges and rims
// included. What every filter shares (fixed points, untouched background, smoothing towards the
// exact surface, more smoothing with more iterations or a larger window, stability at the largest
// settings, depth steps, registry entry): SurfaceFilterPropertiesTest.cpp.
#include <gtest/gtest.h>

#include "smoothing/SmoothingScenes.h"

namespace flipscope {
namespace {

using testing::DepthScene;

TEST(PlaneFitFilter, TiltedPlaneInEyeSpaceIsAFixedPoint) {
  // The plane n . X = n . (0, 0, -4) through the point 4 units ahead, tilted by about 17 and
  // 11 degrees: its exact linear depth along every pixel's ray, edges and disk rim included.
  const glm::vec3 n = glm::normalize(glm::vec3(0.3f, -0.2f, 1.0f));
  const ScreenFrame frame = testing::testFrame(96, 72);
  for (bool disk : {false, true}) {
    const DepthScene s = testing::flatScene(
        96, 72,
        [&](int x, int y) {
          const glm::vec3 v = testing::pixelRay(frame, x, y);
          return 4.0f * n.z * v.z / glm::dot(n, v);
        },
        disk);
    for (float strength : {4.0f, 50.0f}) {
      const auto out = testing::smoothOnCpu(s, testing::filterOptions("plane-fit", strength, 10));
      EXPECT_LT(testing::worstChange(out, s), 1e-5) << "disk " << disk << " strength " << strength;
    }
  }
}

}  // namespace
}  // namespace flipscope
