// SpillBuckets: the spill files of out-of-core binning (Reichl et al. 2014 §3, Fig. 2: particles
// are bucketed by the high bits of their brick's Morton code, then each bucket is binned in
// memory). One partition level: bucket b holds the batch keys (KeyBatch) whose digit
// (key >> shift) & (2^bits - 1) is b, with their attribute values when they travel beside the keys.
//
// Contract:
// - A record keeps the key's bits that a key of the grid may set, less its bucket's digit
//   (SpillRecordLayout). On the grid of `bench preprocess` that is 3 bytes a particle instead of
//   8; the spill files are written once and read once, so on a machine whose disk bounds the
//   out-of-core convert, fewer bytes are the speed-up. (A sub-bucket's records, of a bucket split
//   again, keep its parent's digit too: rare, and not worth a layout of their own.)
// - A bucket's records are in the order they were added.
// - Files are DirectFiles written in blocks from buffers of `bufferBytes` (one a bucket that
//   holds records, plus kQueuedBlocks being written); a bucket's last block is padded, its
//   record count says where its records end.
// - A bucket's file is removed by remove(b) once it was read, else on destruction, and on
//   SIGINT/SIGTERM/SIGHUP (CleanupOnSignal).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/AlignedBuffer.h"
#include "core/AtomicFile.h"
#include "preprocess/BrickBinning.h"
#include "preprocess/DirectFile.h"

namespace flipscope::detail {

/// How a spill record stores a batch key: the bits of `keyBits` (KeyGrid::batchKeyBits) outside
/// the digit [digitShift, digitShift + digitBits), packed low to high into keyBytes() bytes,
/// little-endian; then, where values travel beside the keys, the value's 4 bytes.
class SpillRecordLayout {
 public:
  SpillRecordLayout(std::uint64_t keyBits, std::uint32_t digitShift, std::uint32_t digitBits, bool values);

  std::size_t keyBytes() const { return mKeyBytes; }
  std::size_t recordBytes() const { return mKeyBytes + (mValues ? 4 : 0); }
  bool values() const { return mValues; }
  /// Whether `key` sets only bits a key of the grid may set (else its record would lose some).
  bool holds(std::uint64_t key) const { return (key & ~mKeyBits) == 0; }
  /// The key's record bits (the low keyBytes() bytes of the result).
  std::uint64_t pack(std::uint64_t key) const {
    std::uint64_t packed = 0;
    for (std::uint32_t r = 0; r < mRunCount; ++r) packed |= ((key >> mRuns[r].shift) & mRuns[r].mask) << mRuns[r].to;
    return packed;
  }
  /// The key of bucket `digit` whose record bits are `packed` (bits above keyBytes() ignored).
  std::uint64_t unpack(std::uint64_t packed, std::uint64_t digit) const {
    std::uint64_t key = digit << mDigitShift;
    for (std::uint32_t r = 0; r < mRunCount; ++r) key |= ((packed >> mRuns[r].to) & mRuns[r].mask) << mRuns[r].shift;
    return key;
  }
  /// The key of bucket `digit` whose record starts at `record`, of which 8 bytes may be read.
  std::uint64_t keyAt(const std::byte* record, std::uint64_t digit) const {
    std::uint64_t packed;
    std::memcpy(&packed, record, 8);
    return unpack(packed, digit);
  }
  /// The value of the record at `record` (values() only).
  float valueAt(const std::byte* record) const {
    float value;
    std::memcpy(&value, record + mKeyBytes, 4);
    return value;
  }

 private:
  /// Key bits [shift, shift + width(mask)) at record bit `to`.
  struct Run {
    std::uint32_t shift = 0, to = 0;
    std::uint64_t mask = 0;
  };
  std::uint64_t mKeyBits;
  std::uint32_t mDigitShift;
  bool mValues;
  std::array<Run, 4> mRuns{};  ///< the bits kept are at most 3 runs (KeyBatch's layouts less a digit)
  std::uint32_t mRunCount = 0;
  std::size_t mKeyBytes = 0;
};

class SpillBuckets {
 public:
  /// 2^bits bucket files named `dir / (prefix + "-" + b)`, created at their first block, for keys
  /// that set only `keyBits` (KeyGrid::batchKeyBits).
  SpillBuckets(const std::filesystem::path& dir, const std::string& prefix, std::uint64_t keyBits, std::uint32_t shift,
               std::uint32_t bits, bool values, std::size_t bufferBytes);
  ~SpillBuckets();
  SpillBuckets(const SpillBuckets&) = delete;
  SpillBuckets& operator=(const SpillBuckets&) = delete;

  /// Appends keys[0, n) (and values[0, n) when the buckets keep values) to their buckets.
  /// Throws FileError (disk full, I/O error); a key with bits outside keyBits is a programmer
  /// error (checked).
  void add(const std::uint64_t* keys, const float* values, std::size_t n);
  /// Writes what the buffers hold and closes the files; then forEachPiece(), load() and
  /// readRecords() read them.
  void finish();

  std::size_t size() const { return mBuckets.size(); }
  std::uint64_t records(std::size_t b) const { return mBuckets[b].records; }
  std::uint32_t shift() const { return mShift; }
  const SpillRecordLayout& layout() const { return mLayout; }
  /// Bytes written to the files so far: their records, each file's last block padded.
  std::uint64_t bytesWritten() const { return mBytesWritten; }

  /// One piece of a bucket: n keys, and their values (null without them), valid during the call.
  using PieceFn = std::function<void(const std::uint64_t* keys, const float* values, std::size_t n)>;
  /// Streams bucket b (after finish()) in pieces of at most kPieceKeys keys, in the order its
  /// records were added.
  void forEachPiece(std::size_t b, const PieceFn& fn) const;
  /// Loads bucket b (after finish()) into `batch` (its cellKeys: not a narrow batch), its file
  /// read a few buffers at a time.
  void load(std::size_t b, KeyBatch& batch) const;
  /// The bytes of a buffer that readRecords() fills for a bucket of `records` records.
  std::size_t recordBufferBytes(std::uint64_t records) const;
  /// Reads bucket b's records (after finish()) into `raw` in one read of its file, undecoded
  /// (`raw` grows to recordBufferBytes(records(b)) where it is smaller): the disk's work alone,
  /// for a thread that waits on it while the others compute. unpack() then makes the keys.
  void readRecords(std::size_t b, AlignedBuffer& raw) const;
  /// Bucket b's keys (and values) into `batch` (its cellKeys: not a narrow batch), from `raw` as
  /// readRecords(b, raw) left it, on every core.
  void unpack(std::size_t b, const AlignedBuffer& raw, KeyBatch& batch) const;
  /// Removes bucket b's file, once it was read: it is read no more (records(b) still counts
  /// it). May run on one thread while others read other buckets (not bucket b, nor beside the
  /// destructor). An unlink waits on the disk:
  /// the 256 files of a 100 M particle frame (300 MB) took 0.2 s on the development VM, whose
  /// ext4 is mounted with `discard`; there, files removed before the frame's fsync spare it from
  /// flushing their blocks out of the disk's cache (0.23 s, against 5 ms).
  void remove(std::size_t b) noexcept;

 private:
  struct Bucket {
    std::filesystem::path path;
    std::unique_ptr<DirectFile> file;
    AlignedBuffer buffer;  ///< taken at the bucket's first record
    std::size_t used = 0;  ///< bytes of buffer not yet written
    std::uint64_t records = 0;
    bool removed = false;     ///< by remove(): not to be read
    CleanupOnSignal cleanup;  ///< from before the file exists until it is removed
  };
  /// Calls fn(key, value) for each record of bucket b (value 0 without values), in order.
  template <class Fn>
  void forEachRecord(std::size_t b, Fn&& fn) const;
  /// Queues the buffer's whole blocks for writing; at the end (`last`), all of it, its last
  /// block padded. What is left moves to a buffer of its own.
  void flush(Bucket& b, bool last);

  /// Blocks being written at once: the disk works while the binning computes.
  static constexpr std::size_t kQueuedBlocks = 4;
  /// Bytes a record's store may touch: the key's 8 (whatever its record keeps) and a value's 4.
  static constexpr std::size_t kRecordWriteBytes = 12;
  /// Keys of forEachPiece's pieces at most (768 KiB with their values).
  static constexpr std::size_t kPieceKeys = std::size_t(1) << 16;

  std::uint32_t mShift, mBits;
  SpillRecordLayout mLayout;
  std::size_t mBufferBytes;
  std::uint64_t mBytesWritten = 0;
  std::vector<Bucket> mBuckets;
  std::unique_ptr<BackgroundAppender> mAppender;
};

}  // namespace flipscope::detail
