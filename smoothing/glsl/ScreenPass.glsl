// GPU side of a screen-space pass: the frame block, four input images and the output image, at
// the binding points smoothing/GpuScreenDevice.cpp binds. A pass's .comp includes, in order:
// ScreenTypes.glsl, its own parameter struct and `layout(std140, binding = 1) uniform PassBlock
// { ItsParams S; };`, this file, its kernels (shared with C++), then ScreenPassMain.glsl, or
// ScreenPairPassMain.glsl for a kernel that returns a ScreenPair.
// The C++ side of the same accessors is smoothing/detail/CpuScreenKernel.h.
layout(local_size_x = 8, local_size_y = 8) in;

layout(std140, binding = 0) uniform FrameBlock { ScreenFrame F; };
layout(std430, binding = 2) readonly buffer Input0 { vec4 input0[]; };
layout(std430, binding = 3) readonly buffer Input1 { vec4 input1[]; };
layout(std430, binding = 4) readonly buffer Input2 { vec4 input2[]; };
layout(std430, binding = 5) readonly buffer Input3 { vec4 input3[]; };
layout(std430, binding = 6) writeonly buffer Output { vec4 outputPixels[]; };

// Element `index` of input image `image` (0..3), any size (an environment map, packed hits).
vec4 ssLoadIndex(uint image, uint index) {
  if (image == 0u) return input0[index];
  if (image == 1u) return input1[index];
  if (image == 2u) return input2[index];
  return input3[index];
}

// Pixel `p` of a frame-sized input image, clamped to the image.
vec4 ssLoad(uint image, ivec2 p) {
  ivec2 q = clamp(p, ivec2(0), ivec2(int(F.width) - 1, int(F.height) - 1));
  return ssLoadIndex(image, uint(q.y) * F.width + uint(q.x));
}
#include "ScreenMath.glsl"
