// Small stores for ray-casting tests: a ball of particles (analytic silhouette and depth) and
// random clustered clouds (randomParticles of preprocess/VectorSource.h), binned with the real preprocess into a
// TempDir.
#pragma once

#include <cmath>
#include <memory>
#include <random>

#include "preprocess/Convert.h"
#include "preprocess/VectorSource.h"
#include "raycast/Camera.h"
#include "raycast/CpuRaycaster.h"
#include "raycast/FrameRenderer.h"
#include "streaming/BrickSource.h"

namespace flipscope::testing {

/// Bins each frame's particles into a store at `dir` with cell size 1 over [0, extent)^3.
inline BrickStore makeStore(const std::filesystem::path& dir, const std::vector<std::vector<glm::vec3>>& frames,
                            float extent, std::uint32_t brickSize = 32,
                            const std::vector<std::vector<glm::vec3>>& velocities = {}) {
  ConvertOptions options;
  options.domain = Box{{0, 0, 0}, {extent, extent, extent}};
  options.cellSize = 1.0;
  options.brickSize = brickSize;
  options.progress = Progress::Mode::Silent;
  const AttributeKind attribute = velocities.empty() ? AttributeKind::None : AttributeKind::Speed;
  BrickStore store = BrickStore::createOrAppend(dir, makeStoreHeader(*options.domain, options, attribute));
  for (std::size_t f = 0; f < frames.size(); ++f) {
    VectorSource source(frames[f], velocities.empty() ? std::vector<glm::vec3>{} : velocities[f]);
    convertFrame(source, store, int(f), options);
  }
  return BrickStore::open(dir);
}

/// A FrameRenderer of `store` on the CPU reference ray-caster.
inline std::unique_ptr<FrameRenderer> cpuRenderer(const BrickStore& store, const RenderSettings& settings) {
  return std::make_unique<FrameRenderer>(std::make_shared<StoreBrickSource>(store), std::make_unique<CpuRaycaster>(),
                                         settings);
}

/// One particle at every cell centre within `radius` of `centre` (cell units = world units).
inline std::vector<glm::vec3> ballParticles(glm::vec3 centre, float radius) {
  std::vector<glm::vec3> out;
  const int lo = int(std::floor(-radius - 1)), hi = int(std::ceil(radius + 1));
  for (int z = lo; z <= hi; ++z)
    for (int y = lo; y <= hi; ++y)
      for (int x = lo; x <= hi; ++x) {
        const glm::vec3 p = glm::floor(centre) + glm::vec3(x, y, z) + 0.5f;
        if (glm::length(p - centre) <= radius) out.push_back(p);
      }
  return out;
}

inline RenderSettings smallSettings(std::uint32_t width = 128, std::uint32_t height = 72) {
  RenderSettings settings;
  settings.width = width;
  settings.height = height;
  settings.threads = 2;
  settings.gpuBudgetBytes = 64ull << 20;
  settings.cpuCacheBytes = 256ull << 20;
  return settings;
}

/// A ball of particles seen from +z: it must render as a disk whose depth lies between the
/// ball's and the ball grown by the sphere radius (spheres of radius 1 at cell centres within
/// the ball), with misses outside.
struct BallScene {
  glm::vec3 centre{48.3f, 47.6f, 48.1f};
  float radius = 26.0f;

  BrickStore makeStore(const std::filesystem::path& dir) const {
    return testing::makeStore(dir, {ballParticles(centre, radius)}, 96.0f);
  }
  RenderSettings settings() const {
    RenderSettings s = smallSettings();
    s.jitter = 0;
    s.radius = 1.0f;
    return s;
  }
  Camera camera() const {
    Camera c;
    c.eye = glm::dvec3(centre) + glm::dvec3(0, 0, 150);
    c.target = glm::dvec3(centre);
    return c;
  }
  void expectDiskWithAnalyticDepth(const RenderResult& result) const {
    const Camera cam = camera();
    int inside = 0, hits = 0;
    for (std::uint32_t y = 0; y < result.height; ++y) {
      for (std::uint32_t x = 0; x < result.width; ++x) {
        const RayHit& hit = result.hits[y * result.width + x];
        const glm::dvec3 dir = cam.pixelRay(x, y, result.width, result.height);
        const glm::dvec3 oc = cam.eye - glm::dvec3(centre);
        const double b = glm::dot(oc, dir);
        const auto entry = [&](double r) {
          const double disc = b * b - (glm::dot(oc, oc) - r * r);
          return disc < 0 ? -1.0 : -b - std::sqrt(disc);
        };
        // Cell centres lie within `radius`; spheres add 1 cell; quantization moves centres <= 0.87.
        const double innerEntry = entry(radius - 1.0), outerEntry = entry(radius + 1.9);
        hits += hit.status == kRayHit;
        if (innerEntry > 0) {
          ++inside;
          ASSERT_EQ(hit.status, kRayHit) << "pixel " << x << "," << y << " inside the disk";
          const double t = hit.depth / glm::dot(dir, cam.forward());  // back to distance along the ray
          EXPECT_GE(t, outerEntry - 1e-3) << x << "," << y;
          EXPECT_LE(t, innerEntry + 1e-3) << x << "," << y;
          EXPECT_GT(glm::dot(glm::dvec3(hit.normal), -dir), 0.0) << "normal faces the camera at " << x << "," << y;
        } else if (outerEntry < 0) {
          EXPECT_EQ(hit.status, kRayMiss) << "pixel " << x << "," << y << " outside the disk";
        }
      }
    }
    EXPECT_GT(inside, 500);
    EXPECT_GE(hits, inside);
  }
};

}  // namespace flipscope::testing
