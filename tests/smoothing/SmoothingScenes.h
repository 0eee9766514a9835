// Depth images for the smoothing tests: analytic scenes (a sphere, planes, a step) seen by a
// camera at the origin looking down -z, optionally roughened by particle-sized bumps, and
// helpers to run a filter on a device. Depth is linear camera depth in world units.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
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
  f.size = glm::uvec4(width, height, 0, 0);
  f.forward = glm::vec4(0, 0, -1, t);
  f.right = glm::vec4(1, 0, 0, float(width) / float(height));
  f.up = glm::vec4(0, 1, 0, 0);
  f.worldUp = glm::vec4(0, 1, 0, 0);
  f.focalPixels = float(height) / (2.0f * t);
  f.particleRadius = radius;
  f.cellSize = radius;
  return f;
}

/// The unit ray through the centre of pixel (x, y) (mirrors ssPixelRay).
inline glm::vec3 pixelRay(const ScreenFrame& f, int x, int y) {
  const float sx = ((x + 0.5f) / f.size.x * 2 - 1) * f.forward.w * f.right.w;
  const float sy = (1 - (y + 0.5f) / f.size.y * 2) * f.forward.w;
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

/// Runs `filter` on the CPU reference and returns its output.
inline std::vector<glm::vec4> smoothOnCpu(const DepthScene& scene, const SmoothingOptions& options) {
  CpuScreenDevice device;
  device.setFrame(scene.frame);
  const ScreenImage in = device.createFrameImage(), out = device.createFrameImage();
  device.upload(in, scene.depth);
  createSurfaceFilter(options)->apply(device, in, out);
  return device.download(out);
}

}  // namespace flipscope::testing
