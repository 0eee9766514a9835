// SpillBuckets (see the header).
#include "preprocess/SpillBuckets.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <ios>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/Error.h"
#include "preprocess/ConvertStopPoint.h"

namespace flipscope::detail {

static_assert(std::endian::native == std::endian::little, "a record keeps the low bytes of its packed key");

SpillRecordLayout::SpillRecordLayout(std::uint64_t keyBits, std::uint32_t digitShift, std::uint32_t digitBits,
                                     bool values)
    : mKeyBits(keyBits), mDigitShift(digitShift), mValues(values) {
  FLIPSCOPE_CHECK(digitBits >= 1 && digitBits < 64 && digitShift + digitBits <= 64,
                  "digit " << digitShift << "+" << digitBits);
  const std::uint64_t digit = (~std::uint64_t(0) >> (64 - digitBits)) << digitShift;
  std::uint64_t kept = keyBits & ~digit;
  std::uint32_t to = 0;
  while (kept) {
    const auto shift = std::uint32_t(std::countr_zero(kept));
    const auto width = std::uint32_t(std::countr_one(kept >> shift));
    FLIPSCOPE_CHECK(mRunCount < mRuns.size(), "key bits " << std::hex << keyBits << " in too many runs");
    const std::uint64_t mask = width == 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << width) - 1;
    mRuns[mRunCount++] = {shift, to, mask};
    to += width;
    kept &= ~(mask << shift);
  }
  mKeyBytes = std::max<std::size_t>(1, (to + 7) / 8);
}

SpillBuckets::SpillBuckets(const std::filesystem::path& dir, const std::string& prefix, std::uint64_t keyBits,
                           std::uint32_t shift, std::uint32_t bits, bool values, std::size_t bufferBytes)
    : mShift(shift),
      mBits(bits),
      mLayout(keyBits, shift, bits, values),
      mBufferBytes(bufferBytes),
      mAppender(std::make_unique<BackgroundAppender>(bufferBytes, kQueuedBlocks)) {
  FLIPSCOPE_CHECK(bufferBytes >= kDirectBlock + kRecordWriteBytes, "spill buffers of " << bufferBytes << " bytes");
  const std::size_t count = std::size_t(1) << bits;
  for (std::size_t b = 0; b < count; ++b) {
    Bucket bucket;
    bucket.path = dir / (prefix + "-" + std::to_string(b));
    mBuckets.push_back(std::move(bucket));
  }
}

SpillBuckets::~SpillBuckets() {
  mAppender.reset();  // first: its queued writes name the files
  for (std::size_t b = 0; b < mBuckets.size(); ++b) remove(b);
}

void SpillBuckets::remove(std::size_t b) noexcept {
  Bucket& bucket = mBuckets[b];
  if (bucket.removed) return;
  bucket.removed = true;
  bucket.file.reset();
  if (bucket.records) {  // a bucket without records never had a file
    std::error_code ec;
    std::filesystem::remove(bucket.path, ec);
  }
  bucket.cleanup.release();
}

void SpillBuckets::add(const std::uint64_t* keys, const float* values, std::size_t n) {
  const std::uint64_t mask = (std::uint64_t(1) << mBits) - 1;
  const std::size_t bytes = mLayout.recordBytes(), keyBytes = mLayout.keyBytes();
  const bool withValues = mLayout.values();
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t key = keys[i];
    FLIPSCOPE_CHECK(mLayout.holds(key), "batch key " << std::hex << key << " outside the grid's key bits");
    Bucket& b = mBuckets[(key >> mShift) & mask];
    if (b.buffer.size() == 0) b.buffer = mAppender->take();
    std::byte* record = b.buffer.data() + b.used;
    const std::uint64_t packed = mLayout.pack(key);
    std::memcpy(record, &packed, 8);  // the next record's bytes, if any, are written over
    if (withValues) std::memcpy(record + keyBytes, &values[i], 4);
    b.used += bytes;
    ++b.records;
    if (b.used + kRecordWriteBytes > b.buffer.size()) flush(b, false);
  }
}

void SpillBuckets::finish() {
  for (auto& b : mBuckets) flush(b, true);
  mAppender->drain();
  for (auto& b : mBuckets) b.file.reset();
}

void SpillBuckets::flush(Bucket& b, bool last) {
  const std::size_t whole =
      last ? (b.used + kDirectBlock - 1) / kDirectBlock * kDirectBlock : b.used / kDirectBlock * kDirectBlock;
  if (whole == 0) return;
  if (!b.file) {
    const DeferCleanupSignals step;  // registered and created as one step
    b.cleanup = CleanupOnSignal(b.path);
    b.file = std::make_unique<DirectFile>(b.path, DirectFile::Mode::Create);
  }
  if (whole > b.used) std::memset(b.buffer.data() + b.used, 0, whole - b.used);
  AlignedBuffer rest;
  const std::size_t left = last ? 0 : b.used - whole;
  if (!last) {
    rest = mAppender->take();
    std::memcpy(rest.data(), b.buffer.data() + whole, left);
  }
  mAppender->append(*b.file, std::move(b.buffer), whole);
  mBytesWritten += whole;
  b.buffer = std::move(rest);
  b.used = left;
  testStopPoint("spill");
}

template <class Fn>
void SpillBuckets::forEachRecord(std::size_t b, Fn&& fn) const {
  const Bucket& bucket = mBuckets[b];
  if (!bucket.records) return;
  FLIPSCOPE_CHECK(!bucket.removed, "spill bucket " << b << " read after its removal");
  DirectFile file(bucket.path, DirectFile::Mode::Read);
  const std::size_t bytes = mLayout.recordBytes();
  const bool withValues = mLayout.values();
  AlignedBuffer block(4 * mBufferBytes);  // the spill buffers are free by now (finish())
  std::byte carry[kRecordWriteBytes]{};   // a record split across two blocks (take reads its first 12 bytes)
  std::size_t carried = 0;
  std::uint64_t done = 0;
  // The record at `record`, of which at least 8 + 4 bytes may be read.
  const auto take = [&](const std::byte* record) {
    fn(mLayout.keyAt(record, b), withValues ? mLayout.valueAt(record) : 0.0f);
    ++done;
  };
  while (done < bucket.records) {
    const std::size_t got = file.read({block.data(), block.size()});
    if (got == 0) throw FileError(bucket.path, "spill file shorter than written");
    std::size_t at = 0;
    if (carried) {
      at = std::min(bytes - carried, got);
      std::memcpy(carry + carried, block.data(), at);
      carried += at;
      if (carried == bytes) {
        take(carry);
        carried = 0;
      }
    }
    // Records with kRecordWriteBytes to read in the block, then the one or two before its end.
    for (; at + kRecordWriteBytes <= got && done < bucket.records; at += bytes) take(block.data() + at);
    for (; at + bytes <= got && done < bucket.records; at += bytes) {
      std::memcpy(carry, block.data() + at, bytes);
      take(carry);
    }
    if (done < bucket.records && at < got) {
      carried = got - at;
      std::memcpy(carry, block.data() + at, carried);
    }
  }
}

void SpillBuckets::forEachPiece(std::size_t b, const PieceFn& fn) const {
  const bool withValues = mLayout.values();
  std::vector<std::uint64_t> keys;
  std::vector<float> values;
  keys.reserve(kPieceKeys);
  if (withValues) values.reserve(kPieceKeys);
  const auto hand = [&] {
    fn(keys.data(), withValues ? values.data() : nullptr, keys.size());
    keys.clear();
    values.clear();
  };
  forEachRecord(b, [&](std::uint64_t key, float value) {
    keys.push_back(key);
    if (withValues) values.push_back(value);
    if (keys.size() == kPieceKeys) hand();
  });
  if (!keys.empty()) hand();
}

void SpillBuckets::load(std::size_t b, KeyBatch& batch) const {
  FLIPSCOPE_CHECK(!batch.narrow, "spill bucket " << b << " loaded into a batch of narrow keys");
  batch.clear();
  const bool withValues = mLayout.values();
  batch.cellKeys.resize(mBuckets[b].records);
  if (withValues) batch.values.resize(mBuckets[b].records);
  std::uint64_t* keys = batch.cellKeys.data();
  float* values = batch.values.data();
  std::size_t i = 0;
  forEachRecord(b, [&](std::uint64_t key, float value) {
    keys[i] = key;
    if (withValues) values[i] = value;
    ++i;
  });
}

std::size_t SpillBuckets::recordBufferBytes(std::uint64_t records) const {
  // The file's blocks, and one more: unpack reads kRecordWriteBytes from the last record on.
  return (records * mLayout.recordBytes() + kDirectBlock - 1) / kDirectBlock * kDirectBlock + kDirectBlock;
}

void SpillBuckets::readRecords(std::size_t b, AlignedBuffer& raw) const {
  const Bucket& bucket = mBuckets[b];
  FLIPSCOPE_CHECK(!bucket.removed, "spill bucket " << b << " read after its removal");
  const std::size_t bytes = recordBufferBytes(bucket.records);
  if (raw.size() < bytes) raw = AlignedBuffer(bytes);
  if (!bucket.records) return;
  DirectFile file(bucket.path, DirectFile::Mode::Read);
  const std::size_t fileBytes = bytes - kDirectBlock;
  if (file.read({raw.data(), fileBytes}) != fileBytes) throw FileError(bucket.path, "spill file shorter than written");
}

void SpillBuckets::unpack(std::size_t b, const AlignedBuffer& raw, KeyBatch& batch) const {
  const std::uint64_t records = mBuckets[b].records;
  FLIPSCOPE_CHECK(raw.size() >= recordBufferBytes(records), "spill bucket " << b << " in " << raw.size() << " bytes");
  FLIPSCOPE_CHECK(!batch.narrow, "spill bucket " << b << " unpacked into a batch of narrow keys");
  batch.clear();
  const bool withValues = mLayout.values();
  batch.cellKeys.resize(records);
  if (withValues) batch.values.resize(records);
  std::uint64_t* keys = batch.cellKeys.data();
  float* values = batch.values.data();
  const std::size_t bytes = mLayout.recordBytes();
  const std::byte* data = raw.data();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, records, std::size_t(1) << 16), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      const std::byte* record = data + i * bytes;
      keys[i] = mLayout.keyAt(record, b);
      if (withValues) values[i] = mLayout.valueAt(record);
    }
  });
}

}  // namespace flipscope::detail
