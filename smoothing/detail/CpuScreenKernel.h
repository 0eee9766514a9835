// The C++ side of smoothing/glsl/ScreenPass.glsl: the accessors a shared kernel file calls
// (ssLoad, ssLoadIndex, the frame block F), as members of a base struct, so a kernel .glsl
// included inside a struct derived from it compiles as C++ exactly as it does as GLSL:
//
//   namespace flipscope::glsl {
//   struct RofKernel : CpuScreenKernel {
//     RofParams S;
//   #include "smoothing/glsl/Rof.glsl"
//   };
//   }
//   const ScreenPass kRofDual{"Rof.comp", "rofDual", cpuScreenPass<glsl::RofKernel, &glsl::RofKernel::rofDual>};
#pragma once

#include <type_traits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/Error.h"
#include "smoothing/ScreenDevice.h"
#include "smoothing/ScreenTypes.h"

namespace flipscope::glsl {

struct CpuScreenKernel {
  ScreenFrame F{};
  const CpuPassInputs* in = nullptr;

  vec4 ssLoadIndex(uint image, uint index) const {
    FLIPSCOPE_CHECK(image < 4 && index < in->sizes[image], "image " << image << " element " << index);
    return in->images[image][index];
  }
  vec4 ssLoad(uint image, ivec2 p) const {
    const ivec2 q = clamp(p, ivec2(0), ivec2(int(F.width) - 1, int(F.height) - 1));
    return ssLoadIndex(image, uint(q.y) * F.width + uint(q.x));
  }
#include "smoothing/glsl/ScreenMath.glsl"
};

}  // namespace flipscope::glsl

namespace flipscope {

/// ScreenPass::cpu for kernel `Fn` of `Kernel` (a CpuScreenKernel with a parameter member S),
/// which returns a vec4 or a ScreenPair: one TBB task per band of rows.
template <class Kernel, auto Fn>
void cpuScreenPass(const CpuPassInputs& inputs, const void* params, glm::vec4* output, glm::vec4* secondOutput) {
  constexpr bool pair = std::is_same_v<std::invoke_result_t<decltype(Fn), Kernel&, glm::ivec2>, ScreenPair>;
  FLIPSCOPE_CHECK(pair == (secondOutput != nullptr),
                  (pair ? "a pass of two outputs run with one" : "a pass of one output run with two"));
  Kernel prototype;
  prototype.F = inputs.frame;
  prototype.in = &inputs;
  if constexpr (requires { prototype.S; }) prototype.S = *static_cast<const decltype(prototype.S)*>(params);
  const std::uint32_t width = inputs.frame.width, height = inputs.frame.height;
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, height), [&](const tbb::blocked_range<std::uint32_t>& rows) {
    Kernel kernel = prototype;
    for (std::uint32_t y = rows.begin(); y != rows.end(); ++y) {
      for (std::uint32_t x = 0; x < width; ++x) {
        const std::size_t i = std::size_t(y) * width + x;
        if constexpr (pair) {
          const ScreenPair values = (kernel.*Fn)(glm::ivec2(int(x), int(y)));
          output[i] = values.first;
          secondOutput[i] = values.second;
        } else {
          output[i] = (kernel.*Fn)(glm::ivec2(int(x), int(y)));
        }
      }
    }
  });
}

}  // namespace flipscope
