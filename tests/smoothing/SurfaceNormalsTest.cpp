// Normal reconstruction from depth (smoothing/SurfaceNormals.h) on analytic spheres, and the
// normals of every filter's smoothed sphere against the analytic ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "smoothing/SmoothingScenes.h"
#include "smoothing/SurfaceNormals.h"

namespace flipscope {
namespace {

using testing::DepthScene;

struct AngleError {
  double meanDegrees = 0;
  double p95Degrees = 0;
};

/// The normals reconstructed from `depth` (the scene's frame) on the CPU reference.
std::vector<glm::vec4> normalsOnCpu(const DepthScene& scene, const std::vector<glm::vec4>& depth) {
  CpuScreenDevice device;
  device.setFrame(scene.frame);
  const ScreenImage in = device.createFrameImage(), out = device.createFrameImage();
  device.upload(in, depth);
  reconstructNormals(device, in, out);
  return device.download(out);
}

/// Angles between reconstructed and analytic normals over the sphere's pixels that face the
/// camera (view angle below 70 degrees, away from the silhouette).
AngleError normalError(const DepthScene& scene, const std::vector<glm::vec4>& depth) {
  const auto normals = normalsOnCpu(scene, depth);
  std::vector<double> angles;
  for (int y = 0; y < int(scene.frame.height); ++y)
    for (int x = 0; x < int(scene.frame.width); ++x) {
      const std::size_t i = std::size_t(y) * scene.frame.width + x;
      const glm::vec3 exact = scene.normals[i];
      if (exact.z < 0.99f && glm::dot(exact, -testing::pixelRay(scene.frame, x, y)) < 0.34f) continue;
      if (scene.depth[i].y < 0.5f || exact == glm::vec3(0, 0, 1)) continue;  // background and plane
      EXPECT_EQ(normals[i].w, 1.0f);
      const double c = std::clamp(double(glm::dot(glm::vec3(normals[i]), exact)), -1.0, 1.0);
      angles.push_back(std::acos(c) * 180.0 / 3.14159265358979);
    }
  EXPECT_GT(angles.size(), 500u);
  AngleError e;
  for (double a : angles) e.meanDegrees += a / angles.size();
  std::sort(angles.begin(), angles.end());
  e.p95Degrees = angles[angles.size() * 95 / 100];
  return e;
}

TEST(SurfaceNormals, ExactSphereDepthGivesTheAnalyticNormals) {
  const DepthScene scene = testing::sphereScene(128, 96, 0.0f);
  const AngleError e = normalError(scene, scene.depth);
  EXPECT_LT(e.meanDegrees, 0.5);
  EXPECT_LT(e.p95Degrees, 1.0);
}

TEST(SurfaceNormals, NormalsFaceTheCameraAndIgnoreTheBackground) {
  const DepthScene scene = testing::sphereScene(64, 48, 0.0f, 3.0f, 0.8f, 6.0f);
  const auto normals = normalsOnCpu(scene, scene.depth);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) {
      const glm::vec4 n = normals[y * 64 + x];
      ASSERT_LT(glm::dot(glm::vec3(n), testing::pixelRay(scene.frame, x, y)), 0.0f) << x << "," << y;
      ASSERT_NEAR(glm::length(glm::vec3(n)), 1.0f, 1e-4f);
    }
  // The plane behind the sphere's silhouette is not differenced across the depth edge: it keeps
  // its own normal (0, 0, 1) right next to the sphere.
  int planeNextToSphere = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 1; x < 63; ++x) {
      const std::size_t i = y * 64 + x;
      if (scene.normals[i] != glm::vec3(0, 0, 1) || scene.normals[i + 1] == glm::vec3(0, 0, 1)) continue;
      ++planeNextToSphere;
      EXPECT_GT(normals[i].z, 0.999f) << x << "," << y;
    }
  EXPECT_GT(planeNextToSphere, 5);
}

class FilteredSphereNormals : public ::testing::TestWithParam<std::string> {};

TEST_P(FilteredSphereNormals, ComeCloseToTheAnalyticNormals) {
  const DepthScene scene = testing::sphereScene(160, 120, 1.0f);
  const AngleError rough = normalError(scene, scene.depth);
  const AngleError smooth = normalError(scene, testing::smoothOnCpu(scene, {GetParam()}));
  if (GetParam() == "none") {
    EXPECT_DOUBLE_EQ(smooth.meanDegrees, rough.meanDegrees);
    return;
  }
  EXPECT_LT(smooth.meanDegrees, 0.6 * rough.meanDegrees) << GetParam() << ": rough " << rough.meanDegrees;
  EXPECT_LT(smooth.meanDegrees, 12.0) << GetParam();
  EXPECT_LT(smooth.p95Degrees, 30.0) << GetParam();
}

INSTANTIATE_TEST_SUITE_P(AllFilters, FilteredSphereNormals, ::testing::ValuesIn(testing::surfaceFilterNameList()),
                         [](const auto& info) { return testing::filterTestName(info.param); });

}  // namespace
}  // namespace flipscope
