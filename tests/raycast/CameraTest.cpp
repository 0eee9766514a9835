// Camera helpers: orbitAbout turns the eye about the axis through the target, right-handed,
// keeping its distance and its height along the axis.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "raycast/Camera.h"

namespace flipscope {
namespace {

TEST(Camera, OrbitAboutTurnsTheEyeAboutTheTargetRightHanded) {
  Camera c;
  c.target = {1, 2, 3};
  c.eye = c.target + glm::dvec3(2, 0.5, 0);
  c.up = {0, 1, 0};
  const Camera quarter = orbitAbout(c, {0, 3, 0}, 90);  // the axis need not be a unit vector
  EXPECT_NEAR(quarter.eye.x, 1.0, 1e-12);
  EXPECT_NEAR(quarter.eye.y, 2.5, 1e-12);
  EXPECT_NEAR(quarter.eye.z, 3.0 - 2.0, 1e-12);  // +x turned 90 degrees about +y is -z
  EXPECT_EQ(quarter.target, c.target);
  EXPECT_EQ(quarter.up, c.up);
  EXPECT_EQ(quarter.fovYDegrees, c.fovYDegrees);
  for (double degrees : {7.0, -40.0, 200.0}) {
    const Camera o = orbitAbout(c, {0, 0, 1}, degrees);
    EXPECT_NEAR(glm::length(o.eye - o.target), glm::length(c.eye - c.target), 1e-12);
    EXPECT_NEAR(o.eye.z, c.eye.z, 1e-12) << "the height along the axis is kept";
  }
  const Camera back = orbitAbout(orbitAbout(c, {1, 1, 0}, 33), {1, 1, 0}, -33);
  EXPECT_NEAR(glm::length(back.eye - c.eye), 0.0, 1e-12);
}

}  // namespace
}  // namespace flipscope
