// C++ side of smoothing/glsl/ScreenTypes.glsl: the frame block of every screen-space pass,
// defined once for C++ and GLSL, with its std140 layout checked here.
#pragma once

#include <cstddef>

#include "core/GlslShared.h"

namespace flipscope::glsl {
#include "smoothing/glsl/ScreenTypes.glsl"
}  // namespace flipscope::glsl

namespace flipscope {
using glsl::ScreenFrame;
using glsl::ScreenPair;

static_assert(sizeof(ScreenFrame) == 6 * 16);
static_assert(offsetof(ScreenFrame, forward) == 0 && offsetof(ScreenFrame, right) == 16 &&
              offsetof(ScreenFrame, up) == 32 && offsetof(ScreenFrame, worldUp) == 48);
static_assert(offsetof(ScreenFrame, width) == 64 && offsetof(ScreenFrame, height) == 68 &&
              offsetof(ScreenFrame, tanHalfFovY) == 72 && offsetof(ScreenFrame, aspect) == 76);
static_assert(offsetof(ScreenFrame, focalPixels) == 80 && offsetof(ScreenFrame, particleRadius) == 84 &&
              offsetof(ScreenFrame, cellSize) == 88 && offsetof(ScreenFrame, unused0) == 92);

}  // namespace flipscope
