// The G-buffer pass over its own image: FS_KERNEL is gbufferBlurThickness (GBuffer.glsl).
#include "ScreenTypes.glsl"
#include "RaycastTypes.glsl"
#include "ScreenPass.glsl"
#include "GBuffer.glsl"
#include "ScreenPassMain.glsl"
