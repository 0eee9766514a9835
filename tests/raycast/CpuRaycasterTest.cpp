// The CPU reference ray-caster and the frame loop: a ball renders as a disk with the analytic
// depth; the traversal (octree, bricks, mip skipping) finds the same nearest spheres as a brute
// force over every particle's sphere; cold equals warm; a tiny pool converges by eviction.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <set>
#include <sstream>
#include <utility>

#include "RaycastScenes.h"
#include "TestSupport.h"
#include "core/Error.h"
#include "raycast/CpuRaycaster.h"
#include "raycast/FirstBricks.h"
#include "streaming/Jitter.h"
#include "streaming/SyntheticBrickSource.h"

namespace flipscope {
namespace {

// The first pixel where two images differ, for failure messages.
std::string firstDifference(const std::vector<RayHit>& a, const std::vector<RayHit>& b) {
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::memcmp(&a[i], &b[i], sizeof(RayHit)) == 0) continue;
    std::ostringstream os;
    os << "pixel " << i << ": status " << a[i].status << "/" << b[i].status << " t " << a[i].t << "/" << b[i].t
       << " depth " << a[i].depth << "/" << b[i].depth << " brick " << a[i].brickIndex << "/" << b[i].brickIndex
       << " normal.w " << a[i].normal.w << "/" << b[i].normal.w << " thickness " << a[i].thickness << "/"
       << b[i].thickness;
    return os.str();
  }
  return "identical";
}

using testing::cpuRenderer;
using testing::TempDir;

TEST(CpuRaycaster, BallRendersAsDiskWithAnalyticDepth) {
  TempDir dir("ball");
  const testing::BallScene ball;
  BrickStore store = ball.makeStore(dir / "store");
  auto renderer = cpuRenderer(store, ball.settings());
  const RenderResult result = renderer->render(0, ball.camera());
  ASSERT_TRUE(result.stats.converged);
  ball.expectDiskWithAnalyticDepth(result);
}

// Brute force over every set cell's sphere: the nearest hit distance in cells.
struct BruteForce {
  std::vector<glm::vec3> centres;
  float radius;
  float nearest(glm::vec3 eye, glm::vec3 dir) const {
    float best = -1;
    for (const glm::vec3& c : centres) {
      const glm::vec3 oc = eye - c;
      const float b = glm::dot(oc, dir), disc = b * b - (glm::dot(oc, oc) - radius * radius);
      if (disc < 0) continue;
      const float t = -b - std::sqrt(disc);
      if (t >= 0 && (best < 0 || t < best)) best = t;
    }
    return best;
  }
};

class CpuRaycasterScenes : public ::testing::TestWithParam<int> {};

TEST_P(CpuRaycasterScenes, FindsTheNearestSphereOfABruteForce) {
  const int seed = GetParam();
  TempDir dir("cloud");
  const float extent = 80.0f;
  const auto particles = testing::randomParticles(6000, std::uint32_t(seed), extent);
  BrickStore store = testing::makeStore(dir / "store", {particles}, extent, 32);
  RenderSettings settings = testing::smallSettings(96, 64);
  settings.radius = seed % 2 ? 1.4f : 0.9f;
  settings.jitter = seed % 3 ? 0.3f : 0.0f;
  settings.foam.mode = FoamMode::Keep;  // the brute force tests every sphere
  auto renderer = cpuRenderer(store, settings);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> angle(0, 6.283);
  Camera camera = frameOnBox(Box{{0, 0, 0}, {extent, extent, extent}}, 1.5);
  const double a = angle(rng);
  camera.eye = camera.target + glm::dvec3(std::cos(a), 0.6, std::sin(a)) * 110.0;
  const RenderResult result = renderer->render(0, camera);
  ASSERT_TRUE(result.stats.converged);

  // The oracle's spheres: every occupied cell, jittered like the shader (frame 0).
  BruteForce oracle{{}, settings.radius};
  std::set<std::tuple<int, int, int>> cells;
  for (const glm::vec3& p : particles) cells.insert({int(p.x), int(p.y), int(p.z)});
  for (auto [x, y, z] : cells) {
    glm::vec3 c = glm::vec3(x, y, z) + 0.5f;
    if (settings.jitter > 0) c += cellJitter(glm::uvec3(x, y, z), 0, settings.jitter);
    oracle.centres.push_back(c);
  }
  int both = 0, agree = 0, mismatch = 0;
  for (std::uint32_t y = 0; y < settings.height; ++y) {
    for (std::uint32_t x = 0; x < settings.width; ++x) {
      const RayHit& hit = result.hits[y * settings.width + x];
      const glm::vec3 dir(camera.pixelRay(x, y, settings.width, settings.height));
      const float expected = oracle.nearest(glm::vec3(camera.eye), dir);
      if ((expected >= 0) != (hit.status == kRayHit)) {
        ++mismatch;
        continue;
      }
      if (expected < 0) continue;
      ++both;
      agree += std::abs(hit.t - expected) < 2e-3f * std::max(1.0f, expected);
    }
  }
  // Rays grazing an empty brick can miss spheres that reach into it from a brick they never
  // enter (Raycast.glsl: at most k cells at brick faces): a few silhouette pixels.
  EXPECT_GT(both, 200);
  EXPECT_LE(mismatch, int(settings.width * settings.height) / 100) << "hit/miss disagreements";
  EXPECT_GE(agree, both - both / 100) << "of " << both << " pixels hit on both sides";
}

INSTANTIATE_TEST_SUITE_P(RandomScenes, CpuRaycasterScenes, ::testing::Values(1, 2, 3, 4));

TEST(CpuRaycaster, HitsCarryTheirCellsAttribute) {
  // Two balls: the left one slow, the right one fast; speeds quantize to 0 and 65535 (§3.2).
  TempDir dir("attribute");
  const auto slow = testing::ballParticles({30, 48, 48}, 12), fast = testing::ballParticles({66, 48, 48}, 12);
  std::vector<glm::vec3> particles = slow, velocities(slow.size(), glm::vec3(1, 0, 0));
  particles.insert(particles.end(), fast.begin(), fast.end());
  velocities.resize(particles.size(), glm::vec3(0, 0, 3));
  BrickStore store = testing::makeStore(dir / "store", {particles}, 96.0f, 32, {velocities});
  ASSERT_EQ(store.header().attribute, AttributeKind::Speed);
  RenderSettings settings = testing::smallSettings();
  auto renderer = cpuRenderer(store, settings);
  Camera camera;
  camera.target = {48, 48, 48};
  camera.eye = {48, 48, 170};
  const RenderResult result = renderer->render(0, camera);
  int left = 0, right = 0;
  for (std::uint32_t y = 0; y < settings.height; ++y) {
    for (std::uint32_t x = 0; x < settings.width; ++x) {
      const RayHit& hit = result.hits[y * settings.width + x];
      if (hit.status != kRayHit) continue;
      const bool isLeft = x < settings.width / 2;
      (isLeft ? left : right)++;
      EXPECT_EQ(hit.normal.w, isLeft ? 0.0f : 1.0f) << x << "," << y;
    }
  }
  EXPECT_GT(left, 100);
  EXPECT_GT(right, 100);
}

TEST(FrameRenderer, ColdFrameConvergesToTheWarmImageInOnePass) {
  TempDir dir("warm");
  BrickStore store = testing::makeStore(dir / "store", {testing::randomParticles(8000, 7, 64.0f)}, 64.0f, 32);
  RenderSettings loop = testing::smallSettings();
  loop.prefetch = false;  // the request loop alone streams the cold frame
  auto renderer = cpuRenderer(store, loop);
  const Camera camera = frameOnBox(renderer->occupiedBounds(0), 128.0 / 72.0);
  const RenderResult cold = renderer->render(0, camera);
  const RenderResult warm = renderer->render(0, camera);
  EXPECT_GT(cold.stats.passes, 1);
  EXPECT_GT(cold.stats.bricksUploaded, 0u);
  EXPECT_EQ(warm.stats.passes, 1);
  EXPECT_EQ(warm.stats.bricksUploaded, 0u);
  ASSERT_EQ(cold.hits.size(), warm.hits.size());
  EXPECT_EQ(0, std::memcmp(cold.hits.data(), warm.hits.data(), cold.hits.size() * sizeof(RayHit)))
      << firstDifference(cold.hits, warm.hits);
}

/// Renders `camera` cold with the request loop alone and with the prefetch, and checks that the
/// prefetch saves passes for the same image, streaming the bricks of the loop's first pass
/// (which the walk finds) or, where those are at least half the view, all in view. Returns the
/// prefetching render's statistics and the loop's.
std::pair<RenderStats, RenderStats> expectPrefetchSavesPasses(const BrickStore& store, const Camera& camera,
                                                              const RenderSettings& settings) {
  RenderSettings loopSettings = settings;
  loopSettings.prefetch = false;
  const RenderResult expected = cpuRenderer(store, loopSettings)->render(0, camera);
  const RenderResult result = cpuRenderer(store, settings)->render(0, camera);
  EXPECT_TRUE(result.stats.converged);
  EXPECT_GT(expected.stats.passes, 1);
  EXPECT_LT(result.stats.passes, expected.stats.passes);
  EXPECT_EQ(0, std::memcmp(expected.hits.data(), result.hits.data(), result.hits.size() * sizeof(RayHit)))
      << firstDifference(expected.hits, result.hits);
  // The walk finds what the loop's first pass requests: a loop stopped after that pass (at the
  // second) has streamed just those.
  RenderSettings firstPass = loopSettings;
  firstPass.maxPasses = 2;
  const RenderResult stopped = cpuRenderer(store, firstPass)->render(0, camera);
  const std::vector<std::uint32_t> walked =
      firstBricksAlongRays(camera, firstPass.width, firstPass.height, 1, store.header(), store.frame(0)->octree);
  EXPECT_EQ(walked.size(), stopped.stats.bricksUploaded);
  EXPECT_LE(result.stats.bricksUploaded, std::max<std::uint64_t>(expected.stats.bricksUploaded, 2 * walked.size()));
  return {result.stats, expected.stats};
}

TEST(FrameRenderer, BricksStreamedBeforeTheFirstPassSaveAPassAndGiveTheRequestLoopsImage) {
  TempDir dir("prefetch");
  BrickStore store = testing::makeStore(dir / "store", {testing::randomParticles(20000, 4, 96.0f)}, 96.0f, 32);
  const Box bounds = cpuRenderer(store, testing::smallSettings())->occupiedBounds(0);
  const Camera whole = frameOnBox(bounds, 128.0 / 72.0);
  // Outside one face, looking along a row of bricks near an edge; and from inside the data.
  Camera row = whole;
  row.eye = bounds.min + bounds.extent() * glm::dvec3(-0.1, 1.0 / 6, 1.0 / 6);
  row.target = row.eye + glm::dvec3(1, 0, 0);
  row.up = {0, 1, 0};
  row.fovYDegrees = 15;
  Camera inside = whole;
  inside.eye = bounds.min + bounds.extent() * 0.45;
  for (const Camera& camera : {row, inside}) expectPrefetchSavesPasses(store, camera, testing::smallSettings());
  // The whole frame in view, 27 bricks, is less than twice the first pass's: all streamed, one pass.
  const RenderStats all = expectPrefetchSavesPasses(store, whole, testing::smallSettings()).first;
  EXPECT_EQ(all.passes, 1);
  EXPECT_EQ(all.bricksUploaded, all.frameBricks);
}

TEST(FrameRenderer, BehindAnOpaqueFrontOnlyTheFirstPassesBricksAreStreamedAhead) {
  // A solid block of 3 x 3 x 4 bricks (a particle every other cell, spheres of 1.5 cells
  // closing it, no thickness traced behind a hit) seen from above: the rays stop in its top 9
  // bricks, and the 27 in view below them are far more than as many again.
  TempDir dir("prefetch-block");
  std::vector<glm::vec3> block;
  for (int z = 0; z < 64; ++z)
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 48; ++x) block.push_back(glm::vec3(x, y, z) * 2.0f + 1.0f);
  BrickStore store = testing::makeStore(dir / "store", {block}, 128.0f, 32);
  RenderSettings spheres = testing::smallSettings();
  spheres.radius = 1.5f;
  spheres.thicknessSaturationCells = 0;
  Camera camera;
  camera.eye = {48, 48, 260};
  camera.target = {48, 48, 0};
  camera.fovYDegrees = 30;
  const auto [prefetching, loop] = expectPrefetchSavesPasses(store, camera, spheres);
  EXPECT_EQ(prefetching.bricksUploaded, loop.bricksUploaded) << "no brick streamed that no ray reaches";
  EXPECT_LE(loop.bricksUploaded, loop.frameBricks / 2) << "no ray reaches the block's lower half";
}

TEST(FirstBricks, RaysThatMeetNoBrickFindNoneAndTheStrideKeepsTheRaysFew) {
  TempDir dir("first-bricks");
  BrickStore store = testing::makeStore(dir / "store", {testing::randomParticles(20000, 4, 96.0f)}, 96.0f, 32);
  const Box bounds = cpuRenderer(store, testing::smallSettings())->occupiedBounds(0);
  Camera away = frameOnBox(bounds, 1.0);
  away.target = away.eye + (away.eye - away.target);  // looking away from the data
  EXPECT_TRUE(firstBricksAlongRays(away, 64, 64, 1, store.header(), store.frame(0)->octree).empty());
  const Camera towards = frameOnBox(bounds, 1.0);
  const std::vector<std::uint32_t> found =
      firstBricksAlongRays(towards, 64, 64, 1, store.header(), store.frame(0)->octree);
  ASSERT_FALSE(found.empty());
  EXPECT_TRUE(std::is_sorted(found.begin(), found.end()));
  EXPECT_LT(found.back(), store.frame(0)->bricks.size());
  EXPECT_EQ(firstBrickStride(128, 72), 1u);
  EXPECT_EQ(firstBrickStride(1280, 720), 8u);  // 160 x 90 rays
  EXPECT_EQ(firstBrickStride(3840, 2160), 23u);
}

TEST(FrameRenderer, TinyPoolConvergesByEvictionToTheSameImage) {
  TempDir dir("tiny");
  BrickStore store = testing::makeStore(dir / "store", {testing::randomParticles(20000, 9, 96.0f)}, 96.0f, 32);
  RenderSettings big = testing::smallSettings();
  RenderSettings tiny = big;
  tiny.gpuBudgetBytes = PoolLayout::forBudget(32, storedOverlap(big), false, 64ull << 20, true).slotBytes() * 3;
  auto reference = cpuRenderer(store, big);
  auto starved = cpuRenderer(store, tiny);
  const Camera camera = frameOnBox(reference->occupiedBounds(0), 128.0 / 72.0);
  const RenderResult expected = reference->render(0, camera);
  const RenderResult result = starved->render(0, camera);
  ASSERT_TRUE(result.stats.converged);
  EXPECT_EQ(starved->settings().gpuBudgetBytes, tiny.gpuBudgetBytes);
  EXPECT_GT(result.stats.bricksEvicted, 0u);
  EXPECT_LE(result.stats.bricksResident, 3u);
  EXPECT_GT(result.stats.passes, expected.stats.passes);
  // A pool too small for the frame makes thickness best effort; the hits stay exact.
  std::vector<RayHit> withoutThickness = result.hits, expectedWithout = expected.hits;
  int thinner = 0;
  for (std::size_t i = 0; i < withoutThickness.size(); ++i) {
    EXPECT_GE(withoutThickness[i].thickness, 0.0f);
    EXPECT_LE(withoutThickness[i].thickness, expectedWithout[i].thickness);
    thinner += withoutThickness[i].thickness < expectedWithout[i].thickness;
    withoutThickness[i].thickness = expectedWithout[i].thickness = 0;
  }
  EXPECT_EQ(0, std::memcmp(expectedWithout.data(), withoutThickness.data(), withoutThickness.size() * sizeof(RayHit)))
      << firstDifference(expectedWithout, withoutThickness) << " (" << thinner << " thinner)";
}

TEST(FrameRenderer, RejectsMissingFramesAndBadSettings) {
  TempDir dir("bad");
  BrickStore store = testing::makeStore(dir / "store", {testing::ballParticles({20, 20, 20}, 5)}, 40.0f, 32);
  auto renderer = cpuRenderer(store, testing::smallSettings());
  EXPECT_THROW(renderer->render(5, frameOnBox(renderer->occupiedBounds(0), 1.0)), InputError);
  RenderSettings settings = testing::smallSettings();
  settings.radius = 9;
  EXPECT_THROW(cpuRenderer(store, settings), InputError);
  settings = testing::smallSettings();
  settings.gpuBudgetBytes = 1000;
  EXPECT_THROW(cpuRenderer(store, settings), InputError);
}

TEST(CpuRaycaster, APoolThatCannotBeMadeLeavesNoSlots) {
  // RaycastDevice::allocatePool: the layout is recorded last, so a device whose new pool could
  // not be made refuses every upload (slot < slots) instead of writing past its arrays.
  CpuRaycaster device;
  const PoolLayout layout = PoolLayout::forBudget(32, 1, true, 64ull << 20);
  device.allocatePool(layout);
  EXPECT_EQ(device.pool().layout.slots, layout.slots);
  EXPECT_EQ(device.pool().attributes.size(), layout.attributeCapacity);
  PoolLayout impossible = layout;
  impossible.slots *= 2;
  impossible.attributeCapacity = std::uint64_t(1) << 62;  // beyond what a vector can hold
  EXPECT_ANY_THROW(device.allocatePool(impossible));
  EXPECT_EQ(device.pool().layout.slots, 0u);
}

TEST(FrameRenderer, ConvergesOverASyntheticSource) {
  // No store: the wave tank's bricks, frame indices and domain come from the source itself.
  auto source = std::make_shared<SyntheticBrickSource>(32, glm::uvec3(4, 4, 2), 2, 0.3);
  const StoreHeader& h = source->header();
  const RenderSettings settings = testing::smallSettings();
  FrameRenderer renderer(source, std::make_unique<CpuRaycaster>(), settings);
  EXPECT_EQ(&renderer.source(), source.get());
  // The water fills the tank's footprint from the floor up to below the highest wave.
  const Box bounds = renderer.occupiedBounds(0, 1);
  const double cell = h.cellSize;
  EXPECT_NEAR(bounds.min.x, h.origin.x, 1e-9);
  EXPECT_NEAR(bounds.min.y, h.origin.y, 1e-9);
  EXPECT_NEAR(bounds.min.z, h.origin.z, 1e-9);
  EXPECT_NEAR(bounds.max.x, h.origin.x + 128 * cell, 1e-9);
  EXPECT_NEAR(bounds.max.y, h.origin.y + 128 * cell, 1e-9);
  EXPECT_GT(bounds.max.z, 0.45 * 64 * cell);
  EXPECT_LE(bounds.max.z, (0.65 * 64 + 1) * cell);

  const Camera camera = frameOnBox(bounds, double(settings.width) / settings.height, {0, 0, 1});
  for (int frame : {0, 1}) {
    const RenderResult cold = renderer.render(frame, camera);
    ASSERT_TRUE(cold.stats.converged) << "frame " << frame;
    EXPECT_GT(cold.stats.bricksUploaded, 0u);
    EXPECT_EQ(cold.stats.frameBricks, source->frame(frame)->bricks.size());
    std::size_t hits = 0;
    for (const RayHit& hit : cold.hits) {
      ASSERT_NE(hit.status, kRayPending);
      hits += hit.status == kRayHit;
    }
    // frameOnBox fits the box with a margin: the water covers a good part of the image, not all.
    EXPECT_GT(hits, cold.hits.size() / 5) << "frame " << frame;
    EXPECT_LT(hits, cold.hits.size()) << "frame " << frame;
    const RenderResult warm = renderer.render(frame, camera);
    EXPECT_EQ(warm.stats.passes, 1);
    EXPECT_EQ(warm.stats.bricksUploaded, 0u);
    ASSERT_EQ(cold.hits.size(), warm.hits.size());
    EXPECT_EQ(0, std::memcmp(cold.hits.data(), warm.hits.data(), cold.hits.size() * sizeof(RayHit)))
        << firstDifference(cold.hits, warm.hits);
  }
  try {
    renderer.render(2, camera);
    FAIL() << "frame 2 rendered";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(source->name()), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace flipscope
