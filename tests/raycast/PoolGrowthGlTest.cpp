// FrameRenderer's growing brick pool on OpenGL (PoolGrowthTest runs the same on the CPU
// reference): the buffers reallocated as the pool grows hold what the next passes upload, and
// the images equal a fresh renderer's. Skips only when no EGL/OpenGL 4.5 context can be made.
#include <gtest/gtest.h>

#include "GlTestSupport.h"
#include "PoolGrowthScenes.h"
#include "raycast/GpuRaycaster.h"

namespace flipscope {
namespace {

TEST(FrameRendererPoolGl, GrowsWhileTheFrameBegunHoldsBricks) {
  try {
    GpuRaycaster probe;
  } catch (const gl::Unavailable& e) {
    FLIPSCOPE_SKIP_WITHOUT_GL(e.what());
  }
  testing::WaveTank tank;
  tank.device = [] { return std::make_unique<GpuRaycaster>(); };
  testing::expectGrownPoolViewsEqualTheirImagesAlone(tank);
}

}  // namespace
}  // namespace flipscope
