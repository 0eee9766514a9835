// Foam classification (Reichl et al. 2014 §3.5): "classifying particles as foam when less than
// 20% of the cells inside the particle radius are occupied". Shared by the compute shader
// (raycast/glsl/FoamClassify.comp) and the CPU reference (raycast/CpuRaycaster.cpp); see
// core/GlslShared.h. Needs BitBrick.glsl and FoamTypes.glsl before it, a FoamClassifyParams
// named FP, and these accessors from the includer:
//   uvec4 fcSubBrick(uint slot, uint subBrick)   bits of a resident brick (all its set cells)
//   uvec4 fcFoam(uint slot, uint subBrick)       its foam bit-brick as uploaded: the cells whose
//                                                stored kind counts as foam (zeros without)
//
// Two passes, the second after the first has finished: fcClassify writes the foam bits, then
// fcOccupancyWord summarises them per sub-brick for the volume's empty-space skipping.
//
// One invocation per sub-brick of a batch of freshly uploaded bricks: it reads the bits around
// its sub-brick and returns its foam bits, which the includer writes over fcFoam of the same
// sub-brick. An invocation writes only its own sub-brick and reads no foam bits but its own, so
// a batch needs no atomics and no ordering. A cell's neighbourhood is every cell other than
// itself whose centre lies within FP.radius; cells beyond the stored border count as empty, so
// a cell is classified exactly when its neighbourhood lies within the border (FrameRenderer
// sizes the border for that).

// Cells of the neighbourhood: the offsets d != 0 with |d| <= radius.
FS_FUNC uint fcNeighbourhoodSize(float radius) {
  int reach = int(floor(radius));
  uint count = 0u;
  for (int dz = -reach; dz <= reach; dz++)
    for (int dy = -reach; dy <= reach; dy++)
      for (int dx = -reach; dx <= reach; dx++)
        if (float(dx * dx + dy * dy + dz * dz) <= radius * radius) count++;
  return count - 1u;
}

// Whether stored cell `s` (brick-local cell + overlap) of `slot` is set; false beyond the stored cells.
FS_FUNC bool fcStoredCellSet(uint slot, ivec3 s) {
  int stored = int(FP.brickSize + 2u * FP.overlap);
  if (s.x < 0 || s.y < 0 || s.z < 0 || s.x >= stored || s.y >= stored || s.z >= stored) return false;
  ivec3 cell = s - ivec3(int(FP.overlap));
  return bitBrickBitSet(fcSubBrick(slot, bitBrickSubBrickIndex(cell, FP.brickSize, FP.overlap)),
                        bitBrickBitIndex(cell, FP.overlap));
}

// The foam bits of sub-brick `subBrick` of `slot`: the uploaded ones, plus (FP.classify = 1u) every
// set cell with fewer than FP.threshold times fcNeighbourhoodSize set neighbours.
FS_FUNC uvec4 fcClassify(uint slot, uint subBrick) {
  uvec4 foam = fcFoam(slot, subBrick);
  uvec4 bits = fcSubBrick(slot, subBrick);
  if (FP.classify == 0u || (bits.x | bits.y | bits.z | bits.w) == 0u) return foam;
  float radius = FP.radius;
  int reach = int(floor(radius));
  float needed = FP.threshold * float(fcNeighbourhoodSize(radius));
  ivec3 origin = ivec3(bitBrickSubBrickCoord(subBrick, bitBrickSubBrickDims(FP.brickSize, FP.overlap)) *
                       uvec3(4u, 4u, 8u));
  for (uint bit = 0u; bit < 128u; bit++) {
    if (!bitBrickBitSet(bits, bit)) continue;
    ivec3 s = origin + ivec3(int(bit & 3u), int((bit >> 2u) & 3u), int(bit >> 4u));
    // Counting stops once the cell has the neighbours it needs not to be foam: in a liquid
    // body, after a few of them.
    uint count = 0u;
    for (int dz = -reach; dz <= reach && float(count) < needed; dz++)
      for (int dy = -reach; dy <= reach && float(count) < needed; dy++)
        for (int dx = -reach; dx <= reach && float(count) < needed; dx++) {
          if (float(dx * dx + dy * dy + dz * dz) > radius * radius || (dx == 0 && dy == 0 && dz == 0)) continue;
          if (fcStoredCellSet(slot, s + ivec3(dx, dy, dz))) count++;
        }
    if (float(count) < needed) foam[int(bit >> 5u)] |= 1u << (bit & 31u);
  }
  return foam;
}

// The foam occupancy of sub-bricks 32 word .. 32 word + 31 of `slot`, one bit each: set when the
// sub-brick or one of its 26 neighbours holds a foam cell, so the volume's trilinear density
// (Raycast.glsl, rcFoamDensity) is 0 everywhere in a sub-brick whose bit is clear. One
// invocation per word, after fcClassify has written every sub-brick of the slot.
FS_FUNC uint fcOccupancyWord(uint slot, uint word) {
  uvec3 dims = bitBrickSubBrickDims(FP.brickSize, FP.overlap);
  uint occupancy = 0u;
  for (uint i = 0u; i < 32u; i++) {
    uint subBrick = word * 32u + i;
    if (subBrick >= FP.subBricksPerSlot) break;
    ivec3 c = ivec3(bitBrickSubBrickCoord(subBrick, dims));
    bool foam = false;
    for (int d = 0; d < 27 && !foam; d++) {
      ivec3 q = c + ivec3(d % 3 - 1, (d / 3) % 3 - 1, d / 9 - 1);
      if (q.x < 0 || q.y < 0 || q.z < 0 || q.x >= int(dims.x) || q.y >= int(dims.y) || q.z >= int(dims.z)) continue;
      uvec4 f = fcFoam(slot, bitBrickSubBrickLinear(uvec3(q), dims));
      foam = (f.x | f.y | f.z | f.w) != 0u;
    }
    if (foam) occupancy |= 1u << i;
  }
  return occupancy;
}
