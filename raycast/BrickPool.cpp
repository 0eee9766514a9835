#include "raycast/BrickPool.h"

#include <algorithm>

#include "core/Error.h"
#include "raycast/ClearDistance.h"
#include "raycast/NearSphereMask.h"
#include "streaming/BitBrickLayout.h"

namespace flipscope {

namespace {
constexpr std::uint64_t kMinSlots = 3;  // with attributes, 3 x 35% fill holds any one brick
}  // namespace

std::uint64_t PoolLayout::slotBytes() const {
  return std::uint64_t(subBricksPerSlot) * (16 + (attributes ? 4 : 0) + (foam ? 16 : 0) + (marchTables ? 5 : 0)) +
         std::uint64_t(mipWordsPerSlot + (foam ? foamOccupancyWords() : 0)) * 4 +
         (marchTables ? nearSphereMaskWords(brickSize) * 8 + nearSphereGroupCount(brickSize) + 2 * sizeof(SetBlockBounds) : 0);
}

PoolLayout PoolLayout::forBudget(std::uint32_t brickSize, std::uint32_t overlap, bool attributes,
                                 std::uint64_t budgetBytes, bool foam, bool marchTables, std::uint32_t reach) {
  PoolLayout layout;
  layout.foam = foam;
  layout.marchTables = marchTables;
  layout.reach = reach;
  layout.brickSize = brickSize;
  layout.overlap = overlap;
  const glm::uvec3 dims = bitBrickSubBrickDims(brickSize, overlap);
  layout.subBricksPerSlot = dims.x * dims.y * dims.z;
  layout.mipLevels = bitBrickMipLevelCount(brickSize, overlap);
  layout.mipWordsPerSlot = bitBrickMipWordOffset(layout.mipLevels + 1, brickSize, overlap);
  layout.attributes = attributes;
  const std::uint64_t ringPerSlot = attributes ? (layout.storedCellsPerSlot() * 35 / 100) * 2 : 0;
  const std::uint64_t perSlot = layout.slotBytes() + ringPerSlot;
  if (budgetBytes < kMinSlots * perSlot)
    throw InputError("GPU memory budget of " + std::to_string(budgetBytes) + " bytes is below the minimum of " +
                     std::to_string(kMinSlots * perSlot) + " bytes (3 bricks of " + std::to_string(brickSize) +
                     "^3 cells)");
  const std::uint64_t slots = std::min<std::uint64_t>(budgetBytes / perSlot, 1u << 30);
  layout.slots = std::uint32_t(slots);
  layout.attributeCapacity = attributes ? ((budgetBytes - slots * layout.slotBytes()) / 2) & ~std::uint64_t(1) : 0;
  return layout;
}

PoolLayout PoolLayout::withSlots(std::uint64_t wanted) const {
  wanted = std::max(wanted, kMinSlots);
  if (wanted >= slots) return *this;
  PoolLayout layout = *this;
  layout.slots = std::uint32_t(wanted);
  if (attributes) {
    const std::uint64_t freed = (bytes() - wanted * slotBytes()) / 2;
    layout.attributeCapacity = std::min({freed, wanted * storedCellsPerSlot(), attributeCapacity}) & ~std::uint64_t(1);
  }
  return layout;
}

BrickPool::BrickPool(const PoolLayout& layout) : mLayout(layout) {
  FLIPSCOPE_CHECK(layout.slots > 0);
  mFreeSlots.resize(layout.slots);
  for (std::uint32_t i = 0; i < layout.slots; ++i) mFreeSlots[i] = layout.slots - 1 - i;  // slot 0 first
}

std::optional<std::uint32_t> BrickPool::find(const BrickKey& key) const {
  const auto it = mSlotOf.find(key);
  if (it == mSlotOf.end()) return std::nullopt;
  return it->second;
}

bool BrickPool::rangeFree(std::uint64_t begin, std::uint64_t count) const {
  if (count == 0) return true;
  const std::uint64_t end = begin + count;
  return std::none_of(mResidents.begin(), mResidents.end(), [&](const Resident& r) {
    return r.attributeCount > 0 && r.attributeOffset < end && begin < r.attributeOffset + r.attributeCount;
  });
}

void BrickPool::evictOldest(std::vector<BrickKey>& evicted) {
  const Resident oldest = mResidents.front();
  mResidents.pop_front();
  mSlotOf.erase(oldest.key);
  mFreeSlots.push_back(oldest.slot);
  evicted.push_back(oldest.key);
}

std::optional<BrickPool::Placement> BrickPool::place(const BrickKey& key, std::uint64_t attributeCount,
                                                     std::uint64_t batch, std::vector<BrickKey>& evicted) {
  FLIPSCOPE_CHECK(!mSlotOf.contains(key), "brick placed twice");
  const std::uint64_t count = (attributeCount + 1) & ~std::uint64_t(1);
  if (count > mLayout.attributeCapacity && count > 0)
    throw InputError("a brick with " + std::to_string(attributeCount) +
                     " attribute cells does not fit the GPU attribute pool; raise the GPU memory budget");
  const std::uint64_t begin = count == 0 ? 0 : (mRingHead + count <= mLayout.attributeCapacity ? mRingHead : 0);
  while (mFreeSlots.empty() || !rangeFree(begin, count)) {
    if (mResidents.front().batch == batch) return std::nullopt;
    evictOldest(evicted);
  }
  const std::uint32_t slot = mFreeSlots.back();
  mFreeSlots.pop_back();
  if (count > 0) mRingHead = begin + count;
  mResidents.push_back({key, slot, begin, count, batch});
  mSlotOf.emplace(key, slot);
  return Placement{slot, begin};
}

}  // namespace flipscope
