// C++ side of raycast/glsl/RaycastTypes.glsl: the ray-caster's parameter block and per-pixel
// result, defined once for C++ and GLSL, with their GPU layouts checked here.
#pragma once

#include <cstddef>

#include "core/GlslShared.h"

namespace flipscope::glsl {
#include "raycast/glsl/RaycastTypes.glsl"
}  // namespace flipscope::glsl

namespace flipscope {
using glsl::kMaxMipLevels;
using glsl::kNotResident;
using glsl::kRayHit;
using glsl::kRayMiss;
using glsl::kRayPending;
using glsl::kFoamSkip;
using glsl::kFoamVolume;
using glsl::kThicknessMaxCells;
using glsl::RaycastParams;
using glsl::RayHit;

// std140 and std430 agree with C++ for these members (16-byte vectors, then 4-byte scalars).
static_assert(sizeof(RaycastParams) == 19 * 16);
static_assert(offsetof(RaycastParams, eye) == 0 && offsetof(RaycastParams, forward) == 16 &&
              offsetof(RaycastParams, right) == 32 && offsetof(RaycastParams, up) == 48);
static_assert(offsetof(RaycastParams, bricksPerAxis) == 64 && offsetof(RaycastParams, tanHalfFovY) == 80 &&
              offsetof(RaycastParams, aspect) == 84 && offsetof(RaycastParams, cellSize) == 88);
static_assert(offsetof(RaycastParams, unused0) == 92 && offsetof(RaycastParams, width) == 96 &&
              offsetof(RaycastParams, height) == 100 && offsetof(RaycastParams, timeStep) == 104);
static_assert(offsetof(RaycastParams, brickSize) == 108 && offsetof(RaycastParams, overlap) == 112 &&
              offsetof(RaycastParams, reach) == 116 && offsetof(RaycastParams, octreeLevels) == 120);
static_assert(offsetof(RaycastParams, subBricksPerSlot) == 124 && offsetof(RaycastParams, mipWordsPerSlot) == 128 &&
              offsetof(RaycastParams, attributes) == 132 && offsetof(RaycastParams, frameBricks) == 136);
static_assert(offsetof(RaycastParams, mipLevelCount) == 140 && offsetof(RaycastParams, radius) == 144 &&
              offsetof(RaycastParams, maxJitter) == 148 && offsetof(RaycastParams, thicknessBestEffort) == 152);
static_assert(offsetof(RaycastParams, thicknessSaturationCells) == 156 && offsetof(RaycastParams, foamFlags) == 160 &&
              offsetof(RaycastParams, foamStep) == 164 && offsetof(RaycastParams, foamExtinction) == 168);
static_assert(offsetof(RaycastParams, foamOpacityStop) == 172 && offsetof(RaycastParams, mipLevels) == 176);
static_assert(sizeof(RayHit) == 48 && sizeof(RayHit) % sizeof(glm::vec4) == 0, "a RayHit is three vec4 (pipeline/glsl)");
static_assert(kRayPending == 0, "a zeroed RayHit is a fresh pending ray");
static_assert(offsetof(RayHit, t) == 16 && offsetof(RayHit, status) == 20 && offsetof(RayHit, depth) == 24 &&
              offsetof(RayHit, brickIndex) == 28 && offsetof(RayHit, thickness) == 32 &&
              offsetof(RayHit, foam) == 36);

}  // namespace flipscope
