// Narrow-range passes (Truong and Yuksel 2018): FS_KERNEL is one of the kernels of
// NarrowRange.glsl.
#include "ScreenTypes.glsl"
#include "NarrowRangeTypes.glsl"
layout(std140, binding = 1) uniform PassBlock { NarrowRangeParams S; };
#include "ScreenPass.glsl"
#include "NarrowRange.glsl"
#include "ScreenPassMain.glsl"
