// BrickPool: FIFO eviction of slots and attribute ring ranges, and the batch guard.
#include <gtest/gtest.h>

#include "core/Error.h"
#include "raycast/BrickPool.h"

namespace flipscope {
namespace {

PoolLayout smallLayout(std::uint32_t slots, std::uint64_t ring) {
  PoolLayout layout = PoolLayout::forBudget(32, 1, ring > 0, 1ull << 30);
  layout.slots = slots;
  layout.attributeCapacity = ring;
  return layout;
}

BrickKey key(std::uint32_t i) { return {0, glm::uvec3(i, 0, 0)}; }

TEST(BrickPool, LayoutFitsTheBudgetAndRefusesATinyOne) {
  const PoolLayout layout = PoolLayout::forBudget(64, 2, true, 256ull << 20);
  EXPECT_LE(layout.bytes(), 256ull << 20);
  EXPECT_GE(layout.slots, 3u);
  EXPECT_EQ(layout.subBricksPerSlot, 17u * 17u * 9u);
  EXPECT_THROW(PoolLayout::forBudget(64, 2, true, 100000), InputError);
}

TEST(BrickPool, LayoutCutToTheSlotsWantedGivesItsRingAllTheirCells) {
  const PoolLayout budget = PoolLayout::forBudget(64, 2, true, 256ull << 20);
  const PoolLayout cut = budget.withSlots(10);
  EXPECT_EQ(cut.slots, 10u);
  EXPECT_EQ(cut.subBricksPerSlot, budget.subBricksPerSlot);
  EXPECT_EQ(cut.attributeCapacity, 10 * cut.storedCellsPerSlot());  // every cell of every slot
  EXPECT_LT(cut.bytes(), budget.bytes() / 10);
  EXPECT_EQ(budget.withSlots(0).slots, 3u);  // never below the minimum
  EXPECT_EQ(budget.withSlots(budget.slots).bytes(), budget.bytes());
  EXPECT_EQ(budget.withSlots(budget.slots + 5).slots, budget.slots);
  EXPECT_EQ(PoolLayout::forBudget(64, 2, false, 256ull << 20).withSlots(10).attributeCapacity, 0u);
}

TEST(BrickPool, LayoutCutNearTheBudgetKeepsTheBudgetsRing) {
  // The budget's ring holds 35% of the cells of its slots. Cut to fewer slots than hold all
  // their cells in that ring, the ring stays the budget's, not what the dropped slots freed:
  // the device's buffer limit was checked against the budget's ring.
  const PoolLayout budget = PoolLayout::forBudget(64, 2, true, 64ull << 20);
  for (std::uint64_t slots : {budget.slots - 1, budget.slots / 2, budget.slots * 2 / 5}) {
    const PoolLayout cut = budget.withSlots(slots);
    EXPECT_LT(cut.attributeCapacity, std::uint64_t(cut.slots) * cut.storedCellsPerSlot()) << slots;
    EXPECT_EQ(cut.attributeCapacity, budget.attributeCapacity) << slots;
    EXPECT_LT(cut.bytes(), budget.bytes()) << slots;
  }
  const PoolLayout few = budget.withSlots(budget.slots / 4);  // all their cells fit the budget's ring
  EXPECT_EQ(few.attributeCapacity, few.slots * few.storedCellsPerSlot());
  EXPECT_LT(few.attributeCapacity, budget.attributeCapacity);
}

TEST(BrickPool, EvictsOldestFirstAndReusesItsSlot) {
  BrickPool pool(smallLayout(3, 0));
  std::vector<BrickKey> evicted;
  for (std::uint32_t i = 0; i < 3; ++i) ASSERT_EQ(pool.place(key(i), 0, i, evicted)->slot, i);
  EXPECT_TRUE(evicted.empty());
  const auto placement = pool.place(key(3), 0, 3, evicted);
  ASSERT_TRUE(placement);
  EXPECT_EQ(placement->slot, 0u);
  ASSERT_EQ(evicted.size(), 1u);
  EXPECT_EQ(evicted[0], key(0));
  EXPECT_FALSE(pool.find(key(0)));
  EXPECT_EQ(*pool.find(key(3)), 0u);
  EXPECT_EQ(pool.resident(), 3u);
}

TEST(BrickPool, NeverEvictsABrickOfTheSameBatch) {
  BrickPool pool(smallLayout(2, 0));
  std::vector<BrickKey> evicted;
  ASSERT_TRUE(pool.place(key(0), 0, 7, evicted));
  ASSERT_TRUE(pool.place(key(1), 0, 7, evicted));
  EXPECT_FALSE(pool.place(key(2), 0, 7, evicted));
  EXPECT_TRUE(evicted.empty());
  EXPECT_TRUE(pool.place(key(2), 0, 8, evicted));
}

TEST(BrickPool, AttributeRangesNeverOverlapAndWrap) {
  BrickPool pool(smallLayout(8, 100));
  std::vector<BrickKey> evicted;
  struct Live {
    BrickKey key;
    std::uint64_t begin, count;
  };
  std::vector<Live> live;
  for (std::uint32_t i = 0; i < 40; ++i) {
    const std::uint64_t count = 7 + (i * 13) % 40;
    evicted.clear();
    const auto placement = pool.place(key(i), count, i, evicted);
    ASSERT_TRUE(placement);
    std::erase_if(live,
                  [&](const Live& l) { return std::find(evicted.begin(), evicted.end(), l.key) != evicted.end(); });
    EXPECT_EQ(placement->attributeOffset % 2, 0u);
    EXPECT_LE(placement->attributeOffset + count, 100u);
    for (const Live& l : live)
      EXPECT_TRUE(placement->attributeOffset + count <= l.begin || l.begin + l.count <= placement->attributeOffset);
    live.push_back({key(i), placement->attributeOffset, count});
  }
  EXPECT_THROW(pool.place(key(99), 101, 99, evicted), InputError);
}

}  // namespace
}  // namespace flipscope
