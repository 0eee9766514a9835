// RaycastDevice: where the ray-caster's passes run and its brick pool lives. Two of them, with
// the same contract and the same shared GLSL (raycast/glsl/Raycast.glsl): GpuRaycaster (OpenGL
// compute) and CpuRaycaster (the C++ reference the tests compare it with). FrameRenderer drives
// either one through the request-driven frame loop (Reichl et al. 2014 §3.3, §4.4).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "preprocess/store/PresenceOctree.h"
#include "raycast/BrickPool.h"
#include "raycast/FoamTypes.h"
#include "raycast/RaycastTypes.h"
#include "streaming/ConvertedBrickCache.h"

namespace flipscope {

class RaycastDevice {
 public:
  virtual ~RaycastDevice() = default;
  /// e.g. "OpenGL: NVIDIA H100 ..." or "CPU reference (2 threads)".
  virtual std::string name() const = 0;
  /// Largest single pool buffer the device takes (FrameRenderer shrinks the pool to fit).
  virtual std::uint64_t maxBufferBytes() const { return ~std::uint64_t(0); }
  /// Whether the pool keeps the fast CPU device's tables (PoolLayout::marchTables), which the
  /// budget then pays for.
  virtual bool keepsMarchTables() const { return false; }
  /// Allocates the pool (every slot empty), replacing any earlier one (FrameRenderer grows it):
  /// the earlier buffers go before the new ones are made, and the layout is recorded last, so
  /// one that throws leaves a pool of no slots, whose uploads are refused. Throws when the device
  /// cannot hold it.
  virtual void allocatePool(const PoolLayout& layout) = 0;
  /// The current frame's presence octree, and its page table: one slot (or kNotResident) per
  /// brick of the frame's brick table.
  virtual void setOctree(std::span<const OctreeNode> nodes) = 0;
  virtual void setPageTable(std::span<const std::uint32_t> pageTable) = 0;
  /// Writes a converted brick into `slot`; its attributes go to ring entries from `attributeOffset`.
  /// With a foam pool (PoolLayout::foam) its foam bit-brick becomes brick.foamKinds, or zeros.
  virtual void uploadBrick(std::uint32_t slot, std::uint64_t attributeOffset, const ConvertedBrick& brick) = 0;
  /// One brick of uploadBricks().
  struct BrickUpload {
    std::uint32_t slot;
    std::uint64_t attributeOffset;
    const ConvertedBrick* brick;
  };
  /// uploadBrick() of each, into distinct slots and ring ranges (one batch's placements,
  /// BrickPool::place), in any order: the CPU devices upload them on every core.
  virtual void uploadBricks(std::span<const BrickUpload> uploads) {
    for (const BrickUpload& u : uploads) uploadBrick(u.slot, u.attributeOffset, *u.brick);
  }
  /// Foam classification (§3.5, raycast/glsl/FoamClassify.glsl) of the bricks uploaded into
  /// `slots`: their foam bit-bricks become the uploaded ones plus (params.classify = 1u) the
  /// classified cells, then their foam occupancy is built. Needs a foam pool; params.batchSubBricks must
  /// be slots.size() * the sub-bricks per slot. Every upload into a foam pool needs it before
  /// the next trace.
  virtual void classifyFoam(std::span<const std::uint32_t> slots, const FoamClassifyParams& params) = 0;
  /// Milliseconds the last classifyFoam() took (as lastTraceMs).
  virtual double lastClassifyMs() const = 0;
  /// The foam bit-brick of `slot` of a foam pool (for tests and checks).
  virtual std::vector<glm::uvec4> readFoam(std::uint32_t slot) = 0;
  /// Starts an image: every ray fresh (a zeroed RayHit: pending at t = 0).
  virtual void beginImage(std::uint32_t width, std::uint32_t height) = 0;
  /// One pass over the pending rays. Returns the brick indices that rays stopped at, ascending
  /// and unique.
  virtual std::vector<std::uint32_t> trace(const RaycastParams& params) = 0;
  /// Milliseconds the last trace() took on the device: GL timer query on a GPU; wall clock on
  /// the CPU reference and on llvmpipe (whose timer queries return ~0).
  virtual double lastTraceMs() const = 0;
  /// The image's rays, row 0 at the top.
  virtual std::vector<RayHit> readHits() = 0;
};

/// The pool's attribute bases of one brick: per sub-brick, the ring entry of its first set cell.
std::vector<std::uint32_t> attributeBases(const BitBrick& bits, std::uint64_t attributeOffset);

}  // namespace flipscope
