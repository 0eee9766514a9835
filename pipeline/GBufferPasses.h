// The G-buffer passes of FramePipeline (pipeline/glsl/GBuffer.glsl): the ray-caster's hits made
// the surface and sphere images, then the surface's thickness blurred. Internal to
// flipscope::pipeline; the tests compare the CPU thickness blur with its reference here.
#pragma once

#include "smoothing/ScreenDevice.h"

namespace flipscope {

/// gbufferHits: the RayHit array (input 0) -> the surface and the sphere images.
extern const ScreenPass kGBufferHits;

/// gbufferBlurThickness: the surface image (input 0) -> the same with its thickness blurred. On
/// the CPU by blurThicknessOnCpu, which gives the reference's values bit for bit.
extern const ScreenPass kBlurThickness;

/// gbufferBlurThickness with the kernel compiled from GBuffer.glsl on the CPU too (the
/// reference: per tap, the generic accessors' bounds checks and clamping).
extern const ScreenPass kBlurThicknessReference;

/// kBlurThickness's CPU side: the same taps in the same order (rows of the window from the top,
/// each from the left), so the same sums, with the window clipped to the image once a pixel
/// instead of each tap checked (the G-buffer stage of the dam at 1080p in half the time: README,
/// "Surface").
void blurThicknessOnCpu(const CpuPassInputs& inputs, const void* params, glm::vec4* output, glm::vec4* secondOutput);

}  // namespace flipscope
