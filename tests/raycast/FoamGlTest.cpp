// Foam (Reichl et al. 2014 §3.5) on the GPU (Mesa llvmpipe here): the classification pass
// against the brute force, and foam scenes rendered as the CPU reference renders them.
#include <gtest/gtest.h>

#include "FoamScenes.h"
#include "GlTestSupport.h"
#include "RaycastScenes.h"
#include "TestSupport.h"
#include "raycast/CpuRaycaster.h"
#include "raycast/GpuRaycaster.h"

namespace flipscope {
namespace {

using testing::FoamBrickShape;
using testing::TempDir;

std::unique_ptr<GpuRaycaster> gpuDevice(std::string& skip) {
  try {
    return std::make_unique<GpuRaycaster>();
  } catch (const gl::Unavailable& e) {
    skip = e.what();
    return nullptr;
  }
}

TEST(FoamClassificationGl, RandomBricksEqualABruteForce) {
  std::string skip;
  auto device = gpuDevice(skip);
  if (!device) FLIPSCOPE_SKIP_WITHOUT_GL(skip);
  std::uint32_t seed = 11;
  for (float radius : {1.0f, 1.5f, 2.3f}) {
    FoamBrickShape shape;
    shape.radius = radius;
    std::vector<ConvertedBrick> bricks;
    const auto foam = testing::classifyRandomBricks(*device, shape, 0.2f, seed++, bricks);
    for (std::size_t b = 0; b < bricks.size(); ++b) {
      const auto expected = testing::bruteForceFoam(bricks[b], shape, 0.2f);
      ASSERT_EQ(foam[b].size(), expected.size());
      for (std::size_t i = 0; i < expected.size(); ++i)
        ASSERT_EQ(foam[b][i], expected[i]) << "radius " << radius << " brick " << b << " sub-brick " << i;
    }
  }
}

TEST(FoamGl, ScenesRenderAsTheCpuReferenceRendersThem) {
  TempDir dir("foam-gl");
  std::vector<glm::vec3> particles = testing::ballParticles({48, 48, 40}, 22);
  for (const glm::vec3& p : testing::sprayPlane(10, 86, 75)) particles.push_back(p);
  for (const glm::vec3& p : testing::foamSlab({20, 20, 64}, {70, 60, 72})) particles.push_back(p);
  const BrickStore store = testing::makeStore(dir.path(), {particles}, 96.0f);
  Camera camera;
  camera.eye = {130, 110, 140};
  camera.target = {48, 48, 40};
  for (FoamMode mode : {FoamMode::Volume, FoamMode::Remove}) {
    RenderSettings settings = testing::smallSettings();
    settings.radius = 1.5f;
    settings.foam.mode = mode;
    std::string skip;
    auto gpu = gpuDevice(skip);
    if (!gpu) FLIPSCOPE_SKIP_WITHOUT_GL(skip);
    FrameRenderer onGpu(std::make_shared<StoreBrickSource>(store), std::move(gpu), settings);
    FrameRenderer onCpu(std::make_shared<StoreBrickSource>(store), std::make_unique<CpuRaycaster>(), settings);
    const RenderResult g = onGpu.render(0, camera), c = onCpu.render(0, camera);
    ASSERT_TRUE(g.stats.converged && c.stats.converged);
    // The foam volume is a sum of samples along the ray; a hardware GPU's rounding can move a
    // sample across a cell face (an NVIDIA H200 put one pixel of 9216 0.011 apart), so a few
    // pixels may differ by up to 0.05, and none by more.
    std::size_t mismatch = 0, foamy = 0, foamApart = 0;
    for (std::size_t i = 0; i < g.hits.size(); ++i) {
      mismatch += g.hits[i].status != c.hits[i].status;
      foamy += c.hits[i].foam > 0.01f;
      foamApart += std::abs(g.hits[i].foam - c.hits[i].foam) > 1e-3f;
      EXPECT_NEAR(g.hits[i].foam, c.hits[i].foam, 0.05f) << "pixel " << i;
      if (g.hits[i].status == kRayHit && c.hits[i].status == kRayHit) {
        EXPECT_NEAR(g.hits[i].t, c.hits[i].t, 1e-4f * c.hits[i].t) << "pixel " << i;
        EXPECT_NEAR(g.hits[i].thickness, c.hits[i].thickness, 1e-3f * (1 + c.hits[i].thickness)) << "pixel " << i;
      }
    }
    EXPECT_LE(mismatch, 2u) << foamModeName(mode);
    EXPECT_LE(foamApart, g.hits.size() / 1000) << foamModeName(mode) << ": pixels whose foam is over 1e-3 apart";
    if (mode == FoamMode::Volume) {
      EXPECT_GT(foamy, 200u);
    }
  }
}

}  // namespace
}  // namespace flipscope
