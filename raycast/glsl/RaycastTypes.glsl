// Structs the CPU fills and the ray-caster reads, shared by C++ (raycast/RaycastTypes.h, which
// checks every offset) and GLSL; see core/GlslShared.h for the rules. RaycastParams is a std140
// uniform block, RayHit a std430 array element: only 16-byte vectors and scalars in groups of
// four, so both layouts equal the C++ one. Every field is named: no lane of a vector carries a
// second meaning.
//
// Units. The ray-caster works in grid cells: cell (i,j,k) spans [i, i+1) x ... and brick b spans
// cells [b*B, b*B + B). Grid and world axes are parallel (world = origin + cells * cellSize), so
// directions and normals are the same in both.

struct RaycastParams {
  vec4 eye;            // xyz: eye in grid cells; w: unused
  vec4 forward;        // xyz: unit view direction; w: unused
  vec4 right;          // xyz: unit right vector; w: unused
  vec4 up;             // xyz: unit up vector; w: unused
  uvec4 bricksPerAxis; // xyz: bricks of the grid per axis; w: unused
  float tanHalfFovY;   // tan(vertical fov / 2)
  float aspect;        // width / height
  float cellSize;      // world units (the depth output is in world units)
  float unused0;
  uint width;          // pixels
  uint height;         // pixels
  uint timeStep;       // the jitter's seed (§3.2.2)
  uint brickSize;      // cells per brick edge B, a power of two
  uint overlap;        // n: cells each stored bit-brick reaches beyond its brick on every side
  uint reach;          // k: a sphere reaches cells at most k away from its own
  uint octreeLevels;   // levels of the frame's presence octree (§3.2.1)
  uint subBricksPerSlot;
  uint mipWordsPerSlot;
  uint attributes;     // 1: the pool holds attributes; 0: hits report attribute 0
  uint frameBricks;    // bricks in the frame; 0: an empty frame, every ray misses
  uint mipLevelCount;  // levels of mipLevels in use (0 to kMaxMipLevels)
  float radius;        // sphere radius in cells
  float maxJitter;     // largest jitter offset of a sphere centre, cells (§3.2.2)
  uint thicknessBestEffort;        // 1: bricks behind a hit that are not resident count as
                                   // empty; 0: request them
  float thicknessSaturationCells;  // liquid thickness in cells at which absorption saturates: the
                                   // trace behind a hit stops there (§3.6); 0 = no thickness (a hit
                                   // is final at once)
  uint foamFlags;      // kFoamSkip | kFoamVolume (§3.5); 0: every set cell is a sphere
  float foamStep;      // volumetric foam (§3.5): the march's step in cells
  float foamExtinction;   // extinction per cell at foam density 1
  float foamOpacityStop;  // opacity at which the foam's march ends the ray
  uvec4 mipLevels[8];  // level k (1..mipLevelCount) at k - 1: xyz blocks per axis, w word offset
};

// One pixel's ray. All zeros is a fresh ray: pending from t = 0 (so a device clears the whole
// image with zeros). While pending, t is where the ray resumes (it stopped at a brick that was
// not resident); once hit, t is the hit distance in cells.
const uint kRayPending = 0u;
const uint kRayHit = 1u;
const uint kRayMiss = 2u;

struct RayHit {
  vec4 normal;     // xyz: unit sphere normal at the hit; w: attribute in [0, 1] (0 without)
  float t;         // cells along the unit ray direction
  uint status;     // kRayPending, kRayHit or kRayMiss
  float depth;     // linear camera depth in world units (t * cellSize * dot(dir, forward))
  uint brickIndex; // brick of the hit, or the brick a pending ray waits for (0 before the first
                   // pass), kNotResident on a miss
  float thickness; // liquid along the ray behind the hit, world units (§3.6): the density of the
                   // surface cells (set bits of the 4^3 half sub-brick at every kThicknessStep
                   // cells), summed until it reaches thicknessSaturationCells or after
                   // kThicknessMaxCells cells, times the cell size; -1 while the bricks it needs
                   // are not resident
  float foam;      // opacity of the volumetric foam in front of the hit (or along a miss), 0..1
                   // (§3.5); it accumulates while the ray is pending; 0 without kFoamVolume
  float unused1;
  float unused2;
};

const uint kNotResident = 0xffffffffu;
const uint kMaxMipLevels = 8u;  // 144 stored cells (128 + 2 x 8) make 7
const uint kRaycastMaxSteps = 65536u;  // bound on each traversal loop of one ray in one pass
const uint kThicknessMaxCells = 128u;  // cells behind a hit at most, for its thickness
const uint kThicknessStep = 2u;        // cells between its samples (the density is of 4^3 blocks)
const uint kFoamSkip = 1u;    // the pool's foam bit-bricks are valid: foam cells are no spheres
const uint kFoamVolume = 2u;  // foam is accumulated along the ray as a volume (with kFoamSkip)
