// The foam classification pass (Reichl et al. 2014 §3.5): one invocation per sub-brick of a
// batch of freshly uploaded bricks (raycast/glsl/FoamClassify.glsl); x: the sub-brick, y: the
// brick of the batch. Bound by raycast/GpuRaycaster.cpp: the pool's bits and foam bit-bricks,
// and the batch's slots.
layout(local_size_x = 64) in;

#include "BitBrick.glsl"
#include "FoamTypes.glsl"

layout(std140, binding = 0) uniform FoamParamsBlock { FoamClassifyParams FP; };
layout(std430, binding = 3) readonly buffer SubBrickBuffer { uvec4 subBricks[]; };
layout(std430, binding = 10) buffer FoamBuffer { uvec4 foamBits[]; };
layout(std430, binding = 11) readonly buffer BatchBuffer { uint batchSlots[]; };

uvec4 fcSubBrick(uint slot, uint subBrick) { return subBricks[slot * FP.subBricksPerSlot + subBrick]; }
uvec4 fcFoam(uint slot, uint subBrick) { return foamBits[slot * FP.subBricksPerSlot + subBrick]; }

#include "FoamClassify.glsl"

void main() {
  uint subBrick = gl_GlobalInvocationID.x;
  if (subBrick >= FP.subBricksPerSlot || gl_GlobalInvocationID.y >= FP.batchSubBricks / FP.subBricksPerSlot) return;
  uint slot = batchSlots[gl_GlobalInvocationID.y];
  foamBits[slot * FP.subBricksPerSlot + subBrick] = fcClassify(slot, subBrick);
}
