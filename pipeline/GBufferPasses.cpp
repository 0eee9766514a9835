#include "pipeline/GBufferPasses.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/Error.h"
#include "raycast/RaycastTypes.h"  // kRayHit
#include "smoothing/detail/CpuScreenKernel.h"

namespace flipscope {

namespace glsl {
struct GBufferKernel : CpuScreenKernel {
#include "pipeline/glsl/GBuffer.glsl"
};
}  // namespace glsl

const ScreenPass kGBufferHits{"GBufferHits.comp", "gbufferHits",
                              cpuScreenPass<glsl::GBufferKernel, &glsl::GBufferKernel::gbufferHits>};
const ScreenPass kBlurThicknessReference{
    "GBuffer.comp", "gbufferBlurThickness",
    cpuScreenPass<glsl::GBufferKernel, &glsl::GBufferKernel::gbufferBlurThickness>};
// The reference's shader and kernel, so that the GPU runs the one shader whichever is asked for.
const ScreenPass kBlurThickness{kBlurThicknessReference.shader, kBlurThicknessReference.kernel, blurThicknessOnCpu};

void blurThicknessOnCpu(const CpuPassInputs& inputs, const void*, glm::vec4* output, glm::vec4* secondOutput) {
  FLIPSCOPE_CHECK(secondOutput == nullptr, "a pass of one output run with two");
  const ScreenFrame& F = inputs.frame;
  const int width = int(F.width), height = int(F.height);
  FLIPSCOPE_CHECK(inputs.sizes[0] >= std::size_t(width) * std::size_t(height), "the surface image is smaller");
  const glm::vec4* surface = inputs.images[0];
  // gbufferBlurThickness's expressions, with the functions the kernel compiled as C++ calls
  // (glm's clamp, min and max; std::abs).
  const float sameSurface = 4.0f * F.particleRadius;
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      for (int x = 0; x < width; ++x) {
        const glm::vec4 here = surface[std::size_t(y) * width + x];
        glm::vec4& out = output[std::size_t(y) * width + x];
        if (here.y < 0.5f) {
          out = here;
          continue;
        }
        const int radius = int(glm::clamp(F.focalPixels * F.particleRadius / glm::max(here.x, 1.0e-6f), 1.0f, 8.0f));
        const int x0 = glm::max(x - radius, 0), x1 = glm::min(x + radius, width - 1);
        const int y0 = glm::max(y - radius, 0), y1 = glm::min(y + radius, height - 1);
        float sum = 0.0f;
        float count = 0.0f;
        for (int qy = y0; qy <= y1; ++qy) {
          const glm::vec4* row = surface + std::size_t(qy) * width;
          for (int qx = x0; qx <= x1; ++qx) {
            const glm::vec4& n = row[qx];
            if (n.y < 0.5f || std::abs(n.x - here.x) > sameSurface) continue;
            sum += n.z;
            count += 1.0f;
          }
        }
        out = glm::vec4(here.x, here.y, sum / count, here.w);
      }
    }
  });
}

}  // namespace flipscope
