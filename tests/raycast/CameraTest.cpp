// Camera helpers: orbitAbout turns the eye about the axis through the target, right-handed,
// keeping its distance and its height along the axis; boxMayBeInView keeps every box that a
// pixel's ray meets.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>

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

/// Whether the ray from `eye` along `dir` meets `box` in front of the eye (a slab test).
bool rayMeetsBox(glm::dvec3 eye, glm::dvec3 dir, const Box& box) {
  double near = 0, far = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (dir[a] == 0) {
      if (eye[a] < box.min[a] || eye[a] > box.max[a]) return false;
      continue;
    }
    const double t0 = (box.min[a] - eye[a]) / dir[a], t1 = (box.max[a] - eye[a]) / dir[a];
    near = std::max(near, std::min(t0, t1));
    far = std::min(far, std::max(t0, t1));
  }
  return near <= far;
}

TEST(Camera, BoxMayBeInViewKeepsEveryBoxAPixelsRayMeetsAndDropsMostOthers) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coordinate(-10, 10), size(0.05, 3), fov(10, 100);
  constexpr std::uint32_t kWidth = 48, kHeight = 27;
  int met = 0, keptUnmet = 0, unmet = 0;
  for (int c = 0; c < 40; ++c) {
    Camera camera;
    camera.eye = {coordinate(rng), coordinate(rng), coordinate(rng)};
    camera.target = {coordinate(rng), coordinate(rng), coordinate(rng)};
    camera.fovYDegrees = fov(rng);
    for (int b = 0; b < 100; ++b) {
      const glm::dvec3 lo(coordinate(rng), coordinate(rng), coordinate(rng));
      const Box box{lo, lo + glm::dvec3(size(rng), size(rng), size(rng))};
      bool anyRay = false;
      for (std::uint32_t y = 0; y < kHeight && !anyRay; ++y)
        for (std::uint32_t x = 0; x < kWidth && !anyRay; ++x)
          anyRay = rayMeetsBox(camera.eye, camera.pixelRay(x, y, kWidth, kHeight), box);
      const bool kept = boxMayBeInView(camera, kWidth, kHeight, box);
      if (anyRay) {
        ++met;
        EXPECT_TRUE(kept) << "camera " << c << ", box " << b;
      } else {
        ++unmet;
        keptUnmet += kept;
      }
    }
  }
  EXPECT_GT(met, 100);
  EXPECT_LT(keptUnmet, unmet / 4) << "of " << unmet << " boxes no ray meets (most lie out of view)";
}

TEST(Camera, BoxMayBeInViewDropsBoxesBehindAndBesideTheEyeAndKeepsOneAroundIt) {
  Camera camera;  // at (0, 0, 5) looking down -z, 40 degrees high
  const auto at = [](glm::dvec3 centre, double half) { return Box{centre - half, centre + half}; };
  EXPECT_TRUE(boxMayBeInView(camera, 160, 90, at({0, 0, 0}, 0.5)));
  EXPECT_FALSE(boxMayBeInView(camera, 160, 90, at({0, 0, 10}, 0.5))) << "behind";
  EXPECT_FALSE(boxMayBeInView(camera, 160, 90, at({0, 0, 8}, 2.5))) << "behind, across the view's axis";
  EXPECT_FALSE(boxMayBeInView(camera, 160, 90, at({0, 4, 0}, 0.5))) << "above the top edge";
  EXPECT_TRUE(boxMayBeInView(camera, 160, 90, at({0, 0, 5}, 0.1))) << "around the eye";
  // The image's aspect widens the view: x = 2.5 at distance 5 is out of a square image only.
  EXPECT_TRUE(boxMayBeInView(camera, 160, 90, at({2.5, 0, 0}, 0.2)));
  EXPECT_FALSE(boxMayBeInView(camera, 90, 90, at({2.5, 0, 0}, 0.2)));
  EXPECT_FALSE(boxMayBeInView(camera, 160, 90, Box{}));
}

}  // namespace
}  // namespace flipscope
