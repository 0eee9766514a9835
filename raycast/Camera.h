// The perspective camera of a render: where it is, what it looks at, and how it turns into the
// ray-caster's parameters. Cameras come from the command line (`--camera eye,target,up,fov`),
// a JSON file (`--camera-file`), or are framed on the data (frameOnBox).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>

#include "core/Box.h"

namespace flipscope {

struct Camera {
  glm::dvec3 eye{0, 0, 5};
  glm::dvec3 target{0};
  glm::dvec3 up{0, 1, 0};
  double fovYDegrees = 40;  ///< vertical field of view

  /// Unit view direction, right and (orthogonalized) up vectors.
  glm::dvec3 forward() const;
  glm::dvec3 right() const;
  glm::dvec3 trueUp() const;
  /// Unit direction of the ray through the centre of pixel (x, y) of a width x height image,
  /// row 0 at the top: the double-precision twin of rcCameraRay (raycast/glsl/Raycast.glsl).
  glm::dvec3 pixelRay(double x, double y, std::uint32_t width, std::uint32_t height) const;
  bool operator==(const Camera&) const = default;
};

/// Whether `box` may hold a point that a ray of a width x height image (pixelRay) passes
/// through: it meets the pyramid of the image's corner rays, or lies near one of its edges (the
/// test is conservative: each side plane alone, and the plane across the view at the eye, so
/// that a box wholly behind the eye is out).
bool boxMayBeInView(const Camera& camera, std::uint32_t width, std::uint32_t height, const Box& box);

/// Throws InputError naming `what` when eye == target, up is parallel to the view direction, or
/// the field of view is outside (0, 180).
void validate(const Camera& camera, const std::string& what);

/// A three-quarter view from the front, right and above (relative to `up`), as close as the
/// whole box (all eight corners) fits into an image of `aspect` = width / height, with a margin.
Camera frameOnBox(const Box& box, double aspect, glm::dvec3 up = {0, 1, 0}, double fovYDegrees = 40);

/// `camera` with its eye turned by `degrees` (right-handed) about the line through its target
/// along `axis`: a step of an orbit. Target, up and field of view are kept.
Camera orbitAbout(const Camera& camera, glm::dvec3 axis, double degrees);

/// Parses "ex,ey,ez,tx,ty,tz,ux,uy,uz,fov" (10 numbers, fov in degrees). Throws InputError
/// naming `option`.
Camera parseCamera(const std::string& option, const std::string& text);

/// JSON: {"eye": [x, y, z], "target": [x, y, z], "up": [x, y, z], "fov": degrees}; "up" and
/// "fov" are optional. loadCamera throws FileError naming the file and the field.
Camera loadCamera(const std::filesystem::path& file);
/// loadCamera's parser: the JSON `text` of the camera file `file` (named in errors).
Camera parseCameraJson(std::string_view text, const std::filesystem::path& file);
void saveCamera(const std::filesystem::path& file, const Camera& camera);

}  // namespace flipscope
