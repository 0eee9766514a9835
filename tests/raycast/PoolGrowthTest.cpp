// FrameRenderer's brick pool takes what the frames it rendered fill, not the whole budget: it
// begins at 3 slots, grows (reallocated, twice its slots at least) when a frame needs more, and
// stops at the budget's pool. Growing drops the bricks it held; the images do not change.
#include <gtest/gtest.h>

#include "PoolGrowthScenes.h"
#include "raycast/CpuRaycaster.h"

namespace flipscope {
namespace {

using testing::kFrames;
using testing::sameHits;
using testing::WaveTank;

/// The wave tank on the CPU reference ray-caster.
WaveTank cpuTank() {
  WaveTank tank;
  tank.device = [] { return std::make_unique<CpuRaycaster>(); };
  return tank;
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
  const WaveTank tank = cpuTank();
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
  const WaveTank tank = cpuTank();
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
  testing::expectGrownPoolViewsEqualTheirImagesAlone(cpuTank());
}

TEST(FrameRendererPool, StopsAtTheBudget) {
  WaveTank tank = cpuTank();
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
