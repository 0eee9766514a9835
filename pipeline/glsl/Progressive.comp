// The viewer's progressive display pass: FS_KERNEL is progressiveDisplay (Progressive.glsl).
#include "ScreenTypes.glsl"
#include "RaycastTypes.glsl"
#include "ScreenPass.glsl"
#include "Progressive.glsl"
#include "ScreenPassMain.glsl"
