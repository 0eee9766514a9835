// The fast CPU ray-caster (TiledCpuRaycaster) against the reference (CpuRaycaster) on random
// scenes: every combination of jitter, sphere radius, attributes, thickness and foam mode, a
// cold frame (bricks streamed in over passes, so rays resume) and a warm one from another
// camera. The stated tolerance (raycast/TiledCpuRaycaster.h):
//  - a pixel hits on one side and misses on the other for at most 1 in 500 pixels (a ray
//    grazing a sphere, or an edge where the DDA and the reference's point location part);
//  - where both hit, 99.5% of the pixels agree to 1e-4 relative in t and depth, 1e-3 in the
//    normal, exactly in the attribute, to 1% of the saturation (plus 0.05 cells) in thickness
//    and to 1e-3 in foam opacity;
//  - and the image differs from the reference somewhere only through those tolerances: the
//    mean depth error stays below 1e-4 relative.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <sstream>

#include "RaycastScenes.h"
#include "TestSupport.h"
#include "preprocess/VectorSource.h"
#include "raycast/CpuRaycaster.h"
#include "raycast/TiledCpuRaycaster.h"
#include "streaming/BrickSource.h"

namespace flipscope {
namespace {

using testing::TempDir;

struct SceneCase {
  std::uint32_t seed;
  float radius;
  float jitter;
  bool attribute;
  float thicknessCells;
  FoamMode foam;
};

std::ostream& operator<<(std::ostream& os, const SceneCase& c) {
  return os << "seed " << c.seed << " radius " << c.radius << " jitter " << c.jitter << " attribute " << c.attribute
            << " thickness " << c.thicknessCells << " foam " << foamModeName(c.foam);
}

/// How two images of the same scene compare, pixel by pixel.
struct Agreement {
  int hitMiss = 0;  ///< hit on one side, miss (or pending) on the other
  int bothHit = 0;
  int close = 0;    ///< of bothHit, within every tolerance
  double depthError = 0;  ///< summed relative depth error over bothHit
  std::string firstFar;

  Agreement(const std::vector<RayHit>& reference, const std::vector<RayHit>& fast, float thicknessCells) {
    for (std::size_t i = 0; i < reference.size(); ++i) {
      const RayHit &a = reference[i], &b = fast[i];
      if ((a.status == kRayHit) != (b.status == kRayHit)) {
        ++hitMiss;
        continue;
      }
      if (a.status != kRayHit) {
        if (std::abs(a.foam - b.foam) <= 1e-3f) continue;
        ++hitMiss;  // a miss whose foam differs counts against the same budget
        continue;
      }
      ++bothHit;
      const float scale = std::max(1.0f, a.t);
      depthError += std::abs(a.depth - b.depth) / std::max(1e-6f, std::abs(a.depth));
      const bool ok = std::abs(a.t - b.t) <= 1e-4f * scale &&
                      std::abs(a.depth - b.depth) <= 1e-4f * std::max(1.0f, std::abs(a.depth)) &&
                      glm::distance(glm::vec3(a.normal), glm::vec3(b.normal)) <= 1e-3f && a.normal.w == b.normal.w &&
                      std::abs(a.thickness - b.thickness) <= 0.01f * thicknessCells + 0.05f &&
                      std::abs(a.foam - b.foam) <= 1e-3f && a.brickIndex == b.brickIndex;
      close += ok;
      if (!ok && firstFar.empty()) {
        std::ostringstream os;
        os << "pixel " << i << ": t " << a.t << "/" << b.t << " depth " << a.depth << "/" << b.depth << " normal.w "
           << a.normal.w << "/" << b.normal.w << " thickness " << a.thickness << "/" << b.thickness << " foam "
           << a.foam << "/" << b.foam << " brick " << a.brickIndex << "/" << b.brickIndex;
        firstFar = os.str();
      }
    }
  }
};

class TiledCpuRaycasterScenes : public ::testing::TestWithParam<SceneCase> {};

TEST_P(TiledCpuRaycasterScenes, EqualsTheReferenceColdAndWarm) {
  const SceneCase& c = GetParam();
  TempDir dir("tiled");
  const float extent = 96.0f;
  // A dense ball (a liquid body, for thickness) in a clustered cloud with scattered particles
  // (isolated cells, which the foam classification finds).
  std::vector<glm::vec3> particles = testing::randomParticles(20000, c.seed, extent);
  const auto ball = testing::ballParticles({40.0f + float(c.seed), 50.0f, 45.0f}, 14.0f);
  particles.insert(particles.end(), ball.begin(), ball.end());
  std::vector<std::vector<glm::vec3>> velocities;
  if (c.attribute) {
    std::mt19937 rng(c.seed);
    std::uniform_real_distribution<float> speed(0.0f, 3.0f);
    velocities.emplace_back();
    for (std::size_t i = 0; i < particles.size(); ++i) velocities[0].push_back({speed(rng), 0.0f, 0.0f});
  }
  BrickStore store = testing::makeStore(dir / "store", {particles}, extent, 32, velocities);

  RenderSettings settings = testing::smallSettings(96, 64);
  settings.radius = c.radius;
  settings.jitter = c.jitter;
  settings.thicknessSaturationCells = c.thicknessCells;
  settings.foam.mode = c.foam;
  settings.gpuBudgetBytes = 6ull << 20;  // a pool smaller than the scene: several passes, rays resume
  auto source = std::make_shared<StoreBrickSource>(store);
  FrameRenderer reference(source, std::make_unique<CpuRaycaster>(), settings);
  FrameRenderer fast(source, std::make_unique<TiledCpuRaycaster>(), settings);
  ASSERT_EQ(fast.device().name().rfind("CPU (", 0), 0u) << fast.device().name();

  std::mt19937 rng(c.seed * 7919u);
  std::uniform_real_distribution<double> angle(0, 6.283);
  for (const char* frame : {"cold", "warm"}) {
    SCOPED_TRACE(std::string(frame) + " frame, " + (std::ostringstream() << c).str());
    Camera camera = frameOnBox(Box{{0, 0, 0}, {extent, extent, extent}}, 1.5);
    const double a = angle(rng);
    camera.eye = camera.target + glm::dvec3(std::cos(a), 0.5, std::sin(a)) * 120.0;
    const RenderResult expected = reference.render(0, camera);
    const RenderResult actual = fast.render(0, camera);
    ASSERT_TRUE(expected.stats.converged && actual.stats.converged);
    const Agreement agreement(expected.hits, actual.hits, c.thicknessCells);
    const int pixels = int(expected.hits.size());
    EXPECT_GT(agreement.bothHit, pixels / 10) << "the scene must fill the image";
    EXPECT_LE(agreement.hitMiss, pixels / 500);
    EXPECT_GE(agreement.close, agreement.bothHit - agreement.bothHit / 200) << agreement.firstFar;
    EXPECT_LT(agreement.depthError / std::max(1, agreement.bothHit), 1e-4);
  }
}

/// The fast device with the interface's upload of one brick after the other.
class UploadingOneAtATime final : public TiledCpuRaycaster {
 public:
  void uploadBricks(std::span<const BrickUpload> uploads) override { RaycastDevice::uploadBricks(uploads); }
};

// A pass's bricks go into the pool on every core at once (CpuRaycaster::uploadBricks): each
// slot's arrays, march tables and ring range are its own, so the image is the one of uploads
// one at a time, bit for bit, with attributes, with foam classified after the upload, and
// through a pool small enough to evict.
TEST(TiledCpuRaycaster, BricksUploadedOnEveryCoreAtOnceGiveTheImageOfUploadsOneAtATime) {
  TempDir dir("upload");
  const float extent = 96.0f;
  std::vector<glm::vec3> particles = testing::randomParticles(20000, 9, extent);
  const auto ball = testing::ballParticles({45.0f, 50.0f, 40.0f}, 16.0f);
  particles.insert(particles.end(), ball.begin(), ball.end());
  std::vector<std::vector<glm::vec3>> velocities(1);
  for (std::size_t i = 0; i < particles.size(); ++i) velocities[0].push_back({float(i % 97) / 32.0f, 0.0f, 0.0f});
  BrickStore store = testing::makeStore(dir / "store", {particles}, extent, 32, velocities);
  auto source = std::make_shared<StoreBrickSource>(store);
  for (const FoamMode foam : {FoamMode::Keep, FoamMode::Volume})
    for (const bool tight : {false, true}) {
      RenderSettings settings = testing::smallSettings(96, 64);
      settings.radius = 1.2f;
      settings.jitter = 0.3f;
      settings.thicknessSaturationCells = 24.0f;
      settings.foam.mode = foam;
      if (tight) {  // a pool of about 6 slots, for a frame of 27 bricks: passes evict
        const PoolLayout roomy =
            PoolLayout::forBudget(32, storedOverlap(settings), true, 64ull << 20, foam != FoamMode::Keep, true,
                                  sphereReach(settings.radius, settings.jitter));
        settings.gpuBudgetBytes = roomy.bytes() / roomy.slots * 6;
      }
      const std::uint64_t budget = settings.gpuBudgetBytes;
      FrameRenderer oneAtATime(source, std::make_unique<UploadingOneAtATime>(), settings);
      FrameRenderer atOnce(source, std::make_unique<TiledCpuRaycaster>(), settings);
      for (const double a : {0.4, 2.5}) {
        SCOPED_TRACE(std::string("foam ") + foamModeName(foam) + ", budget " + std::to_string(budget) + ", angle " +
                     std::to_string(a));
        Camera camera = frameOnBox(Box{{0, 0, 0}, {extent, extent, extent}}, 1.5);
        camera.eye = camera.target + glm::dvec3(std::cos(a), 0.5, std::sin(a)) * 120.0;
        const RenderResult expected = oneAtATime.render(0, camera);
        const RenderResult actual = atOnce.render(0, camera);
        ASSERT_TRUE(expected.stats.converged && actual.stats.converged);
        EXPECT_EQ(actual.stats.bricksUploaded, expected.stats.bricksUploaded);
        EXPECT_EQ(actual.stats.bricksEvicted, expected.stats.bricksEvicted);
        if (a == 0.4) {  // the cold frame: batches of several bricks, and through the tight pool, evictions
          EXPECT_GT(actual.stats.bricksUploaded, std::uint64_t(actual.stats.passes));
          if (tight) {
            EXPECT_GT(actual.stats.bricksEvicted, 0u);
          }
        }
        ASSERT_EQ(actual.hits.size(), expected.hits.size());
        EXPECT_EQ(std::memcmp(actual.hits.data(), expected.hits.data(), actual.hits.size() * sizeof(RayHit)), 0);
        EXPECT_GT(std::count_if(actual.hits.begin(), actual.hits.end(),
                                [](const RayHit& h) { return h.status == kRayHit && h.normal.w > 0; }),
                  std::ptrdiff_t(actual.hits.size() / 20))
            << "hits with attributes must fill some of the image";
      }
    }
}

INSTANTIATE_TEST_SUITE_P(RandomScenes, TiledCpuRaycasterScenes,
                         ::testing::Values(SceneCase{1, 1.0f, 0.0f, false, 0.0f, FoamMode::Keep},
                                           SceneCase{2, 1.4f, 0.3f, false, 0.0f, FoamMode::Keep},
                                           SceneCase{3, 0.9f, 0.25f, true, 0.0f, FoamMode::Keep},
                                           SceneCase{4, 1.2f, 0.3f, true, 24.0f, FoamMode::Remove},
                                           SceneCase{5, 1.0f, 0.3f, false, 64.0f, FoamMode::Volume},
                                           SceneCase{6, 1.9f, 0.0f, true, 64.0f, FoamMode::Volume},
                                           // Reach 4, beyond the other scenes' 1 and 2: slabs of 81 cells.
                                           SceneCase{7, 3.6f, 0.3f, true, 0.0f, FoamMode::Keep}));

}  // namespace
}  // namespace flipscope
