#include "raycast/TiledCpuRaycaster.h"

#include <array>
#include <thread>

#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "core/Error.h"
#include "raycast/ClearDistance.h"
#include "raycast/CpuRaycastKernel.h"
#include "raycast/FoamNeighbourCount.h"
#include "raycast/NearSphereMask.h"

namespace flipscope {
namespace {
constexpr std::uint32_t kTileSize = 16;  ///< pixels per tile edge
}  // namespace

namespace glsl {
namespace {

/// The jitter offsets (§3.2.2, cellJitter) of the cells a thread's rays tested, direct-mapped
/// by global cell, for one pass (one time step and jitter amplitude).
class JitterCache {
 public:
  JitterCache(uint timeStep, float maxJitter) : mTimeStep(timeStep), mMaxJitter(maxJitter) {}

  vec3 offset(uvec3 globalCell) {
    // Global cells are below 2^20 per axis (Jitter.glsl); a border cell left of the grid's
    // origin comes as a wrapped negative (as in rcTraceBrick). 21 bits per axis keep both
    // apart, and the key below 2^63 is never kEmpty.
    constexpr std::uint64_t kAxis = (std::uint64_t(1) << 21) - 1;
    const std::uint64_t key = (globalCell.x & kAxis) | ((std::uint64_t(globalCell.y) & kAxis) << 21) |
                              ((std::uint64_t(globalCell.z) & kAxis) << 42);
    Entry& entry = mEntries[(key * 0x9e3779b97f4a7c15ull) >> (64 - kIndexBits)];
    if (entry.key != key) {
      entry.key = key;
      entry.offset = cellJitter(globalCell, mTimeStep, mMaxJitter);
    }
    return entry.offset;
  }

 private:
  static constexpr int kIndexBits = 12;
  static constexpr std::uint64_t kEmpty = ~std::uint64_t(0);
  struct Entry {
    std::uint64_t key = kEmpty;
    vec3 offset{0.0f};
  };
  uint mTimeStep;
  float mMaxJitter;
  std::array<Entry, std::size_t(1) << kIndexBits> mEntries{};
};

/// Raycast.glsl with the brick march below in place of rcTraceBrick. The shared code comes
/// first, so that its types (NearestSphere) name this struct's parameters.
struct TiledRaycastKernel : RaycastPoolAccess {
#include "raycast/glsl/Raycast.glsl"

  TiledRaycastKernel(const RaycastPoolAccess& access, JitterCache& jitter)
      : RaycastPoolAccess(access),
        jitter(&jitter),
        B(int(P.brickSize)),
        k(int(P.reach)),
        overlap(int(P.overlap)),
        subBrickDims(bitBrickSubBrickDims(P.brickSize, P.overlap)) {}

  JitterCache* jitter;
  int B, k, overlap;
  uvec3 subBrickDims;

  /// The half counts Raycast.glsl reads, from the pool's table (Pool::halfCounts), which holds
  /// the sphere cells without the foam cells whenever the pool has foam (FrameRenderer sets
  /// kFoamSkip then).
  uint rcLiquidHalfCount(uint slot, uvec2 h) {
    if (pool->layout.foam && (P.foamFlags & kFoamSkip) == 0u) return rcLiquidHalfCountOfBits(slot, h);
    return pool->halfCounts[(std::size_t(slot) * P.subBricksPerSlot + h.x) * 4u + h.y];
  }
  uint rcFoamHalfCount(uint slot, uvec2 h) {
    return pool->halfCounts[(std::size_t(slot) * P.subBricksPerSlot + h.x) * 4u + 2u + h.y];
  }

  /// Tests the sphere of brick-local cell (x, y, z) (in [-n, B + n)) of the slot whose bits
  /// (and foam bits, or null) are given, if it holds one, against the ray through brick-local
  /// point p = o + t dir (rcNearerSphere, as rcTraceBrick). The cell's bit is read straight from
  /// the sub-brick, with scalars: this is the inner loop.
  [[gnu::always_inline]] void testCell(NearestSphere& nearest, const uvec4* bits, const uvec4* foam, uvec3 brickCell,
                                       int x, int y, int z, vec3 p, float t, vec3 dir) {
    const uint sx = uint(x + overlap), sy = uint(y + overlap), sz = uint(z + overlap);
    const uint subBrick = (sx >> 2u) + subBrickDims.x * ((sy >> 2u) + subBrickDims.y * (sz >> 3u));
    const uint bit = (sx & 3u) | ((sy & 3u) << 2u) | ((sz & 7u) << 4u);
    uint word = (&bits[subBrick].x)[bit >> 5u];
    if (foam) word &= ~(&foam[subBrick].x)[bit >> 5u];
    if (((word >> (bit & 31u)) & 1u) == 0u) return;
    vec3 centre = vec3(float(x) + 0.5f, float(y) + 0.5f, float(z) + 0.5f);
    if (P.maxJitter > 0.0f) centre += jitter->offset(brickCell + uvec3(uint(x), uint(y), uint(z)));
    nearest = rcNearerSphere(nearest, ivec3(x, y, z), centre, p, t, dir);
  }

  /// rcTraceBrick's contract and result: the segment [t, tEnd] of the ray through the resident
  /// brick `brick` at `slot`, front to back, a 3D DDA from cell to cell. The first cell tests its
  /// whole (2k+1)^3 neighbourhood; a step along an axis tests the slab that enters it; a cell
  /// without a sphere near (the slot's NearSphereMask) tests none. A cube of clear blocks
  /// (ClearDistance) is crossed at once; no sphere lies within k of it (the mipmap's dilation is
  /// the reach, buildBrickMipmap), so the cell a ray meets on leaving one through a face tests
  /// only its far slab, as after a step; through an edge or a corner, its whole neighbourhood.
  /// The DDA's state is kept in scalar arrays (a vector indexed by a run-time axis goes through
  /// memory). The vectors come by reference: by value, rcTrace stored them in parts just before
  /// the call and the call read them whole, and such a load waits for those stores.
  void rcMarchBrick(RayHit& ray, uint slot, const uvec3& brick, const vec3& eye, const vec3& dir, float t,
                    float tEnd) {
    const uvec3 brickCell = brick * uvec3(uint(B));
    const vec3 o = eye - vec3(brickCell);
    const vec3 invDir = rcSafeInverse(dir);
    const std::size_t first = std::size_t(slot) * P.subBricksPerSlot;
    const uvec4* bits = pool->subBricks.data() + first;
    const uvec4* foam = (P.foamFlags & kFoamSkip) != 0u ? pool->foamBits.data() + first : nullptr;
    // The slot's NearSphereMask, when it holds the spheres this march tests (without the foam
    // cells exactly when they are skipped) for this reach.
    const bool maskHolds = (!pool->layout.foam || foam) && uint(k) == pool->layout.reach;
    const std::uint64_t* near =
        maskHolds ? pool->nearSpheres.data() + std::size_t(slot) * nearSphereMaskWords(uint(B)) : nullptr;
    const uint rowWords = uint(B + 63) / 64u;
    // Empty space to skip (ClearDistance): with the mask, cubes of 4^3-cell groups with no sphere
    // near; else, and with the foam volume (whose cells the mask leaves out but the ray
    // gathers), cubes of clear level-1 mip blocks (4x4x8 stored cells, foam cells included).
    const bool groups = near && (P.foamFlags & kFoamVolume) == 0u;
    const int groupsPerEdge = B / int(kNearGroupCells);
    const std::uint8_t* distances =
        groups ? pool->nearDistances.data() + std::size_t(slot) * nearSphereGroupCount(uint(B))
               : pool->clearDistances.data() + first;
    const ivec3 blockCells = groups ? ivec3(int(kNearGroupCells)) : ivec3(kSubBrickCells);
    const ivec3 blockShift = groups ? ivec3(2) : ivec3(2, 2, 3);
    const ivec3 blockDims = groups ? ivec3(groupsPerEdge) : ivec3(subBrickDims);
    const int blockOrigin = groups ? 0 : overlap;  // the first block's corner is at brick-local -blockOrigin
    // Outside the box of the set blocks there is nothing to test (nor foam to gather, for the
    // level-1 blocks): start and end there.
    const SetBlockBounds bounds = groups ? pool->setBounds[slot].nearGroups : pool->setBounds[slot].mipBlocks;
    if (bounds.empty()) return;
    const vec2 span = rcBoxSpan(o, invDir, vec3(bounds.lo * blockCells - ivec3(blockOrigin)),
                                vec3(bounds.hi * blockCells - ivec3(blockOrigin)));
    t = max(t, span.x);
    tEnd = min(tEnd, span.y);
    const float origin[3] = {o.x, o.y, o.z};
    const float inverse[3] = {invDir.x, invDir.y, invDir.z};
    const int step[3] = {dir.x < 0.0f ? -1 : 1, dir.y < 0.0f ? -1 : 1, dir.z < 0.0f ? -1 : 1};
    NearestSphere nearest = rcNoSphere();
    int cell[3] = {0, 0, 0};
    float exit[3] = {0.0f, 0.0f, 0.0f};  // where the ray leaves the cell across each axis's far plane
    bool located = false;
    // The last cube of clear blocks skipped, [clearLo, clearHi) in brick-local cells, while the
    // ray has met no other cell since.
    bool leftClearBlock = false;
    int clearLo[3] = {0, 0, 0}, clearHi[3] = {0, 0, 0};
    auto planeExit = [&](int axis) {
      return (float(cell[axis] + (step[axis] > 0 ? 1 : 0)) - origin[axis]) * inverse[axis];
    };
    for (uint n = 0u; n < kRaycastMaxSteps; n++) {
      int axis = -1;  // the axis of the DDA step into this cell; -1 when located afresh
      // The one slab of the neighbourhood to test, at cell[slabAxis] + slabSide * k; slabAxis -1
      // tests the whole neighbourhood.
      int slabAxis = -1, slabSide = 0;
      if (located) {
        axis = exit[0] <= exit[1] ? (exit[0] <= exit[2] ? 0 : 2) : (exit[1] <= exit[2] ? 1 : 2);
        t = rcStepPast(exit[axis]);
        cell[axis] += step[axis];
        if (t > tEnd || cell[axis] < 0 || cell[axis] >= B) return;
        slabAxis = axis;
        slabSide = step[axis];
      } else {
        if (t > tEnd) return;
        const ivec3 c = clamp(ivec3(floor(o + t * dir)), ivec3(0), ivec3(B - 1));
        cell[0] = c.x;
        cell[1] = c.y;
        cell[2] = c.z;
      }
      const ivec3 block = (ivec3(cell[0], cell[1], cell[2]) + ivec3(blockOrigin)) >> blockShift;
      const int distance = distances[block.x + blockDims.x * (block.y + blockDims.y * block.z)];
      if (distance > 0) {
        // The cube of clear blocks within distance - 1 of this one (ClearDistance).
        const ivec3 lo = (block - ivec3(distance - 1)) * blockCells - ivec3(blockOrigin);
        const ivec3 hi = (block + ivec3(distance)) * blockCells - ivec3(blockOrigin);
        t = rcStepPast(max(rcBoxSpan(o, invDir, vec3(lo), vec3(hi)).y, 0.0f));
        located = false;
        leftClearBlock = true;
        clearLo[0] = lo.x, clearLo[1] = lo.y, clearLo[2] = lo.z;
        clearHi[0] = hi.x, clearHi[1] = hi.y, clearHi[2] = hi.z;
        continue;
      }
      if (leftClearBlock) {
        const SlabAfterClearCube slab = slabAfterClearCube(cell, clearLo, clearHi);
        slabAxis = slab.axis;
        slabSide = slab.side;
        leftClearBlock = false;
      }
      const vec3 p = o + t * dir;
      // With no sphere within k of this cell, its neighbourhood (and so the slab) holds none.
      const bool test =
          !near || ((near[uint(cell[2] * B + cell[1]) * rowWords + (uint(cell[0]) >> 6u)] >> (cell[0] & 63)) & 1u) != 0u;
      if (axis < 0) {
        for (int a = 0; a < 3; a++) exit[a] = planeExit(a);
        located = true;
      } else {
        exit[axis] = planeExit(axis);
      }
      if (test && slabAxis < 0) {
        for (int z = cell[2] - k; z <= cell[2] + k; z++)
          for (int y = cell[1] - k; y <= cell[1] + k; y++)
            for (int x = cell[0] - k; x <= cell[0] + k; x++) testCell(nearest, bits, foam, brickCell, x, y, z, p, t, dir);
      } else if (test) {
        const int slab = cell[slabAxis] + slabSide * k;
        if (slabAxis == 0) {
          for (int z = cell[2] - k; z <= cell[2] + k; z++)
            for (int y = cell[1] - k; y <= cell[1] + k; y++) testCell(nearest, bits, foam, brickCell, slab, y, z, p, t, dir);
        } else if (slabAxis == 1) {
          for (int z = cell[2] - k; z <= cell[2] + k; z++)
            for (int x = cell[0] - k; x <= cell[0] + k; x++) testCell(nearest, bits, foam, brickCell, x, slab, z, p, t, dir);
        } else {
          for (int y = cell[1] - k; y <= cell[1] + k; y++)
            for (int x = cell[0] - k; x <= cell[0] + k; x++) testCell(nearest, bits, foam, brickCell, x, y, slab, p, t, dir);
        }
      }
      const float cellExit = std::min(std::min(exit[0], exit[1]), exit[2]);
      if ((P.foamFlags & kFoamVolume) != 0u) {
        ray.foam = rcAccumulateFoam(ray.foam, slot, o, dir, t, min(cellExit, nearest.t));
        if (rcFoamOpaque(ray)) return;
      }
      if (nearest.t <= cellExit) {
        rcSphereHit(ray, slot, nearest);
        return;
      }
    }
  }
};

}  // namespace
}  // namespace glsl

std::string TiledCpuRaycaster::name() const {
  return "CPU (" + std::to_string(std::thread::hardware_concurrency()) + " threads)";
}

void TiledCpuRaycaster::buildMarchTables(std::uint32_t slot) {
  const PoolLayout& layout = mPool.layout;
  FLIPSCOPE_CHECK(layout.marchTables && slot < layout.slots);
  const std::size_t first = std::size_t(slot) * layout.subBricksPerSlot;
  std::uint64_t* mask = &mPool.nearSpheres[std::size_t(slot) * nearSphereMaskWords(layout.brickSize)];
  buildNearSphereMask(&mPool.subBricks[first], layout.foam ? &mPool.foamBits[first] : nullptr, layout.brickSize,
                      layout.overlap, layout.reach, mask);
  const std::uint32_t groupsPerEdge = layout.brickSize / kNearGroupCells;
  std::array<std::uint32_t, 128 * 128 * 128 / 64 / 32> groups;  // of a brick of at most 128^3
  nearSphereGroups(mask, layout.brickSize, groups.data());
  buildClearDistances(groups.data(), glm::uvec3(groupsPerEdge),
                      &mPool.nearDistances[std::size_t(slot) * nearSphereGroupCount(layout.brickSize)]);
  // Level-1 mip bits lead the slot's mip words (bitBrickMipWordOffset(1) = 0).
  const std::uint32_t* level1 = &mPool.mipWords[std::size_t(slot) * layout.mipWordsPerSlot];
  const glm::uvec3 level1Dims = bitBrickMipDims(1u, layout.brickSize, layout.overlap);
  buildClearDistances(level1, level1Dims, &mPool.clearDistances[first]);
  mPool.setBounds[slot] = {setBlockBounds(level1, level1Dims), setBlockBounds(groups.data(), glm::uvec3(groupsPerEdge))};
  for (std::size_t s = first; s < first + layout.subBricksPerSlot; ++s) {
    const glm::uvec4 foam = layout.foam ? mPool.foamBits[s] : glm::uvec4(0);
    const glm::uvec4 liquid = mPool.subBricks[s] & ~foam;
    std::uint8_t* counts = &mPool.halfCounts[s * 4];
    for (std::uint32_t upper = 0; upper < 2; ++upper) {
      counts[upper] = std::uint8_t(bitBrickHalfCount(liquid, upper));
      counts[2 + upper] = std::uint8_t(bitBrickHalfCount(foam, upper));
    }
  }
}

void TiledCpuRaycaster::uploadBrick(std::uint32_t slot, std::uint64_t attributeOffset, const ConvertedBrick& brick) {
  CpuRaycaster::uploadBrick(slot, attributeOffset, brick);
  // A foam pool's upload is classified (and counted there) before the next trace.
  if (!mPool.layout.foam) buildMarchTables(slot);
}

void TiledCpuRaycaster::classifyFoam(std::span<const std::uint32_t> slots, const FoamClassifyParams& params) {
  tbb::enumerable_thread_specific<FoamNeighbourScratch> scratch;
  timedClassify(slots, params, [&](std::uint32_t slot) {
    const std::size_t first = std::size_t(slot) * mPool.layout.subBricksPerSlot;
    classifyBrickFoam(&mPool.subBricks[first], &mPool.foamBits[first], params, scratch.local());
  });
  tbb::parallel_for(std::size_t(0), slots.size(), [&](std::size_t i) { buildMarchTables(slots[i]); });
}

std::vector<std::uint32_t> TiledCpuRaycaster::trace(const RaycastParams& params) {
  return timedPass(params, [&](const glsl::RaycastPoolAccess& access) {
    tbb::enumerable_thread_specific<glsl::JitterCache> caches(params.timeStep, params.maxJitter);
    const tbb::blocked_range2d<std::uint32_t> tiles(0, mHeight, kTileSize, 0, mWidth, kTileSize);
    tbb::parallel_for(tiles, [&](const tbb::blocked_range2d<std::uint32_t>& tile) {
      glsl::TiledRaycastKernel kernel(access, caches.local());
      // A row of at most kTileSize rays is traced into `row`, then copied out whole: the hits'
      // lines miss the cache (44 MB a 1280x720 frame), and a store that misses holds up every
      // later load that must wait for stores, so each is fetched for writing (prefetched)
      // before the row is traced.
      std::array<RayHit, kTileSize> row;
      for (std::uint32_t y = tile.rows().begin(); y != tile.rows().end(); ++y) {
        for (std::uint32_t x0 = tile.cols().begin(); x0 < tile.cols().end(); x0 += kTileSize) {
          const std::uint32_t columns = std::min(kTileSize, tile.cols().end() - x0);
          RayHit* out = &mHits[std::size_t(y) * mWidth + x0];
          for (std::size_t byte = 0; byte < columns * sizeof(RayHit); byte += 64)
            __builtin_prefetch(reinterpret_cast<const char*>(out) + byte, 1);
          for (std::uint32_t c = 0; c < columns; ++c) {
            row[c] = rayAt(std::size_t(y) * mWidth + x0 + c);
            if (kernel.rcNeedsPass(row[c])) kernel.rcPass(glm::uvec2(x0 + c, y), row[c]);
          }
          std::copy(row.begin(), row.begin() + columns, out);
        }
      }
    });
  });
}

}  // namespace flipscope
