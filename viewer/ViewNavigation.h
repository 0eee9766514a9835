// Turntable navigation of the `flipscope view` camera: what mouse drags, the wheel and the
// WASD/QE keys do to a perspective Camera, independent of any window.
#pragma once

#include <glm/vec3.hpp>

#include "core/Box.h"
#include "raycast/Camera.h"

namespace flipscope::viewer {

/// Turntable navigation of a perspective Camera for `flipscope view`: orbit and pan with the
/// mouse, dolly with the wheel, fly on WASD/QE, frame the data (F), reset (R). Angles and
/// distances follow the viewport so a drag feels the same at any window size. Pixel deltas are
/// in window coordinates: x to the right, y downwards. Not thread safe.
class ViewNavigation {
 public:
  /// `home`: the camera reset() returns to; `worldUp`: the axis orbiting turns around (unit or
  /// not; normalized inside). Throws InputError for an invalid camera (flipscope::validate) or a
  /// zero or non-finite worldUp.
  ViewNavigation(const Camera& home, glm::dvec3 worldUp);

  const Camera& camera() const { return mCamera; }
  /// Becomes the current camera (not home). Throws InputError for an invalid camera.
  void setCamera(const Camera& camera);
  /// The camera reset() returns to (the current one is unchanged). Throws InputError for an
  /// invalid camera.
  void setHome(const Camera& camera);
  glm::dvec3 worldUp() const { return mWorldUp; }

  /// Orbits about the target, turntable style, the scene following the cursor: dragging right
  /// turns the scene to the right (the eye moves left around the target, about worldUp);
  /// dragging down tilts the scene's top towards the viewer (the eye rises). A drag across the
  /// full viewport height turns 180 degrees. The elevation is clamped so the view direction
  /// stays at least 1 degree from +-worldUp (never flips). The distance to the target and the
  /// target are kept; camera.up becomes worldUp. Does nothing for a viewport height <= 0.
  void orbit(double dxPixels, double dyPixels, double viewportHeightPixels);
  /// Moves eye and target together in the view plane (right and trueUp axes) so that a point at
  /// the target's depth follows the cursor: a drag of dx pixels moves by
  /// dx * (2 * d * tan(fov/2) / viewportHeight) world units, d = distance(). Dragging right moves
  /// the camera left, dragging down moves it up. Does nothing for a viewport height <= 0.
  void pan(double dxPixels, double dyPixels, double viewportHeightPixels);
  /// Dolly: the distance to the target becomes distance * 0.85^steps (positive steps move
  /// closer), kept within [1e-4, 1e4] times the home distance (a camera already outside that
  /// range is never moved further out of it).
  void zoom(double steps);
  /// Fly (WASD/QE): moves eye and target together by `forward` world units along forward(),
  /// `right` along right(), `up` along worldUp.
  void fly(double forward, double right, double up);
  /// Frames `box` keeping the current view direction, up and fov: the target goes to the box
  /// centre and the eye back along the view direction until the box's bounding sphere, enlarged
  /// by 5%, fits the image of `aspect` = width / height (vertical and horizontal fov). The
  /// distance is at least 1e-4 times the home distance (a box of one point). An empty box
  /// leaves the camera unchanged.
  void frame(const Box& box, double aspect);
  /// The home camera again.
  void reset() { mCamera = mHome; }
  /// Distance eye-target (world units).
  double distance() const;

 private:
  double homeDistance() const;

  Camera mHome;
  Camera mCamera;
  glm::dvec3 mWorldUp;
};

}  // namespace flipscope::viewer
