// The G-buffer pass that reads the hits: FS_KERNEL is gbufferHits (GBuffer.glsl), two outputs.
#include "ScreenTypes.glsl"
#include "RaycastTypes.glsl"
#include "ScreenPass.glsl"
#include "GBuffer.glsl"
#include "ScreenPairPassMain.glsl"
