// Screen-space curvature flow passes (van der Laan, Green, Sainz 2009): FS_KERNEL is one of the
// kernels of CurvatureFlow.glsl.
#include "ScreenTypes.glsl"
#include "CurvatureFlowTypes.glsl"
layout(std140, binding = 1) uniform PassBlock { CurvatureFlowParams S; };
#include "ScreenPass.glsl"
#include "CurvatureFlow.glsl"
#include "ScreenPassMain.glsl"
