// C++ side of streaming/glsl/Jitter.glsl: TEA hash and the per-cell jitter of §3.2.2.
#pragma once

#include "core/Morton.h"

namespace flipscope::glsl {
#include "streaming/glsl/Jitter.glsl"
}  // namespace flipscope::glsl

namespace flipscope {
using glsl::cellJitter;
using glsl::kJitterTeaRounds;
using glsl::tea;
}  // namespace flipscope
