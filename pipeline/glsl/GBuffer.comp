// G-buffer passes: FS_KERNEL is gbufferSurface or gbufferSphereNormal (GBuffer.glsl).
#include "ScreenTypes.glsl"
#include "RaycastTypes.glsl"
#include "ScreenPass.glsl"
#include "GBuffer.glsl"
#include "ScreenPassMain.glsl"
