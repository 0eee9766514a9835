#include "raycast/Camera.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <sstream>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <nlohmann/json.hpp>

#include "core/AtomicFile.h"
#include "core/Error.h"
#include "core/NumberText.h"

namespace flipscope {

glm::dvec3 Camera::forward() const { return glm::normalize(target - eye); }
glm::dvec3 Camera::right() const { return glm::normalize(glm::cross(forward(), up)); }
glm::dvec3 Camera::trueUp() const { return glm::cross(right(), forward()); }

glm::dvec3 Camera::pixelRay(double x, double y, std::uint32_t width, std::uint32_t height) const {
  const double tanHalf = std::tan(glm::radians(fovYDegrees) * 0.5);
  const double sx = ((x + 0.5) / width * 2 - 1) * tanHalf * double(width) / double(height);
  const double sy = (1 - (y + 0.5) / height * 2) * tanHalf;
  return glm::normalize(forward() + sx * right() + sy * trueUp());
}

bool boxMayBeInView(const Camera& camera, std::uint32_t width, std::uint32_t height, const Box& box) {
  if (box.isEmpty()) return false;
  const double tanY = std::tan(glm::radians(camera.fovYDegrees) * 0.5);
  const double tanX = tanY * double(width) / double(height);
  const glm::dvec3 f = camera.forward(), r = camera.right(), u = camera.trueUp();
  // The inward normals of the four side planes through the eye and the image's edges, which
  // bound a pyramid holding every pixel's ray (the centre rays lie within the edges), and of
  // the plane through the eye across the view: nothing behind the eye.
  const std::array<glm::dvec3, 5> inward = {tanX * f - r, tanX * f + r, tanY * f - u, tanY * f + u, f};
  for (const glm::dvec3& n : inward) {
    // The box's corner farthest along n (its "positive vertex"): the box lies wholly outside
    // the plane when that corner does.
    const glm::dvec3 corner(n.x >= 0 ? box.max.x : box.min.x, n.y >= 0 ? box.max.y : box.min.y,
                            n.z >= 0 ? box.max.z : box.min.z);
    if (glm::dot(n, corner - camera.eye) < 0) return false;
  }
  return true;
}

void validate(const Camera& camera, const std::string& what) {
  const auto finite = [](glm::dvec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  if (!finite(camera.eye) || !finite(camera.target) || !finite(camera.up) || !std::isfinite(camera.fovYDegrees))
    throw InputError(what + ": camera values must be finite");
  const glm::dvec3 view = camera.target - camera.eye;
  if (glm::length(view) == 0) throw InputError(what + ": camera eye and target are the same point");
  if (glm::length(glm::cross(glm::normalize(view), camera.up)) < 1e-6)
    throw InputError(what + ": camera up vector is zero or parallel to the view direction");
  if (!(camera.fovYDegrees > 0 && camera.fovYDegrees < 180))
    throw InputError(what + ": field of view must be in (0, 180) degrees, got " + numberText(camera.fovYDegrees));
}

Camera orbitAbout(const Camera& camera, glm::dvec3 axis, double degrees) {
  const double a = glm::radians(degrees);
  const glm::dvec3 k = glm::normalize(axis), v = camera.eye - camera.target;
  Camera c = camera;
  // Rodrigues' rotation of the eye's offset from the target.
  c.eye = camera.target + v * std::cos(a) + glm::cross(k, v) * std::sin(a) + k * glm::dot(k, v) * (1 - std::cos(a));
  return c;
}

Camera frameOnBox(const Box& box, double aspect, glm::dvec3 up, double fovYDegrees) {
  FLIPSCOPE_CHECK(!box.isEmpty() && aspect > 0);
  up = glm::normalize(up);
  // A side axis and a front axis perpendicular to up, so the view is the same for y-up and z-up.
  const glm::dvec3 side = std::abs(up.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  const glm::dvec3 sideAxis = glm::normalize(side - glm::dot(side, up) * up);
  const glm::dvec3 front = glm::cross(sideAxis, up);
  Camera camera;
  camera.target = (box.min + box.max) * 0.5;
  camera.up = up;
  camera.fovYDegrees = fovYDegrees;
  const glm::dvec3 direction = glm::normalize(0.55 * sideAxis + 1.0 * front + 0.45 * up);
  // The view axes from the direction itself (as Camera::right()/trueUp() would give them):
  // target + direction may round onto the target far from the origin.
  const glm::dvec3 forward = -direction;
  const glm::dvec3 right = glm::normalize(glm::cross(forward, up)), trueUp = glm::cross(right, forward);
  // The nearest distance at which all eight corners lie inside the frustum, plus a margin.
  const double tanY = std::tan(glm::radians(fovYDegrees) * 0.5), tanX = tanY * aspect;
  double distance = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::dvec3 c(corner & 1 ? box.max.x : box.min.x, corner & 2 ? box.max.y : box.min.y,
                       corner & 4 ? box.max.z : box.min.z);
    const glm::dvec3 rel = c - camera.target;
    const double towardCamera = glm::dot(rel, direction);
    distance = std::max({distance, towardCamera + std::abs(glm::dot(rel, right)) / tanX,
                         towardCamera + std::abs(glm::dot(rel, trueUp)) / tanY});
  }
  distance = std::max(distance * 1.08, 1e-9);
  camera.eye = camera.target + direction * distance;
  // Far from the origin, doubles may be too coarse for the distance the box's size asks for.
  if (!(glm::length(camera.eye - camera.target) > 0.5 * distance)) {
    const double farthest = std::max({std::abs(camera.target.x), std::abs(camera.target.y), std::abs(camera.target.z)});
    std::ostringstream message;
    message << "the data lies too far from the origin for its size to be viewed: at " << farthest
            << " from the origin, double-precision numbers are " << farthest * std::numeric_limits<double>::epsilon()
            << " apart, and the data is only " << glm::length(box.max - box.min) << " across; move it nearer the origin";
    throw InputError(message.str());
  }
  return camera;
}

Camera parseCamera(const std::string& option, const std::string& text) {
  std::vector<double> values;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    std::size_t used = 0;
    double value = 0;
    try {
      value = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size())
      throw InputError(option + ": '" + item + "' is not a number (expected eye,target,up,fov: 10 numbers)");
    values.push_back(value);
  }
  if (values.size() != 10)
    throw InputError(option + ": expected 10 numbers eye,target,up,fov (ex,ey,ez,tx,ty,tz,ux,uy,uz,fov), got " +
                     std::to_string(values.size()));
  Camera camera{{values[0], values[1], values[2]},
                {values[3], values[4], values[5]},
                {values[6], values[7], values[8]},
                values[9]};
  validate(camera, option);
  return camera;
}

namespace {
glm::dvec3 readVector(const nlohmann::json& json, const char* key, const std::filesystem::path& file) {
  const auto& v = json.at(key);
  if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number())
    throw FileError(file, std::string("\"") + key + "\" must be an array of 3 numbers");
  return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
}
}  // namespace

Camera loadCamera(const std::filesystem::path& file) { return parseCameraJson(readTextFile(file, "camera file"), file); }

Camera parseCameraJson(std::string_view text, const std::filesystem::path& file) {
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw FileError(file, std::string("not valid JSON: ") + e.what());
  }
  if (!json.is_object()) throw FileError(file, "expected a JSON object with \"eye\" and \"target\"");
  for (const char* key : {"eye", "target"})
    if (!json.contains(key)) throw FileError(file, std::string("missing \"") + key + "\"");
  Camera camera;
  camera.eye = readVector(json, "eye", file);
  camera.target = readVector(json, "target", file);
  if (json.contains("up")) camera.up = readVector(json, "up", file);
  if (json.contains("fov")) {
    if (!json["fov"].is_number()) throw FileError(file, "\"fov\" must be a number (degrees)");
    camera.fovYDegrees = json["fov"].get<double>();
  }
  validate(camera, file.string());
  return camera;
}

void saveCamera(const std::filesystem::path& file, const Camera& camera) {
  const nlohmann::json json = {{"eye", {camera.eye.x, camera.eye.y, camera.eye.z}},
                               {"target", {camera.target.x, camera.target.y, camera.target.z}},
                               {"up", {camera.up.x, camera.up.y, camera.up.z}},
                               {"fov", camera.fovYDegrees}};
  writeTextAtomically(file, json.dump(2) + "\n");
}

}  // namespace flipscope
