// FrameRenderer's brick pool takes what the frames it rendered fill, not the whole budget: it
// begins at 3 slots, grows (reallocated, twice its slots at least) when a frame needs more, and
// stops at the budget's pool. Growing drops the bricks it held; the images do not change.
#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <set>

#include "RaycastScenes.h"
#include "raycast/CpuRaycaster.h"
#include "streaming/SyntheticBrickSource.h"

namespace flipscope {
namespace {

constexpr int kFrames = 4;

struct WaveTank {
  std::shared_ptr<SyntheticBrickSource> source =
      std::make_shared<SyntheticBrickSource>(32, glm::uvec3(4, 4, 2), kFrames, 0.3);
  RenderSettings settings = testing::smallSettings();

  std::unique_ptr<FrameRenderer> renderer() const {
    return std::make_unique<FrameRenderer>(source, std::make_unique<CpuRaycaster>(), settings);
  }
  Camera camera() const {
    return frameOnBox(renderer()->occupiedBounds(0, kFrames - 1), double(settings.width) / settings.height, {0, 0, 1});
  }
  std::size_t bricks(int frame) const { return source->frame(frame)->bricks.size(); }
  std::size_t allBricks() const {
    std::size_t n = 0;
    for (int f = 0; f < kFrames; ++f) n += bricks(f);
    return n;
  }
};

bool sameHits(const RenderResult& a, const RenderResult& b) {
  return a.hits.size() == b.hits.size() &&
         std::memcmp(a.hits.data(), b.hits.data(), a.hits.size() * sizeof(RayHit)) == 0;
}

/// Each frame rendered alone, by a fresh renderer: what every render of it must equal.
std::vector<RenderResult> aloneImages(const WaveTank& tank, const Camera& camera) {
  std::vector<RenderResult> alone;
  for (int f = 0; f < kFrames; ++f) alone.push_back(tank.renderer()->render(f, camera));
  return alone;
}

/// Renders every frame `rounds` times in order: each converges to its image alone, the pool never
/// shrinks, and `check` sees each result. The pool's slots at the end.
template <class Check>
std::uint32_t renderRounds(FrameRenderer& renderer, const Camera& camera, int rounds,
                           const std::vector<RenderResult>& alone, Check&& check) {
  std::uint32_t slots = 0;
  for (int round = 0; round < rounds; ++round)
    for (int f = 0; f < kFrames; ++f) {
      const RenderResult result = renderer.render(f, camera);
      EXPECT_TRUE(result.stats.converged);
      EXPECT_TRUE(sameHits(result, alone[std::size_t(f)])) << "round " << round << ", frame " << f;
      EXPECT_GE(renderer.poolLayout().slots, slots) << "a pool never shrinks";
      slots = renderer.poolLayout().slots;
      check(f, result);
    }
  return slots;
}

TEST(FrameRendererPool, TakesWhatAFrameFillsAndKeepsItWarm) {
  const WaveTank tank;
  const Camera camera = tank.camera();
  auto renderer = tank.renderer();
  EXPECT_EQ(renderer->poolLayout().slots, 3u);  // nothing rendered yet

  const RenderResult cold = renderer->render(0, camera);
  ASSERT_TRUE(cold.stats.converged);
  ASSERT_GT(tank.bricks(0), 6u);
  EXPECT_EQ(renderer->poolLayout().slots, tank.bricks(0));
  EXPECT_EQ(cold.stats.poolBytes, renderer->poolLayout().bytes());
  EXPECT_LT(cold.stats.poolBytes, tank.settings.gpuBudgetBytes / 4);
  EXPECT_EQ(cold.stats.bricksEvicted, 0u);

  const RenderResult warm = renderer->render(0, camera);  // the pool holds the frame: no growth
  EXPECT_EQ(warm.stats.bricksUploaded, 0u);
  EXPECT_EQ(warm.stats.passes, 1);
  EXPECT_EQ(renderer->poolLayout().slots, tank.bricks(0));
  EXPECT_TRUE(sameHits(cold, warm));
}

TEST(FrameRendererPool, GrowsForMoreFramesWithTheSameImages) {
  const WaveTank tank;
  const Camera camera = tank.camera();
  auto renderer = tank.renderer();
  const std::uint32_t slots =
      renderRounds(*renderer, camera, 3, aloneImages(tank, camera), [](int, const RenderResult&) {});
  // The budget holds every frame: once grown, the pool keeps them all, as a full-budget pool did.
  EXPECT_GE(slots, tank.allBricks());
  EXPECT_LE(slots, 2 * tank.allBricks());
  for (int f = 0; f < kFrames; ++f) {
    const RenderResult result = renderer->render(f, camera);
    EXPECT_EQ(result.stats.bricksUploaded, 0u) << "frame " << f;
    EXPECT_EQ(result.stats.bricksEvicted, 0u) << "frame " << f;
  }
}

TEST(FrameRendererPool, GrowsWhileTheFrameBegunHoldsBricks) {
  // Narrow views upload a few bricks of a frame; a later wide view of it finds some resident
  // while the pool must grow for the rest. The pool it grows into holds none of them.
  const WaveTank tank;
  const Camera wide = tank.camera();
  std::vector<Camera> cameras{wide};
  for (double side : {-1.0, 1.0}) {
    Camera narrow = wide;
    narrow.fovYDegrees = 8;
    narrow.target += side * 0.3 * wide.right() * glm::distance(wide.eye, wide.target) * 0.2;
    cameras.push_back(narrow);
  }
  std::map<std::pair<int, std::size_t>, RenderResult> alone;
  for (int f = 0; f < kFrames; ++f)
    for (std::size_t c = 0; c < cameras.size(); ++c) alone[{f, c}] = tank.renderer()->render(f, cameras[c]);

  auto renderer = tank.renderer();
  const std::vector<std::pair<int, std::size_t>> views{{0, 1}, {1, 1}, {0, 2}, {2, 0}, {0, 0}, {3, 1},
                                                       {1, 0}, {3, 0}, {2, 2}, {0, 0}, {1, 2}, {3, 2}};
  // Below the budget nothing is evicted (EXPECT below): a frame holds bricks in the pool exactly
  // when it was rendered since the pool last grew.
  std::set<int> sinceGrowth;
  std::uint64_t grownWithResidents = 0;
  for (const auto& [f, c] : views) {
    const std::uint32_t slotsBefore = renderer->poolLayout().slots;
    const RenderResult result = renderer->render(f, cameras[c]);
    ASSERT_TRUE(result.stats.converged);
    EXPECT_EQ(result.stats.bricksEvicted, 0u);
    EXPECT_TRUE(sameHits(result, alone[{f, c}])) << "frame " << f << ", camera " << c;
    if (renderer->poolLayout().slots > slotsBefore) {
      grownWithResidents += sinceGrowth.contains(f);
      sinceGrowth.clear();
    }
    sinceGrowth.insert(f);
  }
  EXPECT_GT(grownWithResidents, 0u) << "no view grew the pool while its frame held bricks";
}

TEST(FrameRendererPool, StopsAtTheBudget) {
  WaveTank tank;
  const Camera camera = tank.camera();
  const PoolLayout least = tank.renderer()->poolLayout();
  // Room for a frame and a half, with the ring's 35% (PoolLayout::forBudget): growth stops there
  // and frames evict each other, still converging to the same images.
  const std::uint64_t perSlot = least.slotBytes() + least.storedCellsPerSlot() * 35 / 100 * 2;
  tank.settings.gpuBudgetBytes = perSlot * (tank.bricks(0) * 3 / 2);
  auto renderer = tank.renderer();
  const std::vector<RenderResult> alone = aloneImages(tank, camera);
  const std::uint32_t slots = renderRounds(*renderer, camera, 2, alone, [&](int f, const RenderResult& result) {
    EXPECT_LE(result.stats.poolBytes, tank.settings.gpuBudgetBytes);
    EXPECT_GE(renderer->poolLayout().slots, tank.bricks(f));
  });
  EXPECT_LT(slots, tank.allBricks());
  const RenderResult again = renderer->render(0, camera);
  EXPECT_GT(again.stats.bricksUploaded, 0u) << "frame 0 was evicted by the others";
  EXPECT_EQ(renderer->poolLayout().slots, slots);
  EXPECT_TRUE(sameHits(again, alone[0]));
}

}  // namespace
}  // namespace flipscope
