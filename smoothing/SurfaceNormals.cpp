#include "smoothing/SurfaceNormals.h"

#include <cstddef>

#include "smoothing/detail/CpuScreenKernel.h"

namespace flipscope {

namespace glsl {
#include "smoothing/glsl/NormalTypes.glsl"
static_assert(sizeof(NormalParams) == 16);

struct NormalKernel : CpuScreenKernel {
  NormalParams S;
#include "smoothing/glsl/Normals.glsl"
};
}  // namespace glsl

namespace {
const ScreenPass kNormals{"Normals.comp", "normalsFromDepth",
                          cpuScreenPass<glsl::NormalKernel, &glsl::NormalKernel::normalsFromDepth>};
}

void reconstructNormals(ScreenDevice& device, ScreenImage depth, ScreenImage normals, float edgeParticles) {
  glsl::NormalParams params{};
  params.edgeDepth = edgeParticles * device.frame().particleRadius;
  device.run(kNormals, params, {depth}, normals);
}

}  // namespace flipscope
