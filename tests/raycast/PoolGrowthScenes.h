// A wave tank (SyntheticBrickSource) of a few frames for the tests of FrameRenderer's growing
// brick pool (PoolGrowthTest on the CPU reference, PoolGrowthGlTest on OpenGL): the images of a
// renderer whose pool grew and dropped its bricks equal those of a fresh renderer.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <map>
#include <set>

#include "RaycastScenes.h"
#include "streaming/SyntheticBrickSource.h"

namespace flipscope::testing {

constexpr int kFrames = 4;

struct WaveTank {
  std::shared_ptr<SyntheticBrickSource> source =
      std::make_shared<SyntheticBrickSource>(32, glm::uvec3(4, 4, 2), kFrames, 0.3);
  RenderSettings settings = smallSettings();
  std::function<std::unique_ptr<RaycastDevice>()> device;  ///< a fresh device for each renderer

  std::unique_ptr<FrameRenderer> renderer() const {
    return std::make_unique<FrameRenderer>(source, device(), settings);
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

inline bool sameHits(const RenderResult& a, const RenderResult& b) {
  return a.hits.size() == b.hits.size() &&
         std::memcmp(a.hits.data(), b.hits.data(), a.hits.size() * sizeof(RayHit)) == 0;
}

/// Views of every frame, wide and narrow: narrow views upload a few bricks of a frame, and a
/// later wide view of it finds some resident while the pool must grow for the rest (the pool it
/// grows into holds none of them). Each image equals the view's image from a fresh renderer.
inline void expectGrownPoolViewsEqualTheirImagesAlone(const WaveTank& tank) {
  const Camera wide = tank.camera();
  std::vector<Camera> cameras{wide};
  for (double side : {-1.0, 1.0}) {
    Camera narrow = wide;
    narrow.fovYDegrees = 8;
    narrow.target += side * 0.06 * glm::distance(wide.eye, wide.target) * wide.right();  // left, right
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
    EXPECT_TRUE(result.stats.converged);
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

}  // namespace flipscope::testing
