// Deferred shading pass: FS_KERNEL is shadeSurface (Shading.glsl).
#include "ScreenTypes.glsl"
#include "ColorMap.glsl"
#include "ShadingTypes.glsl"
layout(std140, binding = 1) uniform PassBlock { ShadingParams S; };
#include "ScreenPass.glsl"
#include "Shading.glsl"
#include "ScreenPassMain.glsl"
