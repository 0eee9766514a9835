// ROF passes (Reichl et al. 2014 §3.4): FS_KERNEL is one of the kernels of Rof.glsl.
#include "ScreenTypes.glsl"
#include "RofTypes.glsl"
layout(std140, binding = 1) uniform PassBlock { RofParams S; };
#include "ScreenPass.glsl"
#include "Rof.glsl"
#include "ScreenPassMain.glsl"
