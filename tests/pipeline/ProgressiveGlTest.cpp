// Progressive frames on the GPU (Mesa llvmpipe here): the display pass (pipeline/glsl/
// Progressive.glsl) and the resumed passes give what the CPU reference gives.
#include <gtest/gtest.h>

#include "GlTestSupport.h"
#include "ProgressiveScenes.h"
#include "raycast/CpuRaycaster.h"
#include "raycast/GpuRaycaster.h"

namespace flipscope {
namespace {

using testing::GatedBrickSource;

TEST(ProgressiveFramesGl, DisplayEqualsTheCpuReference) {
  auto source = std::make_shared<GatedBrickSource>();
  std::optional<FramePipeline> gpu;
  try {
    gpu.emplace(source, DeviceChoice::Gpu, GatedBrickSource::settings(), SurfaceSettings{});
  } catch (const gl::Unavailable& e) {
    FLIPSCOPE_SKIP_WITHOUT_GL(e.what());
  }
  FramePipeline cpu(source, std::make_unique<CpuRaycaster>(), GatedBrickSource::settings(), SurfaceSettings{});
  ASSERT_NE(gpu->displayBuffer(), nullptr);
  ASSERT_EQ(cpu.displayBuffer(), nullptr);
  const Camera camera = GatedBrickSource::camera();
  // Frame 0 to the end, then frame 1 with its bricks held back: pending rays keep frame 0.
  for (FramePipeline* p : {&*gpu, &cpu}) {
    p->begin(0, camera);
    testing::advanceToEnd(*p);
    ASSERT_TRUE(p->finished());
  }
  auto compare = [](const std::vector<glm::vec4>& a, const std::vector<glm::vec4>& b) {
    EXPECT_EQ(a.size(), b.size());
    int different = 0;
    for (std::size_t i = 0; i < a.size(); ++i) different += glm::length(a[i] - b[i]) > 0.05f;
    return different;
  };
  EXPECT_LE(compare(gpu->downloadDisplay(), cpu.downloadDisplay()), 3);
  source->setOpen(false);
  for (FramePipeline* p : {&*gpu, &cpu}) {
    p->begin(1, camera);
    p->advance(1.0);
  }
  EXPECT_LE(compare(gpu->downloadDisplay(), cpu.downloadDisplay()), 3);
  source->setOpen(true);
  for (FramePipeline* p : {&*gpu, &cpu}) testing::advanceToEnd(*p);
  EXPECT_LE(compare(gpu->downloadDisplay(), cpu.downloadDisplay()), 3);
}

}  // namespace
}  // namespace flipscope
