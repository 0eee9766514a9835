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
static_assert(sizeof(FoamClassifyParams) == 2 * 16);
static_assert(offsetof(FoamClassifyParams, brickSize) == 0 && offsetof(FoamClassifyParams, overlap) == 4 &&
              offsetof(FoamClassifyParams, subBricksPerSlot) == 8 &&
              offsetof(FoamClassifyParams, batchSubBricks) == 12);
static_assert(offsetof(FoamClassifyParams, radius) == 16 && offsetof(FoamClassifyParams, threshold) == 20 &&
              offsetof(FoamClassifyParams, classify) == 24 && offsetof(FoamClassifyParams, unused0) == 28);
}  // namespace flipscope
