// Bilateral pass (depth-adaptive bilateral Gaussian): FS_KERNEL is the kernel of Bilateral.glsl.
#include "ScreenTypes.glsl"
#include "BilateralTypes.glsl"
layout(std140, binding = 1) uniform PassBlock { BilateralParams S; };
#include "ScreenPass.glsl"
#include "Bilateral.glsl"
#include "ScreenPassMain.glsl"
