// CpuRaycaster: the C++ reference of the compute ray-caster. It runs raycast/glsl/Raycast.glsl
// and raycast/glsl/FoamClassify.glsl compiled as C++ (see core/GlslShared.h) over a pool held in
// plain arrays, one TBB task per image row (per sub-brick for the foam), so tests can compare the
// GPU's images with it pixel by pixel.
#pragma once

#include <functional>

#include "core/UninitializedVector.h"
#include "raycast/ClearDistance.h"
#include "raycast/RaycastDevice.h"

namespace flipscope {

namespace glsl {
struct RaycastPoolAccess;
}

class CpuRaycaster : public RaycastDevice {
 public:
  std::string name() const override;
  void allocatePool(const PoolLayout& layout) override;
  void setOctree(std::span<const OctreeNode> nodes) override;
  void setPageTable(std::span<const std::uint32_t> pageTable) override;
  void uploadBrick(std::uint32_t slot, std::uint64_t attributeOffset, const ConvertedBrick& brick) override;
  /// In parallel: a slot's arrays (and march tables) are its own, and a batch's ring ranges
  /// do not overlap.
  void uploadBricks(std::span<const BrickUpload> uploads) override;
  void classifyFoam(std::span<const std::uint32_t> slots, const FoamClassifyParams& params) override;
  double lastClassifyMs() const override { return mLastClassifyMs; }
  std::vector<glm::uvec4> readFoam(std::uint32_t slot) override;
  void beginImage(std::uint32_t width, std::uint32_t height) override;
  std::vector<std::uint32_t> trace(const RaycastParams& params) override;
  double lastTraceMs() const override { return mLastTraceMs; }
  std::vector<RayHit> readHits() override {
    const std::span<const RayHit> h = hits();
    return {h.begin(), h.end()};
  }
  /// The image's rays in place, for the passes after the ray-caster (fresh pending rays before
  /// the first pass).
  std::span<const RayHit> hits();

  /// The pool's arrays, laid out as the GPU's buffers. Slots are left uninitialized until a
  /// brick is uploaded (the page table never points at an empty slot), so a large budget costs
  /// no time to allocate.
  struct Pool {
    PoolLayout layout;
    std::vector<glm::uvec2> nodes;
    std::vector<std::uint32_t> pageTable;
    UninitializedVector<glm::uvec4> subBricks;
    UninitializedVector<std::uint32_t> mipWords;
    UninitializedVector<std::uint32_t> attributeBases;
    UninitializedVector<std::uint16_t> attributes;
    UninitializedVector<glm::uvec4> foamBits;  ///< with a foam pool: per slot, as subBricks
    UninitializedVector<std::uint32_t> foamOccupancy;  ///< per slot, PoolLayout::foamOccupancyWords
    /// With PoolLayout::marchTables: per slot and sub-brick, the sphere cells of its lower and
    /// upper half (rcLiquidHalfCountOfBits), then its foam cells (rcFoamHalfCountOfBits);
    UninitializedVector<std::uint8_t> halfCounts;
    /// per slot, its NearSphereMask (nearSphereMaskWords) for spheres of PoolLayout::reach;
    UninitializedVector<std::uint64_t> nearSpheres;
    /// per slot and sub-brick (a level-1 mip block), its ClearDistance;
    UninitializedVector<std::uint8_t> clearDistances;
    /// per slot and group of 4^3 brick cells (nearSphereGroups), the ClearDistance of the
    /// groups with a cell set in the NearSphereMask;
    UninitializedVector<std::uint8_t> nearDistances;
    /// and per slot, the bounds of the set blocks of both tables.
    struct SetBounds {
      SetBlockBounds mipBlocks, nearGroups;
    };
    std::vector<SetBounds> setBounds;
  };
  const Pool& pool() const { return mPool; }

 protected:
  /// classifyFoam's frame: for each slot, in parallel, `classify` writes its foam bits (in place,
  /// as fcClassify gives them), then its foam occupancy (fcOccupancyWord); records
  /// lastClassifyMs.
  void timedClassify(std::span<const std::uint32_t> slots, const FoamClassifyParams& params,
                     const std::function<void(std::uint32_t slot)>& classify);
  /// One pass of trace(): `pass` continues the pending rays of mHits through the pool that
  /// `access` reads, whose rcRequest flags the bricks they stop at. Returns those bricks
  /// ascending and records lastTraceMs.
  std::vector<std::uint32_t> timedPass(const RaycastParams& params,
                                       const std::function<void(const glsl::RaycastPoolAccess& access)>& pass);

  /// Ray i as a pass finds it: a fresh pending ray in the first pass after beginImage, which
  /// leaves the rays unwritten (a fresh ray always needs the pass, which writes it), else
  /// mHits[i]. timedPass ends the freshness.
  RayHit rayAt(std::size_t i) const { return mRaysFresh ? RayHit{} : mHits[i]; }

  Pool mPool;
  UninitializedVector<RayHit> mHits;  ///< (the first pass writes every ray, on every core)
  bool mRaysFresh = false;  ///< mHits not yet written since beginImage
  std::uint32_t mWidth = 0, mHeight = 0;

 private:
  double mLastTraceMs = 0;
  double mLastClassifyMs = 0;
};

}  // namespace flipscope
