// The foam occupancy pass (raycast/glsl/FoamClassify.glsl, fcOccupancyWord): one invocation per
// 32-bit word of the occupancy of a batch of freshly classified bricks; x: the word, y: the
// brick of the batch. Bound by
// raycast/GpuRaycaster.cpp after FoamClassify.comp has finished.
layout(local_size_x = 64) in;

#include "BitBrick.glsl"
#include "FoamTypes.glsl"

layout(std140, binding = 0) uniform FoamParamsBlock { FoamClassifyParams FP; };
layout(std430, binding = 3) readonly buffer SubBrickBuffer { uvec4 subBricks[]; };
layout(std430, binding = 10) readonly buffer FoamBuffer { uvec4 foamBits[]; };
layout(std430, binding = 11) readonly buffer BatchBuffer { uint batchSlots[]; };
layout(std430, binding = 12) buffer FoamOccupancyBuffer { uint foamOccupancy[]; };

uvec4 fcSubBrick(uint slot, uint subBrick) { return subBricks[slot * FP.subBricksPerSlot + subBrick]; }
uvec4 fcFoam(uint slot, uint subBrick) { return foamBits[slot * FP.subBricksPerSlot + subBrick]; }

#include "FoamClassify.glsl"

void main() {
  uint words = (FP.subBricksPerSlot + 31u) / 32u;
  uint word = gl_GlobalInvocationID.x;
  if (word >= words || gl_GlobalInvocationID.y >= FP.batchSubBricks / FP.subBricksPerSlot) return;
  uint slot = batchSlots[gl_GlobalInvocationID.y];
  foamOccupancy[slot * words + word] = fcOccupancyWord(slot, word);
}
