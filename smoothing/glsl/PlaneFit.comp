// Iterative MLS plane-fit passes (Imai, Kanamori, Mitani 2016): FS_KERNEL is one of the kernels
// of PlaneFit.glsl.
#include "ScreenTypes.glsl"
#include "PlaneFitTypes.glsl"
layout(std140, binding = 1) uniform PassBlock { PlaneFitParams S; };
#include "ScreenPass.glsl"
#include "PlaneFit.glsl"
#include "ScreenPassMain.glsl"
