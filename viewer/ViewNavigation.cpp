#include "viewer/ViewNavigation.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "core/Error.h"

namespace flipscope::viewer {

namespace {
constexpr double kZoomFactor = 0.85;         ///< distance factor of one wheel step
constexpr double kMinDistanceFactor = 1e-4;  ///< of the home distance
constexpr double kMaxDistanceFactor = 1e4;   ///< of the home distance
constexpr double kFrameMargin = 1.05;        ///< bounding-sphere enlargement of frame()
constexpr double kMinPoleAngleDegrees = 1;   ///< closest approach of the view direction to worldUp
}  // namespace

ViewNavigation::ViewNavigation(const Camera& home, glm::dvec3 worldUp) {
  const double length = glm::length(worldUp);
  if (!(length > 0 && std::isfinite(length))) throw InputError("view navigation: the world up axis must be non-zero");
  mWorldUp = worldUp / length;
  setHome(home);
  mCamera = home;
}

void ViewNavigation::setCamera(const Camera& camera) {
  validate(camera, "view camera");
  mCamera = camera;
}

void ViewNavigation::setHome(const Camera& camera) {
  validate(camera, "home camera");
  mHome = camera;
}

double ViewNavigation::distance() const { return glm::length(mCamera.eye - mCamera.target); }

double ViewNavigation::homeDistance() const { return glm::length(mHome.eye - mHome.target); }

void ViewNavigation::orbit(double dxPixels, double dyPixels, double viewportHeightPixels) {
  if (!(viewportHeightPixels > 0)) return;
  const double d = distance();
  const glm::dvec3 toEye = (mCamera.eye - mCamera.target) / d;
  const double height = std::clamp(glm::dot(toEye, mWorldUp), -1.0, 1.0);
  glm::dvec3 horizontal = toEye - height * mWorldUp;
  // Looking along worldUp: leave the pole on the side that keeps the image's top where it is.
  if (glm::length(horizontal) < 1e-9) horizontal = -height * (mCamera.up - glm::dot(mCamera.up, mWorldUp) * mWorldUp);
  horizontal = glm::normalize(horizontal);

  const double limit = glm::radians(90 - kMinPoleAngleDegrees);
  const double elevation =
      std::clamp(std::asin(height) + dyPixels / viewportHeightPixels * std::numbers::pi, -limit, limit);
  const double azimuth = -dxPixels / viewportHeightPixels * std::numbers::pi;
  horizontal = std::cos(azimuth) * horizontal + std::sin(azimuth) * glm::cross(mWorldUp, horizontal);
  mCamera.eye = mCamera.target + d * (std::cos(elevation) * horizontal + std::sin(elevation) * mWorldUp);
  mCamera.up = mWorldUp;
}

void ViewNavigation::pan(double dxPixels, double dyPixels, double viewportHeightPixels) {
  if (!(viewportHeightPixels > 0)) return;
  const double worldPerPixel =
      2 * distance() * std::tan(glm::radians(mCamera.fovYDegrees) * 0.5) / viewportHeightPixels;
  const glm::dvec3 move = worldPerPixel * (-dxPixels * mCamera.right() + dyPixels * mCamera.trueUp());
  mCamera.eye += move;
  mCamera.target += move;
}

void ViewNavigation::zoom(double steps) {
  const double d = distance();
  const double lowest = std::min(d, kMinDistanceFactor * homeDistance());
  const double highest = std::max(d, kMaxDistanceFactor * homeDistance());
  const double next = std::clamp(d * std::pow(kZoomFactor, steps), lowest, highest);
  mCamera.eye = mCamera.target - mCamera.forward() * next;
}

void ViewNavigation::fly(double forward, double right, double up) {
  const glm::dvec3 move = forward * mCamera.forward() + right * mCamera.right() + up * mWorldUp;
  mCamera.eye += move;
  mCamera.target += move;
}

void ViewNavigation::frame(const Box& box, double aspect) {
  FLIPSCOPE_CHECK(aspect > 0, "aspect " << aspect);
  if (box.isEmpty()) return;
  const double radius = 0.5 * glm::length(box.extent());
  const double halfY = glm::radians(mCamera.fovYDegrees) * 0.5;
  const double halfX = std::atan(std::tan(halfY) * aspect);
  const double fit = kFrameMargin * radius / std::sin(std::min(halfX, halfY));
  const glm::dvec3 forward = mCamera.forward();
  mCamera.target = (box.min + box.max) * 0.5;
  mCamera.eye = mCamera.target - forward * std::max(fit, kMinDistanceFactor * homeDistance());
}

}  // namespace flipscope::viewer
