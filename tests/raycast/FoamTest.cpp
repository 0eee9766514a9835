// Foam (Reichl et al. 2014 §3.5) on the CPU reference: the classification against a brute
// force, an isolated particle against a block, the threshold at its boundary, the kinds' foam
// bits kept, the volume's opacity against the analytic emission-absorption of a uniform slab, and
// `remove` leaving a liquid body's image exactly as it is without its spray.
#include <gtest/gtest.h>

#include "FoamScenes.h"
#include "RaycastScenes.h"
#include "TestSupport.h"
#include "raycast/CpuRaycaster.h"

namespace flipscope {
namespace {

using testing::cpuRenderer;
using testing::FoamBrickShape;
using testing::TempDir;

TEST(FoamClassification, RandomBricksEqualABruteForce) {
  std::uint32_t seed = 1;
  for (float radius : {1.0f, 1.5f, 2.3f}) {
    for (float threshold : {0.2f, 0.5f}) {
      FoamBrickShape shape;
      shape.radius = radius;
      CpuRaycaster device;
      std::vector<ConvertedBrick> bricks;
      const auto foam = testing::classifyRandomBricks(device, shape, threshold, seed++, bricks);
      std::size_t foamCells = 0, setCells = 0;
      for (std::size_t b = 0; b < bricks.size(); ++b) {
        const auto expected = testing::bruteForceFoam(bricks[b], shape, threshold);
        ASSERT_EQ(foam[b].size(), expected.size());
        for (std::size_t i = 0; i < expected.size(); ++i) {
          ASSERT_EQ(foam[b][i], expected[i]) << "radius " << radius << " threshold " << threshold << " brick " << b
                                             << " sub-brick " << i;
          for (int w = 0; w < 4; ++w) {
            foamCells += std::popcount(expected[i][w]);
            setCells += std::popcount(bricks[b].bits.subBricks[i][w]);
          }
        }
      }
      // Both kinds of cells are there: the test compares foam and liquid alike.
      EXPECT_GT(foamCells, setCells / 50) << radius << " " << threshold;
      EXPECT_LT(foamCells, setCells * 9 / 10) << radius << " " << threshold;
    }
  }
}

/// Classifies one brick on the CPU and tells whether stored cell `s` is foam.
struct OneBrick {
  FoamBrickShape shape;
  CpuRaycaster device;
  ConvertedBrick brick;
  std::vector<glm::uvec4> foam;

  void classify(const std::function<bool(glm::ivec3)>& set, float threshold) {
    brick = testing::foamTestBrick(shape, set);
    const PoolLayout layout = testing::foamTestLayout(shape, 1);
    device.allocatePool(layout);
    device.uploadBrick(0, 0, brick);
    const std::uint32_t slot = 0;
    device.classifyFoam({&slot, 1}, testing::foamTestParams(shape, 1, threshold, layout.subBricksPerSlot));
    foam = device.readFoam(0);
  }
  bool isFoam(glm::ivec3 s) const {
    const glm::ivec3 cell = s - int(shape.overlap);
    return bitBrickBitSet(foam[bitBrickSubBrickIndex(cell, shape.brickSize, shape.overlap)],
                          bitBrickBitIndex(cell, shape.overlap));
  }
};

TEST(FoamClassification, AnIsolatedParticleIsFoamAndOneInsideABlockIsNot) {
  OneBrick one;
  const glm::ivec3 lone(30, 9, 11);
  one.classify([&](glm::ivec3 s) { return s == lone || glm::all(glm::lessThan(glm::abs(s - 12), glm::ivec3(5))); },
               0.2f);
  EXPECT_TRUE(one.isFoam(lone));
  EXPECT_FALSE(one.isFoam({12, 12, 12})) << "the block's centre";
  EXPECT_FALSE(one.isFoam({16, 16, 16})) << "the block's corner: 7 of 18 neighbours";
  EXPECT_FALSE(one.isFoam({0, 0, 0})) << "not set";
}

TEST(FoamClassification, TheThresholdIsHonouredAtItsBoundary) {
  // Radius 1.5: 18 neighbours. Threshold 0.5: foam below 9 set neighbours.
  const glm::ivec3 centre(20, 20, 20);
  std::vector<glm::ivec3> neighbours;
  for (int z = -1; z <= 1; ++z)
    for (int y = -1; y <= 1; ++y)
      for (int x = -1; x <= 1; ++x)
        if ((x || y || z) && x * x + y * y + z * z <= 2) neighbours.emplace_back(x, y, z);
  ASSERT_EQ(neighbours.size(), 18u);
  for (int set : {8, 9}) {
    OneBrick one;
    one.classify([&](glm::ivec3 s) {
      if (s == centre) return true;
      for (int i = 0; i < set; ++i)
        if (s == centre + neighbours[std::size_t(i)]) return true;
      return false;
    }, 0.5f);
    EXPECT_EQ(one.isFoam(centre), set < 9) << set << " of 18 neighbours set";
  }
  for (float threshold : {0.0f, 1.0f}) {
    OneBrick one;
    one.classify([&](glm::ivec3 s) { return s == centre; }, threshold);
    EXPECT_EQ(one.isFoam(centre), threshold > 0) << "threshold " << threshold;
  }
}

TEST(FoamClassification, KeepsTheUploadedKindBitsAndAddsTheClassifiedCells) {
  const FoamBrickShape shape;
  CpuRaycaster device;
  ConvertedBrick brick = testing::foamTestBrick(shape, [](glm::ivec3 s) {
    return glm::all(glm::lessThan(glm::abs(s - 12), glm::ivec3(4))) || s == glm::ivec3(30, 30, 30);
  });
  brick.foamKinds.assign(brick.bits.subBricks.size(), glm::uvec4(0));
  const glm::ivec3 kindCell = glm::ivec3(12, 12, 12) - int(shape.overlap);  // inside the block: not classified
  const std::uint32_t bit = bitBrickBitIndex(kindCell, shape.overlap);
  const std::uint32_t subBrick = bitBrickSubBrickIndex(kindCell, shape.brickSize, shape.overlap);
  brick.foamKinds[subBrick][int(bit >> 5)] |= 1u << (bit & 31);
  const PoolLayout layout = testing::foamTestLayout(shape, 1);
  device.allocatePool(layout);
  device.uploadBrick(0, 0, brick);
  EXPECT_EQ(device.readFoam(0), brick.foamKinds) << "the upload writes the kinds' bits";
  const std::uint32_t slot = 0;
  device.classifyFoam({&slot, 1}, testing::foamTestParams(shape, 1, 0.2f, layout.subBricksPerSlot));
  auto expected = testing::bruteForceFoam(brick, shape, 0.2f);
  expected[subBrick][int(bit >> 5)] |= 1u << (bit & 31);
  EXPECT_EQ(device.readFoam(0), expected);
}

Camera lookingDown(glm::dvec3 target, double height) {
  Camera camera;
  camera.target = target;
  camera.eye = target + glm::dvec3(0, 0, height);
  camera.up = {0, 1, 0};
  return camera;
}

TEST(VolumetricFoam, AUniformSlabGivesTheAnalyticEmissionAbsorption) {
  // A slab 40 cells thick of density 1/8 (the 4^3 blocks on the stored lattice hold 8 cells),
  // seen straight down through its middle: opacity 1 - exp(-sigma * density * 40).
  TempDir dir("foam-slab");
  const BrickStore store = testing::makeStore(dir.path(), {testing::foamSlab({4, 4, 34}, {92, 92, 74})}, 96.0f);
  for (float extinction : {0.05f, 0.1f, 0.3f}) {
    RenderSettings settings = testing::smallSettings(3, 3);
    settings.radius = 1.5f;
    settings.jitter = 0;
    settings.foam.extinction = extinction;
    settings.foam.opacityStop = 1.0f;
    ASSERT_EQ(storedOverlap(settings), 6u) << "the blocks are on the lattice of 2 mod 4";
    auto renderer = cpuRenderer(store, settings);
    const RenderResult result = renderer->render(0, lookingDown({48, 48, 48}, 100));
    ASSERT_TRUE(result.stats.converged);
    EXPECT_GT(result.stats.bricksClassified, 0u);
    const RayHit& centre = result.hits[4];
    EXPECT_EQ(centre.status, kRayMiss) << "foam cells are no spheres";
    const double expected = 1.0 - std::exp(-double(extinction) * 0.125 * 40.0);
    // The 2 cells outside the slab's top, where the trilinear density falls off, lie in a clear
    // mip block and are skipped: 1/80 of the optical depth.
    EXPECT_NEAR(centre.foam, expected, 0.01) << "extinction " << extinction;
  }
}

TEST(VolumetricFoam, TheRayStopsAtTheOpacityLimitAndAtTheSurface) {
  TempDir dir("foam-stop");
  // Foam above a solid floor: the foam in front of the floor is counted, the floor is hit.
  std::vector<glm::vec3> particles = testing::foamSlab({4, 4, 50}, {92, 92, 70});
  for (const glm::vec3& p : testing::ballParticles({48, 48, 10}, 30)) particles.push_back(p);
  const BrickStore store = testing::makeStore(dir.path(), {particles}, 96.0f);
  RenderSettings settings = testing::smallSettings(3, 3);
  settings.radius = 1.5f;
  settings.foam.extinction = 0.1f;
  settings.foam.opacityStop = 1.0f;
  const RenderResult thin = cpuRenderer(store, settings)->render(0, lookingDown({48, 48, 48}, 100));
  EXPECT_EQ(thin.hits[4].status, kRayHit) << "the ball behind the foam";
  EXPECT_NEAR(thin.hits[4].foam, 1.0 - std::exp(-0.1 * 0.125 * 20.0), 0.01);
  settings.foam.extinction = 50.0f;
  settings.foam.opacityStop = 0.95f;
  const RenderResult dense = cpuRenderer(store, settings)->render(0, lookingDown({48, 48, 48}, 100));
  EXPECT_EQ(dense.hits[4].status, kRayMiss) << "opaque foam ends the ray";
  EXPECT_GE(dense.hits[4].foam, 0.95f);
  EXPECT_LT(dense.hits[4].foam, 1.0f);
}

TEST(FoamRemove, LeavesTheBodysImageAndRemovesTheSpray) {
  TempDir dir("foam-remove");
  const std::vector<glm::vec3> body = testing::ballParticles({48, 48, 40}, 22);
  std::vector<glm::vec3> withSpray = body;
  for (const glm::vec3& p : testing::sprayPlane(10, 86, 75)) withSpray.push_back(p);
  for (const glm::vec3& p : testing::sprayPlane(13, 86, 68)) withSpray.push_back(p);
  const BrickStore bodyStore = testing::makeStore(dir.path() / "body", {body}, 96.0f);
  const BrickStore sprayStore = testing::makeStore(dir.path() / "spray", {withSpray}, 96.0f);
  RenderSettings settings = testing::smallSettings();
  settings.radius = 1.5f;
  const Camera camera = lookingDown({48, 48, 40}, 120);
  // The body alone with the same settings: the thickness trace reads 4^3 blocks on the lattice of
  // the stored cells, and the border (storedOverlap) depends on the foam mode.
  settings.foam.mode = FoamMode::Remove;
  const RenderResult alone = cpuRenderer(bodyStore, settings)->render(0, camera);
  const RenderResult removed = cpuRenderer(sprayStore, settings)->render(0, camera);
  settings.foam.mode = FoamMode::Keep;
  const RenderResult kept = cpuRenderer(sprayStore, settings)->render(0, camera);
  std::size_t sprayPixels = 0, bodyPixels = 0;
  for (std::size_t i = 0; i < alone.hits.size(); ++i) {
    const RayHit &a = alone.hits[i], &k = kept.hits[i], &r = removed.hits[i];
    sprayPixels += k.status != a.status || k.t != a.t;
    bodyPixels += a.status == kRayHit;
    ASSERT_EQ(r.status, a.status) << "pixel " << i;
    if (a.status != kRayHit) continue;
    EXPECT_EQ(r.t, a.t) << "pixel " << i;
    EXPECT_EQ(r.normal, a.normal) << "pixel " << i;
    EXPECT_EQ(r.thickness, a.thickness) << "pixel " << i;
    EXPECT_EQ(r.foam, 0.0f);
  }
  EXPECT_GT(bodyPixels, 1000u);
  EXPECT_GT(sprayPixels, 100u) << "kept, the spray covers part of the image";
}

}  // namespace
}  // namespace flipscope
