// BrickPool: which converted brick sits in which GPU pool slot (Reichl et al. 2014 §4.1: "a
// brick pool on the GPU", with a page table from bricks to slots). Bookkeeping only, the same
// for the GPU and the CPU reference device; the bytes live in the RaycastDevice.
//
// A slot holds a brick's bits, mipmap and sub-brick attribute bases (fixed sizes); its 16-bit
// attributes take a variable range of a ring of attribute entries. Eviction is FIFO in upload
// order, which frees slots and attribute ranges in the order the ring hands them out. A
// placement never evicts a brick placed in the same `batch` (the bricks one pass asked for).
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <unordered_map>
#include <vector>

#include "streaming/BrickSource.h"

namespace flipscope {

/// Sizes of one pool, from the bit-brick layout and the memory budget.
struct PoolLayout {
  std::uint32_t brickSize = 64;
  std::uint32_t overlap = 1;
  std::uint32_t subBricksPerSlot = 0;
  std::uint32_t mipWordsPerSlot = 0;
  std::uint32_t mipLevels = 0;
  bool attributes = false;
  bool foam = false;  ///< a foam bit-brick per slot (§3.5), the size of its bits, and its occupancy
  /// 32-bit words of a slot's foam occupancy (one bit per sub-brick; FoamClassify.glsl).
  std::uint32_t foamOccupancyWords() const { return (subBricksPerSlot + 31) / 32; }
  /// The fast CPU device's tables (TiledCpuRaycaster; RaycastDevice::keepsMarchTables): per
  /// sub-brick, 4 bytes: the sphere and the foam cells of each of its halves, and a byte: its
  /// ClearDistance; per brick cell, a bit: whether a sphere cell lies within `reach` cells
  /// (NearSphereMask); per 4^3 cells, a byte: the ClearDistance of the mask's groups; and the
  /// bounds of both tables' set blocks.
  bool marchTables = false;
  std::uint32_t reach = 0;  ///< of the spheres, in cells (sphereReach), with marchTables
  std::uint32_t slots = 0;
  std::uint64_t attributeCapacity = 0;  ///< 16-bit entries in the ring (even)

  /// Fixed bytes per slot: bits, mipmap, (with attributes) one 32-bit base per sub-brick, (with
  /// foam) the foam bits and their occupancy, and (with marchTables) the fast CPU device's tables.
  std::uint64_t slotBytes() const;
  std::uint64_t bytes() const { return slotBytes() * slots + attributeCapacity * 2; }
  /// Cells a slot stores, the border included: the most attributes one brick can have.
  std::uint64_t storedCellsPerSlot() const { return std::uint64_t(subBricksPerSlot) * 128; }
  /// The largest pool within `budgetBytes`; with attributes, the ring gets room for about 35%
  /// filled bricks. Throws InputError when fewer than 3 slots fit (naming the minimum budget).
  /// With `marchTables`, the tables are for spheres of `reach` (sphereReach) cells.
  static PoolLayout forBudget(std::uint32_t brickSize, std::uint32_t overlap, bool attributes,
                              std::uint64_t budgetBytes, bool foam = false, bool marchTables = false,
                              std::uint32_t reach = 0);
  /// This (budget's) pool cut to `wanted` slots (at least 3) when it has more: bricks no frame
  /// asked for cost no memory. The ring then holds every stored cell of every slot, up to this
  /// pool's ring (which the device's buffer limit was checked against), so it is never larger
  /// than this one's, and any one brick still fits. `*this` when `wanted` is not below its slots.
  PoolLayout withSlots(std::uint64_t wanted) const;
};

class BrickPool {
 public:
  struct Placement {
    std::uint32_t slot;
    std::uint64_t attributeOffset;  ///< first ring entry (even)
  };

  explicit BrickPool(const PoolLayout& layout);

  const PoolLayout& layout() const { return mLayout; }
  /// Slot of a resident brick.
  std::optional<std::uint32_t> find(const BrickKey& key) const;
  /// Makes room for a brick with `attributeCount` attributes, evicting the oldest bricks of
  /// earlier batches, and records it as resident. nullopt when that would evict a brick of this
  /// batch (the caller uploads it in a later pass). Evicted keys are appended to `evicted`.
  std::optional<Placement> place(const BrickKey& key, std::uint64_t attributeCount, std::uint64_t batch,
                                 std::vector<BrickKey>& evicted);
  std::size_t resident() const { return mResidents.size(); }
  /// Resident bricks of `frame` by coordinate, for rebuilding its page table.
  template <class F>
  void forEachResident(int frame, F&& f) const {
    for (const auto& r : mResidents)
      if (r.key.frame == frame) f(r.key.coord, r.slot);
  }

 private:
  struct Resident {
    BrickKey key;
    std::uint32_t slot;
    std::uint64_t attributeOffset;
    std::uint64_t attributeCount;
    std::uint64_t batch;
  };
  bool rangeFree(std::uint64_t begin, std::uint64_t count) const;
  void evictOldest(std::vector<BrickKey>& evicted);

  PoolLayout mLayout;
  std::deque<Resident> mResidents;  ///< upload order, oldest first
  std::unordered_map<BrickKey, std::uint32_t, BrickKeyHash> mSlotOf;
  std::vector<std::uint32_t> mFreeSlots;  ///< popped from the back
  std::uint64_t mRingHead = 0;            ///< next attribute entry to hand out
};

}  // namespace flipscope
