// SpillBuckets: a record keeps the bits a key of its grid may set, less its bucket's digit; the
// keys computeKeys makes set no others; and every bucket reads back the keys (and values) added
// to it, in order, whatever the record size, however records straddle the blocks read, for a
// digit at the top of the brick code or below it (a bucket split again), and for empty buckets;
// a bucket's file is removed once read.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <future>
#include <limits>
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

/// Where the digit of `bits` bits at the top of the grid's brick codes starts.
std::uint32_t topDigitShift(const KeyGrid& grid, std::uint32_t bits) {
  return grid.cellKeyShift() + grid.cellBits + grid.codeBits - bits;
}

struct LayoutCase {
  const char* name;
  std::uint32_t bricksPerAxis;
  AttributeKind attribute;
  bool kinds;
  std::size_t keyBytes;  ///< of the record, the top 8 bits of the brick code the digit
};

class SpillRecordLayoutOfGrid : public ::testing::TestWithParam<LayoutCase> {};

TEST_P(SpillRecordLayoutOfGrid, KeepsTheGridsBitsLessTheDigitAndRoundTripsEveryKey) {
  const LayoutCase c = GetParam();
  const KeyGrid grid(headerOf(c.bricksPerAxis, c.attribute, c.kinds));
  const std::uint32_t bits = 8, shift = topDigitShift(grid, bits);
  const SpillRecordLayout layout(grid.batchKeyBits(), shift, bits, grid.valuesBesideKeys());
  EXPECT_EQ(layout.keyBytes(), c.keyBytes);
  EXPECT_EQ(layout.recordBytes(), c.keyBytes + (grid.valuesBesideKeys() ? 4 : 0));
  std::mt19937_64 random(7);
  for (int i = 0; i < 100000; ++i) {
    const std::uint64_t key = random() & grid.batchKeyBits();
    ASSERT_TRUE(layout.holds(key));
    const std::uint64_t digit = (key >> shift) & 0xff;
    const std::uint64_t packed = layout.pack(key);
    ASSERT_EQ(packed >> (8 * layout.keyBytes()), 0u) << std::hex << key;
    // What lies above the record's bytes (the next record's, when read 8 bytes at a time) is ignored.
    const std::uint64_t above = layout.keyBytes() == 8 ? 0 : random() << (8 * layout.keyBytes());
    ASSERT_EQ(layout.unpack(packed | above, digit), key) << std::hex << key;
  }
  ASSERT_NE(~grid.batchKeyBits(), 0u);
  EXPECT_FALSE(layout.holds(~grid.batchKeyBits()));
}

// Cell keys: 18 bits of the cell in its 64^3 brick and 3 a level of the brick octree.
INSTANTIATE_TEST_SUITE_P(
    KeyLayouts, SpillRecordLayoutOfGrid,
    ::testing::Values(LayoutCase{"Plain", 8, AttributeKind::None, false, 3},                // 18 + 9 - 8 = 19 bits
                      LayoutCase{"PlainWithKinds", 8, AttributeKind::None, true, 3},        // + 2 kind bits = 21
                      LayoutCase{"ValueInKey", 8, AttributeKind::Speed, false, 7},          // + a 32-bit value = 51
                      LayoutCase{"ValueInKeyWithKinds", 8, AttributeKind::Speed, true, 7},  // 53
                      LayoutCase{"ValueBesideKey", 256, AttributeKind::Speed, false, 5},    // 18 + 24 - 8 = 34
                      LayoutCase{"ValueBesideKeyWithKinds", 256, AttributeKind::Speed, true, 5}),  // 36
    [](const auto& info) { return std::string(info.param.name); });

TEST(SpillRecordLayout, HoldsEveryKeyComputeKeysMakes) {
  // The grid's corners, every kind, speeds from 0 to the largest float and NaN: each key sets
  // only bits of batchKeyBits(), or a record would lose some.
  for (const StoreHeader& header :
       {headerOf(8, AttributeKind::None, false), headerOf(8, AttributeKind::None, true),
        headerOf(8, AttributeKind::Speed, false), headerOf(8, AttributeKind::Speed, true),
        headerOf(256, AttributeKind::Speed, false), headerOf(256, AttributeKind::Speed, true)}) {
    const KeyGrid grid(header);
    const float last = float(glm::vec3(grid.cells).x) - 0.5f;  // the centre of the grid's last cell
    ParticleChunk chunk;
    AttributeColumn types{"U", 1, {}};
    const float speeds[] = {0.0f, 1.0f, std::numeric_limits<float>::max(), std::numeric_limits<float>::quiet_NaN()};
    const float flags[] = {0.0f, 2.0f, 4.0f, 8.0f};  // liquid, spray, bubble, foam
    for (const glm::vec3 p : {glm::vec3(0.5f), glm::vec3(last), glm::vec3(last, 0.5f, last)})
      for (float speed : speeds)
        for (float flag : flags) {
          chunk.positions.push_back(p);
          chunk.velocities.push_back(glm::vec3(speed, 0.0f, 0.0f));
          types.values.push_back(flag);
        }
    detail::KeyBatch batch;
    const detail::KeyTally tally = detail::computeKeys(chunk, grid, batch, header.particleKinds ? &types : nullptr);
    ASSERT_EQ(tally.kept, chunk.size());
    std::uint64_t set = 0;
    for (std::uint64_t key : batch.cellKeys) set |= key;
    EXPECT_EQ(set & ~grid.batchKeyBits(), 0u) << std::hex << set << " against " << grid.batchKeyBits();
    // And the kind bits are set where the store keeps kinds (a bubble is 3).
    if (header.particleKinds) {
      EXPECT_NE(set & (grid.valueInKey ? 3ull << 62 : 3ull << 48), 0u);
    }
  }
}

/// Adds `keys` (and `values`) to buckets of the digit [shift, shift + bits) in chunks of uneven
/// sizes, then checks every bucket reads back, by forEachPiece, by load and by readRecords and
/// unpack, the keys of its digit in the order added.
void checkRoundTrip(const KeyGrid& grid, std::uint32_t shift, std::uint32_t bits,
                    const std::vector<std::uint64_t>& keys, const std::vector<float>& values, std::size_t bufferBytes) {
  testing::TempDir dir("spill-buckets");
  const bool withValues = grid.valuesBesideKeys();
  SpillBuckets buckets(dir.path(), "spill", grid.batchKeyBits(), shift, bits, withValues, bufferBytes);
  for (std::size_t at = 0, chunk = 1; at < keys.size(); at += chunk, chunk = chunk * 3 % 9973 + 1) {
    const std::size_t n = std::min(chunk, keys.size() - at);
    buckets.add(keys.data() + at, withValues ? values.data() + at : nullptr, n);
  }
  buckets.finish();
  ASSERT_EQ(buckets.size(), std::size_t(1) << bits);
  std::uint64_t written = 0;  // each bucket's records, its last block padded
  for (std::size_t b = 0; b < buckets.size(); ++b)
    written += (buckets.records(b) * buckets.layout().recordBytes() + kDirectBlock - 1) / kDirectBlock * kDirectBlock;
  EXPECT_EQ(buckets.bytesWritten(), written);
  std::uint64_t total = 0;
  AlignedBuffer raw;
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
      ASSERT_GT(n, 0u);
      streamed.insert(streamed.end(), k, k + n);
      if (s) streamedValues.insert(streamedValues.end(), s, s + n);
    });
    ASSERT_EQ(streamed, expectedKeys) << "bucket " << b;
    ASSERT_EQ(streamedValues, expectedValues) << "bucket " << b;
    detail::KeyBatch batch;
    buckets.load(b, batch);
    ASSERT_EQ(std::vector<std::uint64_t>(batch.cellKeys.begin(), batch.cellKeys.end()), expectedKeys) << "bucket " << b;
    ASSERT_EQ(std::vector<float>(batch.values.begin(), batch.values.end()), expectedValues) << "bucket " << b;
    // In one read, then unpacked, into a buffer kept from bucket to bucket (grown, or larger).
    buckets.readRecords(b, raw);
    detail::KeyBatch unpacked;
    buckets.unpack(b, raw, unpacked);
    ASSERT_EQ(std::vector<std::uint64_t>(unpacked.cellKeys.begin(), unpacked.cellKeys.end()), expectedKeys)
        << "bucket " << b;
    ASSERT_EQ(std::vector<float>(unpacked.values.begin(), unpacked.values.end()), expectedValues) << "bucket " << b;
    // Read, the bucket's file goes; an empty bucket never had one.
    const std::filesystem::path file = dir.path() / ("spill-" + std::to_string(b));
    EXPECT_EQ(std::filesystem::exists(file), buckets.records(b) > 0) << "bucket " << b;
    buckets.remove(b);
    EXPECT_FALSE(std::filesystem::exists(file)) << "bucket " << b;
    EXPECT_EQ(buckets.records(b), expectedKeys.size()) << "bucket " << b;
  }
  EXPECT_EQ(total, keys.size());
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));  // before the buckets' destruction
}

/// Buffers of 11 blocks: buckets are read 44 blocks at a time, which records of 3, 7 and 10
/// bytes straddle (8-byte ones cannot).
constexpr std::size_t kBufferBytes = 11 * kDirectBlock;

TEST(SpillBuckets, EveryBucketReadsBackItsKeysInOrderForEveryRecordSize) {
  std::mt19937_64 random(11);
  struct Case {
    StoreHeader header;
    std::size_t recordBytes;  ///< with a digit of 3 bits at the top of the brick code
  };
  for (const Case& c : {Case{headerOf(8, AttributeKind::None, false), 3},           // 27 - 3 = 24 bits
                        Case{headerOf(8, AttributeKind::Speed, false), 7},          // 59 - 3 = 56 bits
                        Case{headerOf(8, AttributeKind::Speed, true), 8},           // 61 - 3 = 58 bits
                        Case{headerOf(256, AttributeKind::Speed, true), 6 + 4}}) {  // 44 - 3 = 41 bits, a value
    const KeyGrid grid(c.header);
    const std::uint32_t bits = 3, shift = topDigitShift(grid, bits);
    SCOPED_TRACE(::testing::Message() << "key bits " << std::hex << grid.batchKeyBits());
    ASSERT_EQ(SpillRecordLayout(grid.batchKeyBits(), shift, bits, grid.valuesBesideKeys()).recordBytes(),
              c.recordBytes);
    if (c.recordBytes != 8) {
      ASSERT_NE(4 * kBufferBytes % c.recordBytes, 0u);  // records straddle blocks
    }
    // Enough keys that each bucket spans several blocks.
    std::vector<std::uint64_t> keys(600000);
    std::vector<float> values(keys.size());
    for (std::size_t i = 0; i < keys.size(); ++i) {
      keys[i] = random() & grid.batchKeyBits();
      values[i] = float(i) * 0.25f - 7.0f;
    }
    checkRoundTrip(grid, shift, bits, keys, values, kBufferBytes);
  }
}

TEST(SpillBuckets, ABucketSplitAgainAndEmptyBucketsReadBack) {
  // FrameBinner's skewed path: the keys of one top bucket (the same 8-bit digit) go to buckets of
  // the 3 bits below it, one of which (5) gets none.
  std::mt19937_64 random(13);
  const KeyGrid grid(headerOf(256, AttributeKind::Speed, true));
  const std::uint32_t top = topDigitShift(grid, 8), shift = top - 3;
  std::vector<std::uint64_t> keys;
  std::vector<float> values;
  while (keys.size() < 200000) {
    std::uint64_t key = (random() & grid.batchKeyBits() & ~(0xffull << top)) | (0xa5ull << top);
    if (((key >> shift) & 7) == 5) continue;
    keys.push_back(key);
    values.push_back(float(keys.size()));
  }
  checkRoundTrip(grid, shift, 3, keys, values, kBufferBytes);
}

TEST(SpillBuckets, RecordsEndingOnABlockBoundaryUnpack) {
  // 2-byte records (2^3 bricks of 32^3 cells: 18 key bits, less a 3-bit digit), 4096 of them in
  // bucket 0: its file is exactly two blocks, so unpack's 8-byte reads of the last records reach
  // into readRecords' spare block (an AddressSanitizer build reports a buffer without it).
  testing::TempDir dir("spill-buckets-boundary");
  StoreHeader header = headerOf(2, AttributeKind::None, false);
  header.brickSize = 32;
  const KeyGrid grid(header);
  const std::uint32_t bits = 3, shift = topDigitShift(grid, bits);
  SpillBuckets buckets(dir.path(), "spill", grid.batchKeyBits(), shift, bits, false, kBufferBytes);
  ASSERT_EQ(buckets.layout().recordBytes(), 2u);
  std::mt19937_64 random(19);
  std::vector<std::uint64_t> keys;
  for (int i = 0; i < 4096; ++i) keys.push_back(random() & grid.batchKeyBits() & ~(std::uint64_t(7) << shift));
  for (int i = 0; i < 5; ++i)
    keys.push_back((random() & grid.batchKeyBits() & ~(std::uint64_t(7) << shift)) | (std::uint64_t(1) << shift));
  buckets.add(keys.data(), nullptr, keys.size());
  buckets.finish();
  ASSERT_EQ(buckets.records(0), 4096u);
  EXPECT_EQ(buckets.recordBufferBytes(4096), 3 * kDirectBlock);
  AlignedBuffer raw(buckets.recordBufferBytes(4096));  // exactly what readRecords asks for
  for (std::size_t b = 0; b < 2; ++b) {
    buckets.readRecords(b, raw);
    detail::KeyBatch batch;
    buckets.unpack(b, raw, batch);
    const std::vector<std::uint64_t> expected(keys.begin() + (b ? 4096 : 0), b ? keys.end() : keys.begin() + 4096);
    EXPECT_EQ(std::vector<std::uint64_t>(batch.cellKeys.begin(), batch.cellKeys.end()), expected) << "bucket " << b;
  }
}

/// The threads of FrameBinner's out-of-core binning (run under ThreadSanitizer in CI:
/// tests/streaming/run-tsan.sh): bucket b + 1's records read on one thread while bucket b's file
/// is removed on another and this thread decodes bucket b's records (without TBB, which that
/// build does not instrument).
TEST(SpillBucketsThreads, ReadAheadBesideRemoval) {
  testing::TempDir dir("spill-buckets-threads");
  const KeyGrid grid(headerOf(8, AttributeKind::None, false));
  const std::uint32_t bits = 3, shift = topDigitShift(grid, bits);
  SpillBuckets buckets(dir.path(), "spill", grid.batchKeyBits(), shift, bits, false, kBufferBytes);
  std::mt19937_64 random(17);
  std::vector<std::uint64_t> keys(40000);
  for (auto& key : keys) key = random() & grid.batchKeyBits();
  buckets.add(keys.data(), nullptr, keys.size());
  buckets.finish();
  const SpillRecordLayout& layout = buckets.layout();
  std::array<AlignedBuffer, 2> raw;
  buckets.readRecords(0, raw[0]);
  std::future<void> removing;
  for (std::size_t b = 0; b < buckets.size(); ++b) {
    std::future<void> reading;
    if (b + 1 < buckets.size())
      reading = std::async(std::launch::async, [&, b] { buckets.readRecords(b + 1, raw[(b + 1) % 2]); });
    if (removing.valid()) removing.get();
    removing = std::async(std::launch::async, [&, b] { buckets.remove(b); });
    std::vector<std::uint64_t> expected, decoded;
    for (std::uint64_t key : keys)
      if (((key >> shift) & 7) == b) expected.push_back(key);
    for (std::uint64_t i = 0; i < buckets.records(b); ++i)
      decoded.push_back(layout.keyAt(raw[b % 2].data() + i * layout.recordBytes(), b));
    EXPECT_EQ(decoded, expected) << "bucket " << b;
    if (reading.valid()) reading.get();
  }
  removing.get();
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(SpillBuckets, AKeyWithBitsTheGridCannotSetIsRefused) {
  testing::TempDir dir("spill-buckets-refused");
  const KeyGrid grid(headerOf(8, AttributeKind::None, false));
  SpillBuckets buckets(dir.path(), "spill", grid.batchKeyBits(), topDigitShift(grid, 2), 2, false, kBufferBytes);
  const std::uint64_t key = grid.batchKeyBits() + 1;  // the lowest bit above the cell key
  EXPECT_THROW(buckets.add(&key, nullptr, 1), LogicError);
}

}  // namespace
}  // namespace flipscope
