// C++ side of raycast/glsl/FoamTypes.glsl: the foam classification pass's parameter block,
// defined once for C++ and GLSL, with its std140 layout checked here.
#pragma once

#include <cstddef>

#include "core/GlslShared.h"

namespace flipscope::glsl {
#include "raycast/glsl/FoamTypes.glsl"
}  // namespace flipscope::glsl

namespace flipscope {
using glsl::FoamClassifyParams;
static_assert(sizeof(FoamClassifyParams) == 2 * 16 && offsetof(FoamClassifyParams, sphere) == 16);
}  // namespace flipscope
