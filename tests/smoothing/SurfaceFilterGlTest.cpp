// Every surface filter on the GPU (OpenGL compute, Mesa llvmpipe here) against its CPU reference,
// on a roughened sphere in front of a plane at 128x72.
#include <gtest/gtest.h>

#include "GlTestSupport.h"

#include <memory>

#include "gl/EglContext.h"
#include "smoothing/GpuScreenDevice.h"
#include "smoothing/SmoothingScenes.h"

namespace flipscope {
namespace {

class SurfaceFilterGl : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    try {
      mContext = gl::EglContext::create();
    } catch (const gl::Unavailable& e) {
      FLIPSCOPE_SKIP_WITHOUT_GL(e.what());
    }
  }
  gl::EglContext mContext;
};

TEST_P(SurfaceFilterGl, GpuMatchesTheCpuReference) {
  const testing::DepthScene scene = testing::sphereScene(128, 72, 1.0f, 3.0f, 0.8f, 5.0f);
  const SmoothingOptions options{GetParam()};
  const auto cpu = testing::smoothOnCpu(scene, options);
  std::vector<glm::vec4> gpu;
  {
    GpuScreenDevice device("test");
    gpu = testing::smoothOn(device, scene, options);
  }
  ASSERT_EQ(gpu.size(), cpu.size());
  double worst = 0;
  for (std::size_t i = 0; i < cpu.size(); ++i) {
    ASSERT_EQ(gpu[i].y, cpu[i].y) << "mask differs at pixel " << i;
    worst = std::max(worst, double(std::abs(gpu[i].x - cpu[i].x)));
  }
  // Depths are about 3 to 5 world units; float rounding and fused multiply-adds differ.
  EXPECT_LT(worst, 2e-3) << GetParam();
}

INSTANTIATE_TEST_SUITE_P(AllFilters, SurfaceFilterGl, ::testing::ValuesIn(testing::surfaceFilterNameList()),
                         [](const auto& info) { return testing::filterTestName(info.param); });

}  // namespace
}  // namespace flipscope
