// SpillBuckets: a record keeps only the key bits that vary within its bucket, and every bucket
// reads back the keys (and values) added to it, in order, whatever the record size and however
// records straddle the blocks read.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "TestSupport.h"
#include "core/Error.h"
#include "preprocess/SpillBuckets.h"

namespace flipscope {
namespace {

using detail::KeyGrid;
using detail::SpillBuckets;
using detail::SpillRecordLayout;

/// A store header whose grid has `bricksPerAxis` bricks of 64^3 along each axis.
StoreHeader headerOf(std::uint32_t bricksPerAxis, AttributeKind attribute, bool kinds) {
  StoreHeader h;
  h.cellSize = 1.0;
  h.brickSize = 64;
  h.brickGrid = glm::uvec3(bricksPerAxis);
  h.attribute = attribute;
  h.particleKinds = kinds;
  return h;
}

/// A random key a grid may make: random bits within its batch key bits.
std::uint64_t randomKey(std::mt19937_64& random, std::uint64_t keyBits) { return random() & keyBits; }

struct LayoutCase {
  const char* name;
  std::uint32_t bricksPerAxis;
  AttributeKind attribute;
  bool kinds;
  std::size_t keyBytes;  ///< of the record, the top 8 bits of the brick code the digit
};

class SpillRecordLayoutOfGrid : public ::testing::TestWithParam<LayoutCase> {};

TEST_P(SpillRecordLayoutOfGrid, KeepsTheBitsThatVaryWithinABucketAndRoundTripsEveryKey) {
  const LayoutCase c = GetParam();
  const KeyGrid grid(headerOf(c.bricksPerAxis, c.attribute, c.kinds));
  const std::uint32_t bits = 8;
  const std::uint32_t shift = grid.cellKeyShift() + grid.cellBits + grid.codeBits - bits;
  const SpillRecordLayout layout(grid.batchKeyBits(), shift, bits, grid.valuesBesideKeys());
  EXPECT_EQ(layout.keyBytes(), c.keyBytes);
  EXPECT_EQ(layout.recordBytes(), c.keyBytes + (grid.valuesBesideKeys() ? 4 : 0));
  std::mt19937_64 random(7);
  for (int i = 0; i < 100000; ++i) {
    const std::uint64_t key = randomKey(random, grid.batchKeyBits());
    ASSERT_TRUE(layout.holds(key));
    const std::uint64_t digit = (key >> shift) & 0xff;
    const std::uint64_t packed = layout.pack(key);
    ASSERT_EQ(packed >> (8 * layout.keyBytes()), 0u) << std::hex << key;
    // What lies above the record's bytes (the next record's, when read 8 bytes at a time) is ignored.
    const std::uint64_t above = layout.keyBytes() == 8 ? 0 : random() << (8 * layout.keyBytes());
    ASSERT_EQ(layout.unpack(packed | above, digit), key) << std::hex << key;
  }
  if (~grid.batchKeyBits() != 0) {
    EXPECT_FALSE(layout.holds(~grid.batchKeyBits()));
  }
}

// Cell keys: 18 bits of the cell in its 64^3 brick and 3 a level of the brick octree.
INSTANTIATE_TEST_SUITE_P(
    KeyLayouts, SpillRecordLayoutOfGrid,
    ::testing::Values(LayoutCase{"Plain", 8, AttributeKind::None, false, 3},                // 18 + 9 - 8 = 19 bits
                      LayoutCase{"PlainWithKinds", 8, AttributeKind::None, true, 3},        // + 2 kind bits = 21
                      LayoutCase{"ValueInKey", 8, AttributeKind::Speed, false, 7},          // + a 32-bit value = 51
                      LayoutCase{"ValueInKeyWithKinds", 8, AttributeKind::Speed, true, 7},  // 53
                      LayoutCase{"ValueBesideKey", 256, AttributeKind::Speed, false,
                                 5},  // 18 + 24 - 8 = 34 bits, + 4 bytes
                      LayoutCase{"ValueBesideKeyWithKinds", 256, AttributeKind::Speed, true, 5}),  // 36 bits
    [](const auto& info) { return std::string(info.param.name); });

/// Adds `keys` (and `values`) to buckets in chunks of uneven sizes, then checks every bucket
/// reads back, by forEachPiece and by load, the keys of its digit in the order added.
void checkRoundTrip(const KeyGrid& grid, std::uint32_t bits, const std::vector<std::uint64_t>& keys,
                    const std::vector<float>& values, std::size_t bufferBytes) {
  testing::TempDir dir("spill-buckets");
  const bool withValues = grid.valuesBesideKeys();
  const std::uint32_t shift = grid.cellKeyShift() + grid.cellBits + grid.codeBits - bits;
  SpillBuckets buckets(dir.path(), "spill", grid.batchKeyBits(), shift, bits, withValues, bufferBytes);
  for (std::size_t at = 0, chunk = 1; at < keys.size(); at += chunk, chunk = chunk * 3 % 9973 + 1) {
    const std::size_t n = std::min(chunk, keys.size() - at);
    buckets.add(keys.data() + at, withValues ? values.data() + at : nullptr, n);
  }
  buckets.finish();
  ASSERT_EQ(buckets.size(), std::size_t(1) << bits);
  std::uint64_t total = 0;
  for (std::size_t b = 0; b < buckets.size(); ++b) {
    std::vector<std::uint64_t> expectedKeys;
    std::vector<float> expectedValues;
    for (std::size_t i = 0; i < keys.size(); ++i)
      if (((keys[i] >> shift) & ((1u << bits) - 1)) == b) {
        expectedKeys.push_back(keys[i]);
        if (withValues) expectedValues.push_back(values[i]);
      }
    ASSERT_EQ(buckets.records(b), expectedKeys.size()) << "bucket " << b;
    total += buckets.records(b);
    std::vector<std::uint64_t> streamed;
    std::vector<float> streamedValues;
    buckets.forEachPiece(b, [&](const std::uint64_t* k, const float* s, std::size_t n) {
      ASSERT_EQ(s != nullptr, withValues);
      streamed.insert(streamed.end(), k, k + n);
      if (s) streamedValues.insert(streamedValues.end(), s, s + n);
    });
    ASSERT_EQ(streamed, expectedKeys) << "bucket " << b;
    ASSERT_EQ(streamedValues, expectedValues) << "bucket " << b;
    detail::KeyBatch batch;
    buckets.load(b, batch);
    ASSERT_TRUE(std::equal(batch.cellKeys.begin(), batch.cellKeys.end(), expectedKeys.begin(), expectedKeys.end()))
        << "bucket " << b;
    ASSERT_TRUE(std::equal(batch.values.begin(), batch.values.end(), expectedValues.begin(), expectedValues.end()))
        << "bucket " << b;
  }
  EXPECT_EQ(total, keys.size());
}

TEST(SpillBuckets, EveryBucketReadsBackItsKeysInOrderForEveryRecordSize) {
  // Records of 3, 7, 7 and 5 + 4 bytes: most straddle the blocks they are read in; buffers of
  // three blocks, so that a bucket's records go out in many writes.
  std::mt19937_64 random(11);
  for (const StoreHeader& header :
       {headerOf(8, AttributeKind::None, false), headerOf(8, AttributeKind::Speed, false),
        headerOf(8, AttributeKind::Speed, true), headerOf(256, AttributeKind::Speed, true)}) {
    const KeyGrid grid(header);
    std::vector<std::uint64_t> keys(150000);
    std::vector<float> values(keys.size());
    for (std::size_t i = 0; i < keys.size(); ++i) {
      keys[i] = randomKey(random, grid.batchKeyBits());
      values[i] = float(i) * 0.25f - 7.0f;
    }
    SCOPED_TRACE(::testing::Message() << "key bits " << std::hex << grid.batchKeyBits());
    checkRoundTrip(grid, 3, keys, values, 3 * kDirectBlock);
  }
}

TEST(SpillBuckets, AKeyWithBitsTheGridCannotSetIsRefused) {
  testing::TempDir dir("spill-buckets-refused");
  const KeyGrid grid(headerOf(8, AttributeKind::None, false));
  const std::uint32_t shift = grid.cellBits + grid.codeBits - 2;
  SpillBuckets buckets(dir.path(), "spill", grid.batchKeyBits(), shift, 2, false, 3 * kDirectBlock);
  const std::uint64_t key = grid.batchKeyBits() + 1;  // the lowest bit above the cell key
  EXPECT_THROW(buckets.add(&key, nullptr, 1), LogicError);
}

}  // namespace
}  // namespace flipscope
