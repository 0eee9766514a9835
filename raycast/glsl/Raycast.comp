// The compute ray-caster (Reichl et al. 2014 §3.3): one invocation per pixel continues its
// pending ray through raycast/glsl/Raycast.glsl. Buffers are bound by raycast/GpuRaycaster.cpp
// at the binding points below; every array is laid out as CpuRaycaster::Pool describes.
layout(local_size_x = 8, local_size_y = 8) in;

#include "Morton.glsl"
#include "Jitter.glsl"
#include "BitBrick.glsl"
#include "RaycastTypes.glsl"

layout(std140, binding = 0) uniform ParamsBlock { RaycastParams P; };
layout(std430, binding = 1) readonly buffer NodeBuffer { uvec2 nodes[]; };
layout(std430, binding = 2) readonly buffer PageBuffer { uint pages[]; };
layout(std430, binding = 3) readonly buffer SubBrickBuffer { uvec4 subBricks[]; };
layout(std430, binding = 4) readonly buffer MipBuffer { uint mipWords[]; };
layout(std430, binding = 5) readonly buffer AttributeBaseBuffer { uint attributeBases[]; };
layout(std430, binding = 6) readonly buffer AttributeBuffer { uint attributePairs[]; };  // two uint16 per uint
layout(std430, binding = 7) buffer HitBuffer { RayHit hits[]; };
layout(std430, binding = 8) buffer RequestBuffer { uint requestCount; uint requests[]; };
layout(std430, binding = 9) buffer RequestFlagBuffer { uint requestFlags[]; };  // one per brick, cleared per pass
layout(std430, binding = 10) readonly buffer FoamBuffer { uvec4 foamBits[]; };  // as subBricks, with kFoamSkip
layout(std430, binding = 12) readonly buffer FoamOccupancyBuffer { uint foamOccupancy[]; };  // with kFoamVolume

uvec2 rcNode(uint node) { return nodes[node]; }
uint rcPage(uint brickIndex) { return pages[brickIndex]; }
uvec4 rcSubBrick(uint slot, uint subBrick) { return subBricks[slot * P.subBricksPerSlot + subBrick]; }
uint rcMipWord(uint slot, uint word) { return mipWords[slot * P.mipWordsPerSlot + word]; }
uint rcAttributeBase(uint slot, uint subBrick) { return attributeBases[slot * P.subBricksPerSlot + subBrick]; }
uvec4 rcFoamSubBrick(uint slot, uint subBrick) { return foamBits[slot * P.subBricksPerSlot + subBrick]; }
uint rcFoamOccupancy(uint slot, uint word) { return foamOccupancy[slot * ((P.subBricksPerSlot + 31u) / 32u) + word]; }
uint rcAttribute(uint index) { return (attributePairs[index >> 1u] >> ((index & 1u) * 16u)) & 0xffffu; }

// The request buffer (§3.3): a brick is appended once per pass; overflow is dropped (the ray
// stays pending and asks again next pass).
void rcRequest(uint brickIndex) {
  if (atomicExchange(requestFlags[brickIndex], 1u) == 0u) {
    uint slot = atomicAdd(requestCount, 1u);
    if (slot < uint(requests.length())) requests[slot] = brickIndex;
  }
}

// The brick march rcTrace runs and the half block counts are the shared ones.
uint rcLiquidHalfCountOfBits(uint slot, uvec2 h);
uint rcFoamHalfCountOfBits(uint slot, uvec2 h);
uint rcLiquidHalfCount(uint slot, uvec2 h) { return rcLiquidHalfCountOfBits(slot, h); }
uint rcFoamHalfCount(uint slot, uvec2 h) { return rcFoamHalfCountOfBits(slot, h); }
void rcTraceBrick(inout RayHit result, uint slot, uvec3 brick, vec3 eye, vec3 dir, float t, float tEnd);
void rcMarchBrick(inout RayHit result, uint slot, uvec3 brick, vec3 eye, vec3 dir, float t, float tEnd) {
  rcTraceBrick(result, slot, brick, eye, dir, t, tEnd);
}

#include "Raycast.glsl"

void main() {
  uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= P.width || pixel.y >= P.height) return;
  uint index = pixel.y * P.width + pixel.x;
  RayHit ray = hits[index];
  if (!rcNeedsPass(ray)) return;
  rcPass(pixel, ray);
  hits[index] = ray;
}
