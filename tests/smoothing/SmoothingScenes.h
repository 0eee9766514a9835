// Depth images for the smoothing tests: analytic scenes (a sphere, planes, a step) seen by a
// camera at the origin looking down -z, optionally roughened by particle-sized bumps; helpers to
// run a filter on a device; and the measures the filter tests judge a result by (roughness,
// distance to the analytic depth, largest change). Depth is linear camera depth in world units.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec4.hpp>

#include "smoothing/CpuScreenDevice.h"
#include "core/Error.h"
#include "smoothing/SurfaceFilter.h"

namespace flipscope::testing {

/// A width x height frame, vertical fov `fovDegrees`, spheres of `radius` world units.
inline ScreenFrame testFrame(std::uint32_t width, std::uint32_t height, float radius = 0.02f,
                             float fovDegrees = 40.0f) {
  ScreenFrame f{};
  const float t = std::tan(fovDegrees * 3.14159265f / 360.0f);
  f.forward = glm::vec4(0, 0, -1, 0);
  f.right = glm::vec4(1, 0, 0, 0);
  f.up = glm::vec4(0, 1, 0, 0);
  f.worldUp = glm::vec4(0, 1, 0, 0);
  f.width = width;
  f.height = height;
  f.tanHalfFovY = t;
  f.aspect = float(width) / float(height);
  f.focalPixels = float(height) / (2.0f * t);
  f.particleRadius = radius;
  f.cellSize = radius;
  return f;
}

/// The unit ray through the centre of pixel (x, y) (mirrors ssPixelRay).
inline glm::vec3 pixelRay(const ScreenFrame& f, int x, int y) {
  const float sx = ((x + 0.5f) / f.width * 2 - 1) * f.tanHalfFovY * f.aspect;
  const float sy = (1 - (y + 0.5f) / f.height * 2) * f.tanHalfFovY;
  return glm::normalize(glm::vec3(0, 0, -1) + sx * glm::vec3(1, 0, 0) + sy * glm::vec3(0, 1, 0));
}

/// A smooth hash-based bump field in [-1, 1] with features of `cell` pixels.
inline float bumps(int x, int y, float cell, std::uint32_t seed) {
  auto hash = [seed](int i, int j) {
    std::uint32_t h = std::uint32_t(i) * 73856093u ^ std::uint32_t(j) * 19349663u ^ seed * 83492791u;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return float(h & 0xffffu) / 32767.5f - 1.0f;
  };
  const float fx = x / cell, fy = y / cell;
  const int ix = int(std::floor(fx)), iy = int(std::floor(fy));
  const float tx = fx - ix, ty = fy - iy;
  const float a = hash(ix, iy) + (hash(ix + 1, iy) - hash(ix, iy)) * tx;
  const float b = hash(ix, iy + 1) + (hash(ix + 1, iy + 1) - hash(ix, iy + 1)) * tx;
  return a + (b - a) * ty;
}

struct DepthScene {
  ScreenFrame frame;
  std::vector<glm::vec4> depth;      ///< x depth, y mask (the filter's input)
  std::vector<glm::vec3> normals;    ///< analytic world normal, 0 on the background
  std::vector<float> exactDepth;     ///< analytic depth before roughening
};

constexpr float kBackgroundDepth = 123.0f;  ///< what background pixels hold (must survive untouched)

/// A sphere of radius `sphereRadius` at distance `distance` in front of the camera, in front of
/// a plane at depth `planeDepth` (0: no plane), roughened by bumps of `roughness` particle
/// radii with features of one particle's screen size.
inline DepthScene sphereScene(std::uint32_t width, std::uint32_t height, float roughness = 0.5f,
                              float distance = 3.0f, float sphereRadius = 0.8f, float planeDepth = 0.0f,
                              std::uint32_t seed = 1) {
  DepthScene s;
  s.frame = testFrame(width, height);
  const std::size_t n = std::size_t(width) * height;
  s.depth.assign(n, glm::vec4(kBackgroundDepth, 0, 0, 0));
  s.normals.assign(n, glm::vec3(0));
  s.exactDepth.assign(n, kBackgroundDepth);
  const glm::vec3 centre(0, 0, -distance);
  for (int y = 0; y < int(height); ++y) {
    for (int x = 0; x < int(width); ++x) {
      const glm::vec3 d = pixelRay(s.frame, x, y);
      const float b = glm::dot(-centre, d);
      const float c = glm::dot(centre, centre) - sphereRadius * sphereRadius;
      const float disc = b * b - c;
      float depth = 0;
      glm::vec3 normal(0);
      if (disc >= 0) {
        const float hit = glm::dot(centre, d) - std::sqrt(disc);
        depth = hit * -d.z;
        normal = glm::normalize(hit * d - centre);
      } else if (planeDepth > 0) {
        depth = planeDepth;
        normal = glm::vec3(0, 0, 1);
      } else {
        continue;
      }
      const std::size_t i = std::size_t(y) * width + x;
      const float pixels = s.frame.focalPixels * s.frame.particleRadius / depth;
      s.exactDepth[i] = depth;
      s.normals[i] = normal;
      s.depth[i] = glm::vec4(depth - roughness * s.frame.particleRadius * bumps(x, y, std::max(pixels, 1.0f), seed), 1,
                             0, 0);
    }
  }
  return s;
}

/// Depth `depthAt(x, y)` on the whole w x h frame or, with `disk`, on a centred disk of radius
/// 0.4 h (the rest background); exactDepth is the same depth, normals are left empty.
template <class DepthAt>
DepthScene flatScene(std::uint32_t w, std::uint32_t h, DepthAt depthAt, bool disk) {
  DepthScene s;
  s.frame = testFrame(w, h);
  s.depth.assign(std::size_t(w) * h, glm::vec4(kBackgroundDepth, 0, 0, 0));
  s.exactDepth.assign(s.depth.size(), kBackgroundDepth);
  for (int y = 0; y < int(h); ++y)
    for (int x = 0; x < int(w); ++x) {
      const float dx = x - w / 2.0f, dy = y - h / 2.0f;
      if (disk && dx * dx + dy * dy > 0.16f * h * h) continue;
      const std::size_t i = std::size_t(y) * w + x;
      s.depth[i] = glm::vec4(depthAt(x, y), 1, 0, 0);
      s.exactDepth[i] = s.depth[i].x;
    }
  return s;
}

/// Constant depth 5 on the 64 x 48 frame or a disk of it (see flatScene).
inline DepthScene constantScene(bool disk) {
  return flatScene(64, 48, [](int, int) { return 5.0f; }, disk);
}

/// 96 x 72: a plane facing the camera at depth 3, roughened by one particle radius (0.02) with
/// features of two pixels (a particle radius is 0.66 pixels there); exactDepth is the plane.
inline DepthScene roughPlaneScene() {
  DepthScene s = flatScene(96, 72, [](int x, int y) { return 3.0f - 0.02f * bumps(x, y, 2.0f, 3); }, false);
  s.exactDepth.assign(s.depth.size(), 3.0f);
  return s;
}

/// 96 x 72: two planes facing the camera, at depth 3 (columns 0..47) and 3.5 (48..95), 25
/// particle radii apart, each roughened by one particle radius with features of three pixels;
/// exactDepth holds the planes.
inline DepthScene depthStepScene() {
  DepthScene s = flatScene(96, 72, [](int x, int) { return x < 48 ? 3.0f : 3.5f; }, false);
  for (int y = 0; y < 72; ++y)
    for (int x = 0; x < 96; ++x) s.depth[y * 96 + x].x -= 0.02f * bumps(x, y, 3.0f, 7);
  return s;
}

/// `{name, iterations, strength}`; -1 takes the filter's default.
inline SmoothingOptions filterOptions(const std::string& name, float strength = -1, int iterations = -1) {
  return {name, iterations, strength};
}

/// The registry entry of filter `name` (surfaceFilters()); throws when there is none.
inline const SurfaceFilterInfo& filterInfo(const std::string& name) {
  for (const SurfaceFilterInfo& info : surfaceFilters())
    if (info.name == name) return info;
  throw InputError("no surface filter '" + name + "'");
}

/// The names of surfaceFilters(), for a suite parameterised over every filter.
inline std::vector<std::string> surfaceFilterNameList() {
  std::vector<std::string> names;
  for (const SurfaceFilterInfo& info : surfaceFilters()) names.emplace_back(info.name);
  return names;
}

/// A test name for filter `name`: "curvature-flow" becomes "curvature_flow".
inline std::string filterTestName(std::string name) {
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
}

/// Runs `options`' filter on `device` (its frame set to the scene's) and returns its output.
inline std::vector<glm::vec4> smoothOn(ScreenDevice& device, const DepthScene& scene, const SmoothingOptions& options) {
  device.setFrame(scene.frame);
  const ScreenImage in = device.createFrameImage(), out = device.createFrameImage();
  device.upload(in, scene.depth);
  createSurfaceFilter(options)->apply(device, in, out);
  return device.download(out);
}

/// Runs `options`' filter on the CPU reference and returns its output.
inline std::vector<glm::vec4> smoothOnCpu(const DepthScene& scene, const SmoothingOptions& options) {
  CpuScreenDevice device;
  return smoothOn(device, scene, options);
}

/// Mean |5-point Laplacian| of value(i) (pixel i = y * width + x) over the pixels off the frame's
/// edge for which counts(i) holds.
template <class Value, class Counts>
double meanAbsLaplacian(const ScreenFrame& frame, Value value, Counts counts) {
  const std::uint32_t w = frame.width, h = frame.height;
  double sum = 0;
  int count = 0;
  for (std::uint32_t y = 1; y + 1 < h; ++y)
    for (std::uint32_t x = 1; x + 1 < w; ++x) {
      const std::size_t i = y * w + x;
      if (!counts(i)) continue;
      sum += std::abs(4 * value(i) - value(i - 1) - value(i + 1) - value(i - w) - value(i + w));
      ++count;
    }
  return sum / count;
}

/// Mean |5-point Laplacian| of the depth `d` over the pixels whose 4-neighbourhood is foreground
/// in `d` (the surface's own curvature included).
inline double depthRoughness(const std::vector<glm::vec4>& d, const DepthScene& s) {
  const std::size_t w = s.frame.width;
  return meanAbsLaplacian(
      s.frame, [&](std::size_t j) { return double(d[j].x); },
      [&](std::size_t i) {
        return d[i].y >= 0.5f && d[i - 1].y >= 0.5f && d[i + 1].y >= 0.5f && d[i - w].y >= 0.5f && d[i + w].y >= 0.5f;
      });
}

/// Mean |5-point Laplacian| of the depth's deviation from the exact depth (the noise, not the
/// surface's own curvature) over the pixels of a continuous surface: whose four neighbours are
/// foreground with exact depths within 0.05 (2.5 particle radii) of theirs.
inline double noiseRoughness(const std::vector<glm::vec4>& d, const DepthScene& s) {
  const std::size_t w = s.frame.width;
  return meanAbsLaplacian(
      s.frame, [&](std::size_t j) { return double(d[j].x) - s.exactDepth[j]; },
      [&](std::size_t i) {
        bool continuous = s.depth[i].y > 0.5f;
        for (std::size_t j : {i - 1, i + 1, i - w, i + w})
          continuous = continuous && s.depth[j].y > 0.5f && std::abs(s.exactDepth[j] - s.exactDepth[i]) < 0.05f;
        return continuous;
      });
}

/// Root mean square of depth - exact depth over the foreground pixels where the z of the
/// analytic unit normal lies in [minFacing, maxFacing) (z = 1 faces the eye; near 0 the view
/// rays graze the surface, where a depth error is no surface error). Needs the scene's normals.
inline double rmsError(const std::vector<glm::vec4>& d, const DepthScene& s, float minFacing = -2.0f,
                       float maxFacing = 2.0f) {
  double sum = 0;
  int count = 0;
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (s.depth[i].y < 0.5f || s.normals[i].z < minFacing || s.normals[i].z >= maxFacing) continue;
    const double e = d[i].x - s.exactDepth[i];
    sum += e * e;
    ++count;
  }
  return std::sqrt(sum / count);
}

/// The largest |out - input depth| over the pixels at least `margin` pixels inside the frame.
inline double worstChange(const std::vector<glm::vec4>& out, const DepthScene& s, int margin = 0) {
  const int w = int(s.frame.width), h = int(s.frame.height);
  double worst = 0;
  for (int y = margin; y < h - margin; ++y)
    for (int x = margin; x < w - margin; ++x) {
      const std::size_t i = std::size_t(y) * w + x;
      worst = std::max(worst, double(std::abs(out[i].x - s.depth[i].x)));
    }
  return worst;
}

/// The smallest and largest depth of the foreground pixels of `s` in `d`.
inline std::pair<float, float> foregroundRange(const std::vector<glm::vec4>& d, const DepthScene& s) {
  float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
  for (std::size_t i = 0; i < d.size(); ++i)
    if (s.depth[i].y > 0.5f) lo = std::min(lo, d[i].x), hi = std::max(hi, d[i].x);
  return {lo, hi};
}

}  // namespace flipscope::testing
