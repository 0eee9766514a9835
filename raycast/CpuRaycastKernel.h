// Raycast.glsl and FoamClassify.glsl compiled as C++ (see core/GlslShared.h) over a
// CpuRaycaster::Pool: the exact reference that CpuRaycaster runs per pixel. TiledCpuRaycaster
// compiles Raycast.glsl once more over the same accessors, with its own brick march.
// Internal to flipscope::raycast.
#pragma once

#include <atomic>

#include "raycast/CpuRaycaster.h"
#include "streaming/BitBrickLayout.h"
#include "streaming/Jitter.h"

namespace flipscope::glsl {

/// The accessors Raycast.glsl calls, over the pool's arrays. Its functions become members of a
/// struct derived from this one, so the accessors (and the parameter block P) are in scope as
/// they are globals in Raycast.comp.
struct RaycastPoolAccess {
  RaycastParams P;
  const CpuRaycaster::Pool* pool;
  std::atomic<std::uint8_t>* requestFlags;

  uvec2 rcNode(uint node) const { return pool->nodes[node]; }
  uint rcPage(uint brickIndex) const { return pool->pageTable[brickIndex]; }
  uvec4 rcSubBrick(uint slot, uint subBrick) const {
    return pool->subBricks[std::size_t(slot) * P.subBricksPerSlot + subBrick];
  }
  uint rcMipWord(uint slot, uint word) const { return pool->mipWords[std::size_t(slot) * P.mipWordsPerSlot + word]; }
  uint rcAttributeBase(uint slot, uint subBrick) const {
    return pool->attributeBases[std::size_t(slot) * P.subBricksPerSlot + subBrick];
  }
  uint rcAttribute(uint index) const { return pool->attributes[index]; }
  void rcRequest(uint brickIndex) const { requestFlags[brickIndex].store(1, std::memory_order_relaxed); }
  uvec4 rcFoamSubBrick(uint slot, uint subBrick) const {
    return pool->foamBits[std::size_t(slot) * P.subBricksPerSlot + subBrick];
  }
  uint rcFoamOccupancy(uint slot, uint word) const {
    return pool->foamOccupancy[std::size_t(slot) * pool->layout.foamOccupancyWords() + word];
  }
};

/// The reference: Raycast.glsl with its own brick march and half block counts.
struct RaycastKernel : RaycastPoolAccess {
  uint rcLiquidHalfCount(uint slot, uvec2 h) { return rcLiquidHalfCountOfBits(slot, h); }
  uint rcFoamHalfCount(uint slot, uvec2 h) { return rcFoamHalfCountOfBits(slot, h); }
  void rcMarchBrick(RayHit& result, uint slot, uvec3 brick, vec3 eye, vec3 dir, float t, float tEnd) {
    rcTraceBrick(result, slot, brick, eye, dir, t, tEnd);
  }

#include "raycast/glsl/Raycast.glsl"
};

/// FoamClassify.glsl compiled as C++, the same way.
struct FoamKernel {
  FoamClassifyParams FP;
  const CpuRaycaster::Pool* pool;

  uvec4 fcSubBrick(uint slot, uint subBrick) const {
    return pool->subBricks[std::size_t(slot) * FP.subBricksPerSlot + subBrick];
  }
  uvec4 fcFoam(uint slot, uint subBrick) const {
    return pool->foamBits[std::size_t(slot) * FP.subBricksPerSlot + subBrick];
  }

#include "raycast/glsl/FoamClassify.glsl"
};

}  // namespace flipscope::glsl
