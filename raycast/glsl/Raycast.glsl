// Sphere ray casting through the presence octree and bit-bricks (Reichl et al. 2014 §3.3,
// §3.3.1, §4.2), shared by the compute shader (raycast/glsl/Raycast.comp) and the CPU reference
// (raycast/CpuRaycaster.cpp); see core/GlslShared.h for the rules. Needs Morton.glsl,
// Jitter.glsl, BitBrick.glsl and RaycastTypes.glsl before it, a RaycastParams named P, and
// these accessors from the includer:
//   uvec2 rcNode(uint node)                       presence octree node (childMask, firstChild)
//   uint  rcPage(uint brickIndex)                 pool slot of a brick of the frame, or kNotResident
//   uvec4 rcSubBrick(uint slot, uint subBrick)    bits of a resident brick
//   uint  rcMipWord(uint slot, uint word)         its occupancy mipmap (BrickMipmap.h layout)
//   uvec4 rcFoamSubBrick(uint slot, uint subBrick)  its foam bit-brick (FoamClassify.glsl), read
//                                                 only with kFoamSkip
//   uint  rcFoamOccupancy(uint slot, uint word)   its foam occupancy (fcOccupancyWord), with
//                                                 kFoamVolume
//   uint  rcAttributeBase(uint slot, uint subBrick)  attribute index of the sub-brick's first set cell
//   uint  rcAttribute(uint index)                 16-bit attribute value
//   void  rcRequest(uint brickIndex)              asks for a brick (deduplicated by the includer)
//   uint  rcLiquidHalfCount(uint slot, uvec2 h)   sphere cells of half block h (rcHalfBlock) of a
//   uint  rcFoamHalfCount(uint slot, uvec2 h)     slot, and its foam cells: rcLiquidHalfCountOfBits
//                                                 and rcFoamHalfCountOfBits, or a table of them
//   void rcMarchBrick(FS_INOUT(RayHit) ray, uint slot, uvec3 brick, vec3 eye, vec3 dir,
//                     float t, float tEnd)        the march through one resident brick that rcTrace
//                                                 runs: rcTraceBrick, or an equivalent (the fast
//                                                 CPU device's, raycast/TiledCpuRaycaster.cpp)
//
// A ray's RayHit is updated in place (FS_INOUT) from rcPass down to the march: on the CPU, a
// copy of a struct just written field by field waits for those stores to reach the cache.
//
// Model. Every set cell of a bit-brick holds one sphere of radius P.radius cells centred at the
// cell centre plus the cell's jitter (§3.2.2). A sphere reaches cells at most k = P.reach away
// (k >= radius + jitter - 0.5), so the overlap border (n >= k) lets a brick alone answer for any
// ray segment inside it, and a mip block whose bit is clear (dilation >= k) holds no sphere.
//
// Traversal, front to back, by point location (no DDA state to carry across passes):
//  1. the brick containing the ray's point is found by descending the octree; an empty octant is
//     skipped to its exit;
//  2. a brick that is not resident is requested and the ray stops (kRayPending, resumes at t);
//  3. inside a brick, the coarsest clear mip block around the point is skipped to its exit
//     (levels and their word offsets come precomputed in P.mipLevels);
//     otherwise the spheres of the (2k+1)^3 cells around the point's cell are tested (those
//     not tested at the previous cell), and once the nearest hit so far lies no farther than
//     the cell's exit it ends the ray (a nearer hit would have been found in an earlier cell).
//
// Foam (§3.5). With kFoamSkip the cells of the slot's foam bit-brick are no spheres (`--foam
// remove` and `volume`). With kFoamVolume the ray also accumulates the foam in front of its hit
// (or along its whole way through the bricks) at fixed steps, emission-absorption over a density
// interpolated trilinearly between the 4^3 halves of the foam sub-bricks (Fig. 7); it ends as a
// miss once the foam's opacity reaches P.foamOpacityStop. Regions a clear mip block skips hold no
// set cell within the dilation, and no foam is gathered there.

// A small step past a box exit, so that point location lands in the next box.
FS_FUNC float rcStepPast(float t) { return t + 1.0e-3f + abs(t) * 4.0e-7f; }

FS_FUNC vec3 rcSafeInverse(vec3 d) {
  vec3 safe = d;
  for (int a = 0; a < 3; a++) {
    if (abs(safe[a]) < 1.0e-12f) safe[a] = safe[a] < 0.0f ? -1.0e-12f : 1.0e-12f;
  }
  return vec3(1.0f) / safe;
}

// Entry and exit distances of the ray o + t d (invDir = 1 / d) through the box [lo, hi].
FS_FUNC vec2 rcBoxSpan(vec3 o, vec3 invDir, vec3 lo, vec3 hi) {
  vec3 t1 = (lo - o) * invDir;
  vec3 t2 = (hi - o) * invDir;
  vec3 tn = min(t1, t2);
  vec3 tf = max(t1, t2);
  return vec2(max(max(tn.x, tn.y), tn.z), min(min(tf.x, tf.y), tf.z));
}

// Unit direction of the ray through the centre of `pixel` (row 0 at the top).
FS_FUNC vec3 rcCameraRay(uvec2 pixel) {
  float sx = ((float(pixel.x) + 0.5f) * (2.0f / float(P.width)) - 1.0f) * P.tanHalfFovY * P.aspect;
  float sy = (1.0f - (float(pixel.y) + 0.5f) * (2.0f / float(P.height))) * P.tanHalfFovY;
  vec3 f = vec3(P.forward.x, P.forward.y, P.forward.z);
  vec3 r = vec3(P.right.x, P.right.y, P.right.z);
  vec3 u = vec3(P.up.x, P.up.y, P.up.z);
  return normalize(f + sx * r + sy * u);
}

// Whether brick-local `cell` holds a sphere: set, and not foam when the pool's foam bit-bricks
// are valid (kFoamSkip; §3.5: the surface pass skips foam cells).
FS_FUNC bool rcSurfaceCellSet(uint slot, ivec3 cell) {
  uint subBrick = bitBrickSubBrickIndex(cell, P.brickSize, P.overlap);
  uvec4 bits = rcSubBrick(slot, subBrick);
  if ((P.foamFlags & kFoamSkip) != 0u) bits = bits & ~rcFoamSubBrick(slot, subBrick);
  return bitBrickBitSet(bits, bitBrickBitIndex(cell, P.overlap));
}

// The 4^3 block `block` of a slot's stored cells (block b spans stored cells [4b, 4b + 4), the
// halves of the sub-bricks; clamped to the stored blocks): x its sub-brick, y which half.
FS_FUNC uvec2 rcHalfBlock(ivec3 block) {
  uvec3 dims = bitBrickSubBrickDims(P.brickSize, P.overlap);
  uvec3 b = uvec3(clamp(block, ivec3(0), ivec3(int(dims.x) - 1, int(dims.y) - 1, int(2u * dims.z) - 1)));
  return uvec2(bitBrickSubBrickLinear(uvec3(b.x, b.y, b.z >> 1u), dims), b.z & 1u);
}

// The sphere cells (set, and not foam with kFoamSkip) of half block `h` (rcHalfBlock) of a slot.
FS_FUNC uint rcLiquidHalfCountOfBits(uint slot, uvec2 h) {
  uvec4 bits = rcSubBrick(slot, h.x);
  if ((P.foamFlags & kFoamSkip) != 0u) bits = bits & ~rcFoamSubBrick(slot, h.x);
  return bitBrickHalfCount(bits, h.y);
}

// The foam cells of half block `h` of a slot's foam bit-brick.
FS_FUNC uint rcFoamHalfCountOfBits(uint slot, uvec2 h) { return bitBrickHalfCount(rcFoamSubBrick(slot, h.x), h.y); }

// Density (0..1) of the sphere cells in the 4^3 block holding brick-local `cell` (§3.6).
FS_FUNC float rcLiquidDensity(uint slot, ivec3 cell) {
  return float(rcLiquidHalfCount(slot, rcHalfBlock((cell + ivec3(int(P.overlap))) >> 2))) / 64.0f;
}

// Foam density (0..1) at brick-local point `p`: trilinear between the centres of the 4^3 blocks
// of the foam bit-brick, each block's density its set bits / 64 (§3.5, Fig. 7).
FS_FUNC float rcFoamDensity(uint slot, vec3 p) {
  vec3 u = (p + vec3(float(P.overlap))) * 0.25f - vec3(0.5f);
  vec3 f = floor(u);
  vec3 w = u - f;
  ivec3 b = ivec3(f);
  float density = 0.0f;
  for (int i = 0; i < 8; i++) {
    ivec3 o = ivec3(i & 1, (i >> 1) & 1, i >> 2);
    float weight = (o.x == 1 ? w.x : 1.0f - w.x) * (o.y == 1 ? w.y : 1.0f - w.y) * (o.z == 1 ? w.z : 1.0f - w.z);
    density += weight * float(rcFoamHalfCount(slot, rcHalfBlock(b + o)));
  }
  return density / 64.0f;
}

// The foam opacity `opacity` after the ray segment [a, b) (cells from the eye) through the
// resident brick at `slot` (o: the eye in brick-local cells): samples at the fixed steps
// t_i = (i + 0.5) * P.foamStep of the whole ray, each absorbing and emitting 1 - exp(-sigma
// density step) of what is left (§3.5). Stops once the opacity reaches P.foamOpacityStop.
FS_FUNC float rcAccumulateFoam(float opacity, uint slot, vec3 o, vec3 dir, float a, float b) {
  float step = P.foamStep;
  float i = -floor(0.5f - a / step);  // the first i with t_i >= a
  int n = int(P.overlap);
  for (uint k = 0u; k < kRaycastMaxSteps && opacity < P.foamOpacityStop; k++) {
    float t = (i + 0.5f) * step;
    if (t >= b) break;
    i += 1.0f;
    // Empty-space skipping: no foam within a sub-brick of the sample, no density.
    vec3 p = o + t * dir;
    ivec3 cell = clamp(ivec3(floor(p)), ivec3(-n), ivec3(int(P.brickSize) + n - 1));
    uint subBrick = bitBrickSubBrickIndex(cell, P.brickSize, P.overlap);
    if (((rcFoamOccupancy(slot, subBrick >> 5u) >> (subBrick & 31u)) & 1u) == 0u) continue;
    float density = rcFoamDensity(slot, p);
    if (density > 0.0f) opacity += (1.0f - opacity) * (1.0f - exp(-P.foamExtinction * density * step));
  }
  return opacity;
}

// Whether `ray` has met foam opaque enough to end it (kFoamVolume).
FS_FUNC bool rcFoamOpaque(RayHit ray) { return (P.foamFlags & kFoamVolume) != 0u && ray.foam >= P.foamOpacityStop; }

FS_FUNC float rcCellAttribute(uint slot, ivec3 cell) {
  if (P.attributes == 0u) return 0.0f;
  uint subBrick = bitBrickSubBrickIndex(cell, P.brickSize, P.overlap);
  uvec4 bits = rcSubBrick(slot, subBrick);
  uint index = bitBrickAttributeOffset(rcAttributeBase(slot, subBrick), bits, bitBrickBitIndex(cell, P.overlap));
  return float(rcAttribute(index)) / 65535.0f;
}

// Whether the mip block of `level` around brick-local `cell` is clear (holds no sphere).
FS_FUNC bool rcMipClear(uint slot, uint level, ivec3 cell) {
  uvec3 s = uvec3(cell + ivec3(int(P.overlap)));
  uvec3 block = uvec3(s.x >> (level + 1u), s.y >> (level + 1u), s.z >> (level + 2u));
  uvec4 dims = P.mipLevels[level - 1u];
  uint bit = block.x + dims.x * (block.y + dims.y * block.z);
  uint word = rcMipWord(slot, dims.w + (bit >> 5u));
  return ((word >> (bit & 31u)) & 1u) == 0u;
}

// Empty-space skipping (§4.2): where the ray o + t d (invDir = 1 / d, brick-local cells) leaves
// the coarsest clear mip block around brick-local `cell`, or -1 when the cell's level-1 block
// is set (its spheres must be tested). A block's parent covers it, so once a level is set every
// coarser one is too: walk up from level 1.
FS_FUNC float rcClearBlockExit(uint slot, ivec3 cell, vec3 o, vec3 invDir) {
  uint clearLevel = 0u;
  for (uint level = 1u; level <= P.mipLevelCount; level++) {
    if (!rcMipClear(slot, level, cell)) break;
    clearLevel = level;
  }
  if (clearLevel == 0u) return -1.0f;
  int overlap = int(P.overlap);
  ivec3 size = ivec3(2 << clearLevel, 2 << clearLevel, 4 << clearLevel);
  ivec3 s = cell + ivec3(overlap);  // >= 0; sizes are powers of two
  ivec3 lo = (s & ~(size - ivec3(1))) - ivec3(overlap);
  return max(rcBoxSpan(o, invDir, vec3(lo), vec3(lo + size)).y, 0.0f);
}

// The nearest sphere a brick march has met so far: its distance along the ray (3e38 while
// none), the brick-local cell whose sphere it is, and the unnormalized normal at the hit.
struct NearestSphere {
  float t;
  ivec3 cell;
  vec3 normal;
};

FS_FUNC NearestSphere rcNoSphere() {
  NearestSphere none;
  none.t = 3.0e38f;
  none.cell = ivec3(0);
  none.normal = vec3(0.0f);
  return none;
}

// §3.3.1: `nearest`, or the sphere of brick-local `cell`, centred at `centre`, where the ray
// through brick-local point p = o + t dir meets it nearer (at t >= 0). Solved from p, not from
// the ray's origin: p is within a few cells of the centre, so b * b - c does not cancel
// catastrophically far from the camera.
FS_FUNC NearestSphere rcNearerSphere(NearestSphere nearest, ivec3 cell, vec3 centre, vec3 p, float t, vec3 dir) {
  float radius = P.radius;
  vec3 oc = p - centre;
  float b = dot(oc, dir);
  float c = dot(oc, oc) - radius * radius;
  float disc = b * b - c;
  if (disc < 0.0f) return nearest;
  float local = -b - sqrt(disc);
  float tHit = t + local;
  if (tHit >= 0.0f && tHit < nearest.t) {
    nearest.t = tHit;
    nearest.cell = cell;
    nearest.normal = (oc + local * dir) / radius;
  }
  return nearest;
}

// Makes `ray` a hit on the sphere `nearest` of `slot`. A march ends on it once it lies no
// farther than the exit of the cell just tested: a nearer one would have been found in an
// earlier cell.
FS_FUNC void rcSphereHit(FS_INOUT(RayHit) ray, uint slot, NearestSphere nearest) {
  ray.normal = vec4(normalize(nearest.normal), rcCellAttribute(slot, nearest.cell));
  ray.t = nearest.t;
  ray.status = kRayHit;
}

// Traces the segment [t, tEnd] of the ray through resident brick `brick` (at `slot`). Makes
// `result` a hit (status kRayHit) or leaves its status pending; with kFoamVolume it adds the foam
// in front of the hit (or of tEnd) to result.foam and returns as soon as rcFoamOpaque.
FS_FUNC void rcTraceBrick(FS_INOUT(RayHit) result, uint slot, uvec3 brick, vec3 eye, vec3 dir, float t, float tEnd) {
  int B = int(P.brickSize);
  int k = int(P.reach);
  float jitter = P.maxJitter;
  vec3 brickOrigin = vec3(brick * uvec3(uint(B)));
  vec3 o = eye - brickOrigin;  // ray origin in brick-local cells
  vec3 invDir = rcSafeInverse(dir);
  // The nearest sphere hit found so far, from any cell tested in this brick. Spheres of cells
  // within k of the previously tested cell were tested already: a step tests only the cells
  // that enter the neighbourhood (9 of 27 for k = 1 on a face step).
  NearestSphere nearest = rcNoSphere();
  ivec3 previous = ivec3(-1000000);
  for (uint step = 0u; step < kRaycastMaxSteps; step++) {
    if (t > tEnd) return;
    vec3 p = o + t * dir;
    ivec3 cell = clamp(ivec3(floor(p)), ivec3(0), ivec3(B - 1));
    float clearExit = rcClearBlockExit(slot, cell, o, invDir);
    if (clearExit >= 0.0f) {
      t = rcStepPast(clearExit);
      continue;
    }
    // §3.3.1: ray-sphere tests against the jittered centres of the cells around this one.
    for (int dz = -k; dz <= k; dz++) {
      for (int dy = -k; dy <= k; dy++) {
        for (int dx = -k; dx <= k; dx++) {
          ivec3 q = cell + ivec3(dx, dy, dz);
          ivec3 seen = abs(q - previous);
          if (max(max(seen.x, seen.y), seen.z) <= k) continue;
          if (!rcSurfaceCellSet(slot, q)) continue;
          vec3 centre = vec3(q) + vec3(0.5f);
          if (jitter > 0.0f) {
            uvec3 global = uvec3(ivec3(brick * uvec3(uint(B))) + q);
            centre += cellJitter(global, P.timeStep, jitter);
          }
          nearest = rcNearerSphere(nearest, q, centre, p, t, dir);
        }
      }
    }
    previous = cell;
    float cellExit = rcBoxSpan(o, invDir, vec3(cell), vec3(cell + ivec3(1))).y;
    if ((P.foamFlags & kFoamVolume) != 0u) {
      result.foam = rcAccumulateFoam(result.foam, slot, o, dir, t, min(cellExit, nearest.t));
      if (rcFoamOpaque(result)) return;
    }
    if (nearest.t <= cellExit) {
      rcSphereHit(result, slot, nearest);
      return;
    }
    t = rcStepPast(cellExit);
  }
}

// Index of `brick` (brick-grid coordinates inside the grid) in the frame's brick table, or
// kNotResident when the presence octree has no such brick.
FS_FUNC uint rcBrickIndex(uvec3 brick) {
  uint levels = P.octreeLevels;
  uint node = 0u;
  uvec3 origin = uvec3(0u);
  for (uint level = 0u; level < levels; level++) {
    uint halfSize = 1u << (levels - 1u - level);
    uvec3 octant = uvec3(brick.x - origin.x >= halfSize ? 1u : 0u, brick.y - origin.y >= halfSize ? 1u : 0u,
                         brick.z - origin.z >= halfSize ? 1u : 0u);
    uint child = octant.x | (octant.y << 1u) | (octant.z << 2u);
    uvec2 n = rcNode(node);
    origin += octant * uvec3(halfSize);
    if (((n.x >> child) & 1u) == 0u) return kNotResident;
    node = n.y + uint(bitCount(n.x & ((1u << child) - 1u)));
  }
  return node;
}

// What rcThickness measured: the liquid in cells, and kNotResident or the index of a brick on
// the way that is not resident (cells is then incomplete).
struct ThicknessTrace {
  float cells;
  uint missingBrick;
};

// Thickness of the liquid behind a hit at tHit (§3.6: "tracing each ray through the fluid body,
// using our proposed density calculation, until maximum absorption is reached"): the density of
// the sphere cells (rcLiquidDensity) summed at steps of kThicknessStep cells along the ray until
// it reaches P.thicknessSaturationCells cells, after kThicknessMaxCells cells, or at the grid's
// end. With P.thicknessBestEffort = 1u, bricks that are not resident count as empty.
FS_FUNC ThicknessTrace rcThickness(vec3 eye, vec3 dir, float tHit) {
  int B = int(P.brickSize);
  int brickShift = findLSB(P.brickSize);  // B is a power of two
  ivec3 gridCells = ivec3(P.bricksPerAxis) * B;
  bool bestEffort = P.thicknessBestEffort != 0u;
  ivec3 current = ivec3(-1);
  uint slot = kNotResident;
  ThicknessTrace trace;
  trace.cells = 0.0f;
  trace.missingBrick = kNotResident;
  for (uint i = 0u; i < kThicknessMaxCells / kThicknessStep && trace.cells < P.thicknessSaturationCells; i++) {
    vec3 p = eye + (tHit + (0.5f + float(i)) * float(kThicknessStep)) * dir;
    ivec3 cell = ivec3(floor(p));
    if (cell.x < 0 || cell.y < 0 || cell.z < 0 || cell.x >= gridCells.x || cell.y >= gridCells.y ||
        cell.z >= gridCells.z)
      break;
    ivec3 brick = cell >> brickShift;  // cell >= 0
    if (brick.x != current.x || brick.y != current.y || brick.z != current.z) {
      current = brick;
      uint index = rcBrickIndex(uvec3(brick));
      slot = index == kNotResident ? kNotResident : rcPage(index);
      if (index != kNotResident && slot == kNotResident && !bestEffort) {
        trace.missingBrick = index;
        return trace;
      }
    }
    if (slot != kNotResident) trace.cells += rcLiquidDensity(slot, cell - brick * B) * float(kThicknessStep);
  }
  return trace;
}

// Continues `result` (pending, from result.t) for `pixel` until it hits, misses, or stops at a
// brick that is not resident (then requested). A ray that exhausts kRaycastMaxSteps is a miss.
FS_FUNC void rcTrace(uvec2 pixel, FS_INOUT(RayHit) result) {
  float resume = result.t;
  vec3 eye = vec3(P.eye.x, P.eye.y, P.eye.z);
  vec3 dir = rcCameraRay(pixel);
  vec3 invDir = rcSafeInverse(dir);
  uint B = P.brickSize;
  vec3 gridCells = vec3(uvec3(P.bricksPerAxis) * uvec3(B));
  vec2 domain = rcBoxSpan(eye, invDir, vec3(0.0f), gridCells);
  result.status = kRayMiss;
  result.brickIndex = kNotResident;
  result.depth = 0.0f;
  result.t = 0.0f;  // a miss carries no distance
  if (P.frameBricks == 0u || domain.x > domain.y || domain.y < 0.0f) return;
  float t = max(max(resume, domain.x), 0.0f);
  uint levels = P.octreeLevels;
  for (uint step = 0u; step < kRaycastMaxSteps; step++) {
    if (t > domain.y) return;
    vec3 p = eye + t * dir;
    // B is a power of two: multiplying by 1 / B is exact, and cheaper than dividing.
    uvec3 brick = uvec3(clamp(ivec3(floor(p * (1.0f / float(B)))), ivec3(0), ivec3(P.bricksPerAxis) - ivec3(1)));
    // 1. Descend the presence octree to the brick, or to the empty octant holding the point.
    uint node = 0u;
    uvec3 origin = uvec3(0u);
    uint brickIndex = kNotResident;
    float emptyExit = -1.0f;
    for (uint level = 0u; level < levels; level++) {
      uint halfSize = 1u << (levels - 1u - level);
      uvec3 octant = uvec3(brick.x - origin.x >= halfSize ? 1u : 0u, brick.y - origin.y >= halfSize ? 1u : 0u,
                           brick.z - origin.z >= halfSize ? 1u : 0u);
      uint child = octant.x | (octant.y << 1u) | (octant.z << 2u);
      uvec2 n = rcNode(node);
      origin += octant * uvec3(halfSize);
      if (((n.x >> child) & 1u) == 0u) {
        vec3 lo = vec3(origin * uvec3(B));
        emptyExit = rcBoxSpan(eye, invDir, lo, lo + vec3(float(halfSize * B))).y;
        break;
      }
      uint index = n.y + uint(bitCount(n.x & ((1u << child) - 1u)));
      if (level + 1u == levels) brickIndex = index;
      node = index;
    }
    if (brickIndex == kNotResident) {
      t = rcStepPast(max(emptyExit, t));
      continue;
    }
    // 2. Stop at a brick that is not resident.
    uint slot = rcPage(brickIndex);
    if (slot == kNotResident) {
      rcRequest(brickIndex);
      result.t = t;
      result.status = kRayPending;
      result.brickIndex = brickIndex;
      return;
    }
    // 3. March the brick.
    vec3 lo = vec3(brick * uvec3(B));
    float brickExit = rcBoxSpan(eye, invDir, lo, lo + vec3(float(B))).y;
    result.status = kRayPending;
    rcMarchBrick(result, slot, brick, eye, dir, t, brickExit);
    if (rcFoamOpaque(result)) {
      result.status = kRayMiss;
      return;
    }
    if (result.status == kRayHit) {
      result.brickIndex = brickIndex;
      result.depth = result.t * P.cellSize * dot(dir, vec3(P.forward.x, P.forward.y, P.forward.z));
      return;
    }
    result.status = kRayMiss;
    t = rcStepPast(max(brickExit, t));
  }
}

// Fills in the thickness of a hit `ray` (status kRayHit) for `pixel`: the bricks behind the hit
// must be resident; a missing one is requested and the thickness stays -1 (unknown), so the
// next pass comes back to it. The hit itself is final. P.thicknessSaturationCells = 0: thickness
// 0 at once.
FS_FUNC void rcResolveThickness(uvec2 pixel, FS_INOUT(RayHit) ray) {
  ray.thickness = 0.0f;
  if (P.thicknessSaturationCells <= 0.0f) return;
  vec3 eye = vec3(P.eye.x, P.eye.y, P.eye.z);
  ThicknessTrace trace = rcThickness(eye, rcCameraRay(pixel), ray.t);
  if (trace.missingBrick != kNotResident) {
    rcRequest(trace.missingBrick);
    ray.thickness = -1.0f;
  } else {
    ray.thickness = trace.cells * P.cellSize;
  }
}

// Whether a pass still has work for `ray`: a pending ray, or a hit whose thickness is unknown.
FS_FUNC bool rcNeedsPass(RayHit ray) {
  return ray.status == kRayPending || (ray.status == kRayHit && ray.thickness < 0.0f);
}

// One pass of the ray of `pixel`: continues a pending ray (rcTrace), or resolves a hit's thickness.
FS_FUNC void rcPass(uvec2 pixel, FS_INOUT(RayHit) ray) {
  if (ray.status == kRayPending) {
    rcTrace(pixel, ray);
    if (ray.status == kRayHit) rcResolveThickness(pixel, ray);
    return;
  }
  rcResolveThickness(pixel, ray);
}
