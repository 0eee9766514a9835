// ViewNavigation: orbit, pan, zoom, fly and frame keep their geometric contracts, with y-up and
// z-up worlds alike.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "core/Error.h"
#include "viewer/ViewNavigation.h"

namespace flipscope::viewer {
namespace {

constexpr double kTolerance = 1e-9;

struct World {
  const char* name;
  glm::dvec3 up;
};

class ViewNavigationTest : public ::testing::TestWithParam<World> {
 protected:
  /// A three-quarter view of a box near (1, 2, 3), its up the world's up.
  Camera home() const { return frameOnBox(Box{{0, 1, 2}, {2, 4, 5}}, 1.5, GetParam().up, 50); }
};

void expectNear(glm::dvec3 a, glm::dvec3 b, double tolerance = kTolerance) {
  EXPECT_NEAR(glm::length(a - b), 0, tolerance)
      << "(" << a.x << ", " << a.y << ", " << a.z << ") vs (" << b.x << ", " << b.y << ", " << b.z << ")";
}

void expectSameCamera(const Camera& a, const Camera& b) {
  expectNear(a.eye, b.eye);
  expectNear(a.target, b.target);
  expectNear(glm::normalize(a.up), glm::normalize(b.up));
  EXPECT_DOUBLE_EQ(a.fovYDegrees, b.fovYDegrees);
}

double degreesBetween(glm::dvec3 a, glm::dvec3 b) {
  return glm::degrees(std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0)));
}

TEST_P(ViewNavigationTest, OrbitKeepsTargetAndDistanceAndSetsUp) {
  ViewNavigation navigation(home(), GetParam().up * 3.0);
  const double distance = navigation.distance();
  const glm::dvec3 target = navigation.camera().target;
  for (const auto& [dx, dy] : {std::pair{37.0, -12.0}, {-250.0, 400.0}, {0.5, 0.25}, {1000.0, -3000.0}}) {
    navigation.orbit(dx, dy, 720);
    EXPECT_NEAR(navigation.distance(), distance, kTolerance * distance);
    expectNear(navigation.camera().target, target);
    expectNear(navigation.camera().up, GetParam().up);
  }
}

TEST_P(ViewNavigationTest, OrbitDirectionsFollowTheDocumentedConvention) {
  ViewNavigation navigation(home(), GetParam().up);
  const Camera start = navigation.camera();
  navigation.orbit(10, 0, 500);
  // Dragging right: the eye moves left around the target, at the same height.
  EXPECT_LT(glm::dot(navigation.camera().eye - start.eye, start.right()), 0);
  EXPECT_NEAR(glm::dot(navigation.camera().eye - start.eye, GetParam().up), 0, kTolerance);
  navigation.setCamera(start);
  navigation.orbit(0, 10, 500);
  // Dragging down: the eye rises, by the angle the drag asks for (10 / 500 of 180 degrees).
  EXPECT_GT(glm::dot(navigation.camera().eye - start.eye, GetParam().up), 0);
  EXPECT_NEAR(degreesBetween(navigation.camera().forward(), start.forward()), 10.0 / 500 * 180, 1e-9);
}

TEST_P(ViewNavigationTest, OrbitThereAndBackReturnsToTheStart) {
  ViewNavigation navigation(home(), GetParam().up);
  const Camera start = navigation.camera();
  navigation.orbit(123, -45, 800);
  navigation.orbit(-123, 45, 800);
  expectSameCamera(navigation.camera(), start);
}

TEST_P(ViewNavigationTest, TwoFullHeightDragsTurnOnceAround) {
  ViewNavigation navigation(home(), GetParam().up);
  const Camera start = navigation.camera();
  navigation.orbit(600, 0, 600);
  // Half way round: the eye is on the far side, mirrored through the worldUp axis of the target.
  EXPECT_NEAR(degreesBetween(navigation.camera().eye - start.target, start.eye - start.target),
              180 - 2 * (90 - degreesBetween(start.eye - start.target, GetParam().up)), 1e-9);
  navigation.orbit(600, 0, 600);
  expectSameCamera(navigation.camera(), start);
}

TEST_P(ViewNavigationTest, OrbitNeverCrossesThePoles) {
  ViewNavigation navigation(home(), GetParam().up);
  for (const double dy : {5000.0, 17.0, -100000.0, 3.0, 1e9, -1e9, 0.25}) {
    navigation.orbit(31, dy, 700);
    const glm::dvec3 forward = navigation.camera().forward();
    EXPECT_GT(degreesBetween(forward, GetParam().up), 0.999);
    EXPECT_GT(degreesBetween(forward, -GetParam().up), 0.999);
    EXPECT_NO_THROW(validate(navigation.camera(), "orbited camera"));
  }
  // At the clamp, a drag back moves away from the pole at once.
  navigation.orbit(0, 1e6, 700);
  const double atPole = degreesBetween(navigation.camera().forward(), -GetParam().up);
  navigation.orbit(0, -7, 700);
  EXPECT_NEAR(degreesBetween(navigation.camera().forward(), -GetParam().up), atPole + 7.0 / 700 * 180, 1e-9);
}

TEST_P(ViewNavigationTest, OrbitLeavesAStraightDownViewWithoutTurningTheImage) {
  const glm::dvec3 up = GetParam().up;
  const glm::dvec3 side = std::abs(up.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  Camera top{up * 10.0, glm::dvec3(0), side, 40};
  ViewNavigation navigation(top, up);
  navigation.orbit(0, -1, 1000);
  EXPECT_NEAR(degreesBetween(navigation.camera().forward(), -up), 1, 1e-6);
  EXPECT_GT(glm::dot(navigation.camera().trueUp(), side), 0.99);
}

TEST_P(ViewNavigationTest, PanFollowsTheCursorAtTheTargetsDepth) {
  ViewNavigation navigation(home(), GetParam().up);
  const Camera start = navigation.camera();
  const double height = 900, dx = 40, dy = -25;
  navigation.pan(dx, dy, height);
  const glm::dvec3 eyeMove = navigation.camera().eye - start.eye;
  expectNear(navigation.camera().target - start.target, eyeMove);
  EXPECT_NEAR(glm::dot(eyeMove, start.forward()), 0, kTolerance);
  const double perPixel = 2 * navigation.distance() * std::tan(glm::radians(start.fovYDegrees) / 2) / height;
  EXPECT_NEAR(glm::length(eyeMove), std::hypot(dx, dy) * perPixel, kTolerance);
  // The scene follows the cursor: dragging right and up moves the camera left and down.
  EXPECT_NEAR(glm::dot(eyeMove, start.right()), -dx * perPixel, kTolerance);
  EXPECT_NEAR(glm::dot(eyeMove, start.trueUp()), dy * perPixel, kTolerance);
}

TEST_P(ViewNavigationTest, ZoomIsReversibleAndNeverReachesTheTarget) {
  ViewNavigation navigation(home(), GetParam().up);
  const Camera start = navigation.camera();
  const double distance = navigation.distance();
  navigation.zoom(3);
  EXPECT_NEAR(navigation.distance(), distance * std::pow(0.85, 3), kTolerance);
  expectNear(navigation.camera().forward(), start.forward());
  navigation.zoom(-3);
  expectSameCamera(navigation.camera(), start);

  navigation.zoom(1e6);
  EXPECT_GE(navigation.distance(), 1e-4 * distance * (1 - 1e-9));
  EXPECT_NO_THROW(validate(navigation.camera(), "zoomed camera"));
  expectNear(navigation.camera().target, start.target);
  navigation.zoom(-1e6);
  EXPECT_LE(navigation.distance(), 1e4 * distance * (1 + 1e-9));
  EXPECT_TRUE(std::isfinite(navigation.distance()));
  expectNear(navigation.camera().forward(), start.forward());
}

TEST_P(ViewNavigationTest, FlyMovesEyeAndTargetTogether) {
  ViewNavigation navigation(home(), GetParam().up);
  const Camera start = navigation.camera();
  navigation.fly(2, -0.5, 0.75);
  const glm::dvec3 move = navigation.camera().eye - start.eye;
  expectNear(navigation.camera().target - start.target, move);
  EXPECT_NEAR(glm::dot(move, start.forward()), 2 + 0.75 * glm::dot(GetParam().up, start.forward()), kTolerance);
  EXPECT_NEAR(glm::dot(move, start.right()), -0.5, kTolerance);
  EXPECT_NEAR(glm::dot(move, GetParam().up), 0.75 + 2 * glm::dot(start.forward(), GetParam().up), kTolerance);
}

/// The largest share of the image's half-width or half-height a corner of `box` takes as seen
/// by `camera` (image aspect `aspect`): below 1 when all corners are inside the frustum.
double cornerFill(const Camera& camera, const Box& box, double aspect) {
  const double tanY = std::tan(glm::radians(camera.fovYDegrees) / 2), tanX = tanY * aspect;
  double fill = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::dvec3 c(corner & 1 ? box.max.x : box.min.x, corner & 2 ? box.max.y : box.min.y,
                       corner & 4 ? box.max.z : box.min.z);
    const glm::dvec3 rel = c - camera.eye;
    const double depth = glm::dot(rel, camera.forward());
    if (!(depth > 0)) return std::numeric_limits<double>::infinity();
    fill = std::max({fill, std::abs(glm::dot(rel, camera.right())) / depth / tanX,
                     std::abs(glm::dot(rel, camera.trueUp())) / depth / tanY});
  }
  return fill;
}

/// `navigation` looking along `direction` from wherever its target is.
void lookAlong(ViewNavigation& navigation, glm::dvec3 direction) {
  Camera camera = navigation.camera();
  camera.eye = camera.target - glm::normalize(direction) * 7.0;
  navigation.setCamera(camera);
}

TEST_P(ViewNavigationTest, FrameFitsTheBoundingSphereWithItsMargin) {
  const glm::dvec3 directions[] = {{1, 0.3, -0.2}, {-0.4, -1, 0.5}, {0.3, 0.2, 1}};
  const Box box{{-3, 10, 4}, {5, 12, 4.5}};
  for (const double aspect : {0.5, 1.0, 2.5}) {
    for (const glm::dvec3& direction : directions) {
      ViewNavigation navigation(home(), GetParam().up);
      lookAlong(navigation, direction);
      navigation.frame(box, aspect);
      const Camera& framed = navigation.camera();
      expectNear(framed.forward(), glm::normalize(direction));
      expectNear(framed.target, (box.min + box.max) * 0.5);
      EXPECT_LT(cornerFill(framed, box, aspect), 1) << "aspect " << aspect;
      // The bounding sphere, 5% larger, touches the narrower side of the frustum.
      const double tanY = std::tan(glm::radians(framed.fovYDegrees) / 2);
      const double halfAngle = std::min(std::atan(tanY * aspect), std::atan(tanY));
      const double radius = glm::length(box.extent()) / 2;
      EXPECT_NEAR(std::asin(1.05 * radius / navigation.distance()), halfAngle, 1e-9) << "aspect " << aspect;
    }
  }
}

TEST_P(ViewNavigationTest, FrameIsTightOnACubeSeenAlongItsDiagonal) {
  // The cube's silhouette nearly fills its bounding sphere's: a corner comes near the edge.
  const Box cube{{-1, 6, -1}, {1, 8, 1}};
  for (const glm::dvec3& direction : {glm::dvec3(1, 1, 1), glm::dvec3(-1, 1, -1), glm::dvec3(1, -1, -1)}) {
    ViewNavigation navigation(home(), GetParam().up);
    lookAlong(navigation, direction);
    navigation.frame(cube, 1);
    const double fill = cornerFill(navigation.camera(), cube, 1);
    EXPECT_LT(fill, 1);
    EXPECT_GT(fill, 0.75);
  }
}

TEST_P(ViewNavigationTest, FrameIgnoresAnEmptyBoxAndKeepsAPointAway) {
  ViewNavigation navigation(home(), GetParam().up);
  const Camera start = navigation.camera();
  navigation.frame(Box{}, 1.5);
  expectSameCamera(navigation.camera(), start);
  navigation.frame(Box{{1, 1, 1}, {1, 1, 1}}, 1.5);
  EXPECT_NO_THROW(validate(navigation.camera(), "framed camera"));
  expectNear(navigation.camera().target, {1, 1, 1});
}

TEST_P(ViewNavigationTest, ResetReturnsHome) {
  ViewNavigation navigation(home(), GetParam().up);
  navigation.orbit(100, 50, 600);
  navigation.pan(-30, 80, 600);
  navigation.zoom(4);
  navigation.fly(1, 2, 3);
  navigation.reset();
  expectSameCamera(navigation.camera(), home());

  Camera other = home();
  other.eye += glm::dvec3(1, 2, 3);
  navigation.setHome(other);
  expectSameCamera(navigation.camera(), home());  // setHome leaves the current camera
  navigation.reset();
  expectSameCamera(navigation.camera(), other);
}

INSTANTIATE_TEST_SUITE_P(Worlds, ViewNavigationTest,
                         ::testing::Values(World{"YUp", {0, 1, 0}}, World{"ZUp", {0, 0, 1}}),
                         [](const ::testing::TestParamInfo<World>& info) { return std::string(info.param.name); });

TEST(ViewNavigation, RefusesAnInvalidCameraOrUpAxis) {
  const Camera good;
  EXPECT_THROW(ViewNavigation(good, glm::dvec3(0)), InputError);
  EXPECT_THROW(ViewNavigation(Camera{{1, 1, 1}, {1, 1, 1}, {0, 1, 0}, 40}, {0, 1, 0}), InputError);
  ViewNavigation navigation(good, {0, 1, 0});
  EXPECT_THROW(navigation.setCamera(Camera{{0, 5, 0}, {0, 0, 0}, {0, 1, 0}, 40}), InputError);
  EXPECT_THROW(navigation.setHome(Camera{{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 200}), InputError);
  expectSameCamera(navigation.camera(), good);
}

TEST(ViewNavigation, IgnoresAnEmptyViewport) {
  ViewNavigation navigation(Camera{}, {0, 1, 0});
  navigation.orbit(10, 10, 0);
  navigation.pan(10, 10, -1);
  expectSameCamera(navigation.camera(), Camera{});
}

}  // namespace
}  // namespace flipscope::viewer
