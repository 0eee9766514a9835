// Normal reconstruction pass: FS_KERNEL is normalsFromDepth (Normals.glsl).
#include "ScreenTypes.glsl"
#include "NormalTypes.glsl"
layout(std140, binding = 1) uniform PassBlock { NormalParams S; };
#include "ScreenPass.glsl"
#include "Normals.glsl"
#include "ScreenPassMain.glsl"
