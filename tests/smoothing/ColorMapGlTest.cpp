// Colouring by attribute on the GPU (OpenGL compute, Mesa llvmpipe here) against the CPU
// reference: the shading pass over the attribute ramp for every colour map, in the liquid,
// spheres and lit-surface modes, with and without a colour range.
#include <gtest/gtest.h>

#include "GlTestSupport.h"

#include "gl/EglContext.h"
#include "smoothing/CpuScreenDevice.h"
#include "smoothing/GpuScreenDevice.h"
#include "smoothing/ShadingScenes.h"

namespace flipscope {
namespace {

TEST(ColorMapGl, GpuShadingMatchesTheCpuReferenceForEveryMap) {
  gl::EglContext context;
  try {
    context = gl::EglContext::create();
  } catch (const gl::Unavailable& e) {
    FLIPSCOPE_SKIP_WITHOUT_GL(e.what());
  }
  GpuScreenDevice gpu("test");
  CpuScreenDevice cpu;
  int compared = 0;
  for (ColorMap map : {ColorMap::Viridis, ColorMap::Magma, ColorMap::Coolwarm, ColorMap::Blues})
    for (ShadingMode mode : {ShadingMode::Liquid, ShadingMode::Spheres, ShadingMode::Attribute})
      for (bool ranged : {false, true}) {
        SCOPED_TRACE(std::string(colorMapName(map)) + " mode " + std::to_string(int(mode)) + (ranged ? " ranged" : ""));
        ShadingOptions options;
        options.mode = mode;
        options.colorByAttribute = true;
        options.colorMap = map;
        if (ranged) options.colorRange = glm::vec2(-1.0f, 3.0f);
        const auto a = testing::shadeRamp(gpu, options, 64, 16, 0.5f, 2.0f);
        const auto b = testing::shadeRamp(cpu, options, 64, 16, 0.5f, 2.0f);
        ASSERT_EQ(a.size(), b.size());
        float worst = 0;
        for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, glm::length(glm::vec3(a[i] - b[i])));
        EXPECT_LT(worst, 2e-3f);
        ++compared;
      }
  EXPECT_EQ(compared, 24);
}

}  // namespace
}  // namespace flipscope
