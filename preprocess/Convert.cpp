// convert(): particle files -> BrickStore, in core or out of core (see Convert.h).
#include "preprocess/Convert.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <future>
#include <memory>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "core/AtomicFile.h"
#include "core/Elapsed.h"
#include "core/Error.h"
#include "core/NumberText.h"
#include "preprocess/BrickBinning.h"
#include "preprocess/FiniteBounds.h"
#include "preprocess/ParticleSpacing.h"
#include "preprocess/PositionRanges.h"
#include "preprocess/SpillBuckets.h"
#include "preprocess/particles/PrefetchingSource.h"
#include "preprocess/store/FrameFile.h"
#include "preprocess/store/StoreLock.h"

namespace flipscope {
namespace {

using detail::KeyBatch;
using detail::KeyGrid;
using detail::SpillBuckets;

/// Spill files are `<kSpillPrefix><pid>-<frame>[-<n>]-<bucket>`.
constexpr std::string_view kSpillPrefix = ".flipscope-spill-";

/// The test hook of Convert.h (FLIPSCOPE_CONVERT_STOP): raises the configured signal in the
/// calling thread at the configured pass through `point`.
void stopPoint(const char* point) {
  struct Stop {
    std::string point;
    long pass = 0;
    int signal = 0;
    std::atomic<long> seen{0};
  };
  static Stop* const stop = [] () -> Stop* {
    const char* spec = std::getenv("FLIPSCOPE_CONVERT_STOP");
    if (!spec || !*spec) return nullptr;
    auto* s = new Stop;
    std::string text = spec;
    const auto a = text.find(':'), b = a == std::string::npos ? a : text.find(':', a + 1);
    s->point = text.substr(0, a);
    s->pass = a == std::string::npos ? 1 : std::atol(text.c_str() + a + 1);
    const std::string name = b == std::string::npos ? "KILL" : text.substr(b + 1);
    s->signal = name == "INT" ? SIGINT : name == "TERM" ? SIGTERM : name == "HUP" ? SIGHUP : SIGKILL;
    return s;
  }();
  if (!stop || stop->point != point) return;
  if (++stop->seen == stop->pass) ::raise(stop->signal);
}

/// Memory plan of one conversion, all derived from the budget.
struct MemoryPlan {
  explicit MemoryPlan(std::uint64_t budget, bool separateValues) {
    // Key (+ value): binning sorts in place. Its runs (at most 24 bytes a detail::kKeysPerRun
    // keys: 5.6 % of the budget at most) and its per-thread blocks fit in what keys leave.
    keyBytes = separateValues ? 12 : 8;
    // At most 256 Ki particles a chunk (6 MiB of positions and velocities; two chunks are in
    // flight with read-ahead): the 20 M particle PLY of `bench render --peer embree` converted in
    // 0.67-0.70 s with chunks of 256 Ki, 0.69-0.71 s with 512 Ki, 0.70-1.00 s with 1 Mi (their
    // first touch) and 0.69-0.76 s with 64 Ki (the passes a chunk), alternating runs.
    chunkParticles = std::clamp<std::uint64_t>(budget / 256 / 24, 4096, 1 << 18);
    maxBinParticles = std::max<std::uint64_t>(budget * 6 / 10 / keyBytes, 1 << 16);
    // An eighth of the budget buffers the spill files: up to 256 of up to 1 MiB (direct writes of
    // 64 KiB ran at half the disk's speed of 1 MiB ones here).
    spillBufferBytes = std::clamp<std::uint64_t>(budget / 8 / 256 / kDirectBlock, 16, 256) * kDirectBlock;
    maxBucketFiles = std::clamp<std::uint64_t>(budget / 8 / spillBufferBytes, 2, 256);
    // A sixteenth reads the input ahead of binning, around the page cache (the binning pass's
    // ReadOptions::readOnceAheadBytes), one file at a time and until its end: at least the two
    // pieces of DirectReadAhead (4 MiB, more than a sixteenth under --mem 64M), at most 32 MiB.
    readAheadBytes = std::clamp<std::uint64_t>(budget / 16, 4 << 20, 32 << 20);
  }
  /// Of a particle's key and its value, binned in memory: 8 for narrow keys too (KeyBatch), since a
  /// spill bucket is binned in 8-byte keys; a frame of narrow keys in core takes half its share.
  std::uint64_t keyBytes;
  std::uint64_t chunkParticles;   ///< particles read at once
  std::uint64_t maxBinParticles;  ///< particles binned in memory at once
  std::uint64_t maxBucketFiles;   ///< spill files open at once
  std::uint64_t spillBufferBytes;  ///< buffer of each, a multiple of kDirectBlock
  std::uint64_t readAheadBytes;    ///< of the input, by its binning pass
};

/// Bins one frame's keys: in memory while they fit, spilled to buckets beyond.
class FrameBinner {
 public:
  /// `expectedParticles`: the source's count hint, when it gives one. `keys`: where the frame's
  /// keys are binned in memory (emptied first), storage the caller may keep for its next frame.
  FrameBinner(const KeyGrid& grid, const MemoryPlan& plan, const ConvertOptions& options,
              std::filesystem::path scratchDir, int frame, std::optional<std::uint64_t> expectedParticles,
              KeyBatch& keys)
      : mGrid(grid),
        mExpectedParticles(expectedParticles),
        mValues(grid.valuesBesideKeys()),
        mPlan(plan),
        mOptions(options),
        mScratch(std::move(scratchDir)),
        mPrefix(std::string(kSpillPrefix) + std::to_string(::getpid()) + "-" + std::to_string(frame)),
        mKeys(keys) {
    mKeys.clear();
    mKeys.sortRuns = true;
    // 4 bytes a key where they fit, until spilling starts. A frame that spilled before kept
    // 8-byte keys, which the plan does not count beside the narrow ones: setNarrow frees them.
    mKeys.setNarrow(grid.narrowKeys());
    mBatch.sortRuns = false;  // the spill files take its keys in any order
  }

  /// With particle kinds, the chunk's last column holds the type flags (convertFrame).
  void add(const ParticleChunk& chunk) {
    const AttributeColumn* types = mGrid.header.particleKinds ? &chunk.attributes.back() : nullptr;
    // The source's count says the frame will not fit in memory: binning in memory first would
    // only add memory.
    if (!mSpill && mExpectedParticles && *mExpectedParticles > mPlan.maxBinParticles) startSpilling();
    if (mSpill) {
      mBatch.clear();
      account(detail::computeKeys(chunk, mGrid, mBatch, types));
      mSpill->add(mBatch.cellKeys.data(), mBatch.values.data(), mBatch.cellKeys.size());
      return;
    }
    if (!mReserved) {
      // Address space for every key once (no reallocation copies): the budget's worth, or the
      // frame's, when its source tells (a sanitizer's allocator fills shadow for all of it).
      // Storage kept from the frame before serves as it is where it is large enough.
      mReserved = true;
      const std::uint64_t keys =
          std::min(mPlan.maxBinParticles, mExpectedParticles.value_or(mPlan.maxBinParticles)) + mPlan.chunkParticles;
      mKeys.withKeys([&](auto& vector) { vector.reserve(keys); });
      if (mValues) mKeys.values.reserve(keys);
      mKeys.runs.reserve(keys / detail::kKeysPerRun + 1);  // untouched unless computeKeys sorts
    }
    account(detail::computeKeys(chunk, mGrid, mKeys, types));
    if (mKeys.keyCount() > mPlan.maxBinParticles) startSpilling();
  }

  /// Bins everything added into `writer`; returns the frame's stats.
  FrameStats finish(FrameWriter& writer) {
    if (!mSpill) {
      binInMemory(mKeys, writer);
    } else {
      mSpill->finish();
      mSpillBytes += mSpill->bytesWritten();
      binBuckets(*mSpill, writer);
    }
    return mStats;
  }
  std::uint32_t spillBuckets() const { return mSpillBuckets; }
  std::uint64_t spillBytes() const { return mSpillBytes; }

 private:
  void account(const detail::KeyTally& t) {
    mStats.skippedInvalid += t.invalid;
    mStats.skippedOutside += t.outside;
    if (!t.ranged) return;
    mStats.attributeMin = mHasRange ? std::min(mStats.attributeMin, t.valueMin) : t.valueMin;
    mStats.attributeMax = mHasRange ? std::max(mStats.attributeMax, t.valueMax) : t.valueMax;
    mHasRange = true;
  }

  std::uint32_t bucketBitsFor(std::uint32_t availableBits) const {
    std::uint32_t bits = 1;
    while (bits < availableBits && (2ull << bits) <= mPlan.maxBucketFiles) ++bits;
    return std::min(bits, availableBits);
  }

  /// Moves the keys binned so far into bucket files. mKeys keeps its memory, where its keys were
  /// 8 bytes: the buckets are loaded into it, and pages touched once are not paid for again.
  /// Narrow keys are freed: the buckets' keys take fresh pages.
  void startSpilling() {
    const std::uint32_t bits = bucketBitsFor(mGrid.codeBits);
    const std::uint32_t shift = mGrid.cellKeyShift() + mGrid.cellBits + mGrid.codeBits - bits;
    mSpill = std::make_unique<SpillBuckets>(mScratch, mPrefix, mGrid.batchKeyBits(), shift, bits, mValues,
                                            mPlan.spillBufferBytes);
    if (mKeys.narrow) {
      // Widened a chunk's worth at a time in mBatch, the spilled chunks' batch; then freed.
      const std::uint32_t* narrow = mKeys.narrowKeys.data();
      for (std::size_t from = 0, n = mKeys.narrowKeys.size(); from < n; from += mPlan.chunkParticles) {
        mBatch.cellKeys.assign(narrow + from, narrow + std::min<std::size_t>(n, from + mPlan.chunkParticles));
        mSpill->add(mBatch.cellKeys.data(), nullptr, mBatch.cellKeys.size());
      }
      mBatch.clear();
      mKeys.setNarrow(false);
    } else {
      mSpill->add(mKeys.cellKeys.data(), mKeys.values.data(), mKeys.cellKeys.size());
    }
    mKeys.clear();
    std::vector<detail::CodedRun>().swap(mKeys.runs);  // the buckets loaded into mKeys have none
    mSpillBuckets += std::uint32_t(mSpill->size());
  }

  /// Bins each bucket in turn. Each bucket's file is removed once read, on a thread of its own
  /// (an unlink waits on the disk), and all of them before this returns: before the frame's fsync,
  /// which then need not flush the spill's blocks from the disk's cache where the filesystem
  /// discards a removed file's blocks.
  void binBuckets(SpillBuckets& buckets, FrameWriter& writer) {
    std::uint64_t largest = 0;  // of the buckets binned in memory: reserved once, no reallocation copies
    bool skewed = false;        // some bucket must be split again
    for (std::size_t b = 0; b < buckets.size(); ++b) {
      if (buckets.records(b) <= mPlan.maxBinParticles) largest = std::max(largest, buckets.records(b));
      skewed = skewed || buckets.records(b) > mPlan.maxBinParticles;
    }
    // The next bucket's records are read while this one is binned (on a thread that waits on the
    // disk; they are unpacked on every core at their turn), when the largest bucket's keys and
    // records fit one bin of the budget and no bucket is split again.
    const bool ahead =
        mOptions.readAhead && !skewed &&
        largest * mPlan.keyBytes + buckets.recordBufferBytes(largest) <= mPlan.maxBinParticles * mPlan.keyBytes;
    mKeys.cellKeys.reserve(largest);
    if (mValues) mKeys.values.reserve(largest);
    if (ahead && mNextRecords.size() < buckets.recordBufferBytes(largest))
      mNextRecords = AlignedBuffer(buckets.recordBufferBytes(largest));
    std::future<void> removing;  // of the file of the last bucket read
    const auto removeRead = [&](std::size_t b) {
      if (removing.valid()) removing.get();
      removing = std::async(std::launch::async, [&buckets, b] { buckets.remove(b); });
    };
    std::future<void> reading;                // of bucket `readBucket`'s records into mNextRecords
    std::size_t readBucket = buckets.size();  // none
    for (std::size_t b = 0; b < buckets.size(); ++b) {
      if (buckets.records(b) == 0) continue;
      if (buckets.records(b) <= mPlan.maxBinParticles) {
        if (!ahead) {
          buckets.load(b, mKeys);
        } else {
          if (readBucket == b)
            reading.get();
          else  // the first
            buckets.readRecords(b, mNextRecords);
          buckets.unpack(b, mNextRecords, mKeys);
        }
        readBucket = buckets.size();
        if (ahead) {
          std::size_t next = b + 1;
          while (next < buckets.size() && buckets.records(next) == 0) ++next;
          if (next < buckets.size()) {
            readBucket = next;
            reading =
                std::async(std::launch::async, [&buckets, this, next] { buckets.readRecords(next, mNextRecords); });
          }
        }
        removeRead(b);  // once the next read is on its way: this waits for the removal before
        binInMemory(mKeys, writer);
        continue;
      }
      // Skewed data: split this bucket by the next bits of the brick code.
      const std::uint32_t remaining = buckets.shift() - mGrid.cellKeyShift() - mGrid.cellBits;
      if (remaining == 0)
        throw InputError("a single brick holds " + std::to_string(buckets.records(b)) +
                         " particles, more than --mem allows binning at once; raise --mem or use a smaller cell size");
      const std::uint32_t bits = bucketBitsFor(remaining);
      SpillBuckets sub(mScratch, mPrefix + "-" + std::to_string(mSpillBuckets), mGrid.batchKeyBits(),
                       buckets.shift() - bits, bits, mValues, mPlan.spillBufferBytes);
      mSpillBuckets += std::uint32_t(sub.size());
      buckets.forEachPiece(b, [&](const std::uint64_t* k, const float* s, std::size_t n) { sub.add(k, s, n); });
      removeRead(b);
      sub.finish();
      mSpillBytes += sub.bytesWritten();
      binBuckets(sub, writer);
    }
    if (removing.valid()) removing.get();
  }

  /// Bins `batch` into `writer` (the batch is empty after).
  void binInMemory(KeyBatch& batch, FrameWriter& writer) {
    detail::binKeys(batch, mGrid, mStats.attributeMin, mStats.attributeMax, mOptions.zstdLevel,
                    [&](const detail::EncodedBrick& brick) {
                      writer.addBrick(brick.coord, brick.particles, brick.cells, brick.payload);
                      mStats.particles += brick.particles;
                      for (std::size_t k = 0; k < kParticleKindCount; ++k) mStats.kindCells[k] += brick.kindCells[k];
                      stopPoint("brick");
                    });
    batch.clear();
  }

  const KeyGrid& mGrid;
  std::optional<std::uint64_t> mExpectedParticles;  ///< the source's count hint, if any
  bool mValues;          ///< KeyGrid::valuesBesideKeys()
  MemoryPlan mPlan;
  const ConvertOptions& mOptions;
  std::filesystem::path mScratch;
  std::string mPrefix;
  FrameStats mStats;
  bool mHasRange = false;
  KeyBatch& mKeys;     // in memory until spilling starts; then each bucket in turn
  bool mReserved = false;  // mKeys reserved for the frame
  AlignedBuffer mNextRecords;  // the records of the bucket after, read while mKeys is binned
  KeyBatch mBatch;     // one chunk, once spilling
  std::unique_ptr<SpillBuckets> mSpill;
  std::uint32_t mSpillBuckets = 0;
  std::uint64_t mSpillBytes = 0;  // of every level's spill files
};

std::unique_ptr<ParticleSource> joined(std::vector<std::unique_ptr<ParticleSource>> parts) {
  if (parts.size() == 1) return std::move(parts.front());
  return concatSources(std::move(parts));
}

std::unique_ptr<ParticleSource> openFrame(const FrameInput& input, const ReadOptions& read) {
  std::vector<std::unique_ptr<ParticleSource>> parts;
  for (const auto& file : input.files) parts.push_back(openParticleFile(file, read));
  return joined(std::move(parts));
}

/// One file of a frame binned into a store with particle kinds: its chunks end in a column of
/// the particles' type flags, the file's kind attribute `kindName`, or all 0 (liquid) for a file
/// without one (kindName empty). `asked`: kindName was read for the types alone, as the last
/// column (else it is the stored attribute too, and copied).
class TypedSource final : public ParticleSource {
 public:
  TypedSource(std::unique_ptr<ParticleSource> inner, std::string kindName, bool asked)
      : mInner(std::move(inner)), mKindName(std::move(kindName)), mAsked(asked) {}
  std::string name() const override { return mInner->name(); }
  std::string format() const override { return mInner->format(); }
  std::vector<AttributeDesc> attributes() const override { return mInner->attributes(); }
  bool hasVelocity() const override { return mInner->hasVelocity(); }
  std::optional<std::uint64_t> countHint() const override { return mInner->countHint(); }
  std::optional<SpacingHint> spacingHint() const override { return mInner->spacingHint(); }
  std::optional<std::string> kindAttribute() const override { return mInner->kindAttribute(); }
  void rewind() override { mInner->rewind(); }
  bool read(ParticleChunk& chunk, std::size_t maxParticles) override {
    if (!mInner->read(chunk, maxParticles)) return false;
    if (mAsked) {
      FLIPSCOPE_CHECK(!chunk.attributes.empty() && chunk.attributes.back().name == mKindName, mKindName);
      return true;
    }
    AttributeColumn types{mKindName, 1, {}};
    if (mKindName.empty()) {
      types.values.assign(chunk.size(), 0.0f);
    } else {
      auto column = std::find_if(chunk.attributes.begin(), chunk.attributes.end(),
                                 [&](const AttributeColumn& c) { return c.name == mKindName; });
      FLIPSCOPE_CHECK(column != chunk.attributes.end(), mKindName);
      types.values = column->values;
    }
    chunk.attributes.push_back(std::move(types));
    return true;
  }

 private:
  std::unique_ptr<ParticleSource> mInner;
  std::string mKindName;
  bool mAsked;
};

/// Per input, per file: the attribute holding the particles' types (empty: none, liquid).
using KindAttributes = std::vector<std::vector<std::string>>;

/// A frame for convertFrame into a store with particle kinds (`kinds` of its files), else as
/// openFrame.
std::unique_ptr<ParticleSource> openTypedFrame(const FrameInput& input, const ReadOptions& read, bool storeKinds,
                                               const std::vector<std::string>& kinds) {
  if (!storeKinds) return openFrame(input, read);
  std::vector<std::unique_ptr<ParticleSource>> parts;
  for (std::size_t f = 0; f < input.files.size(); ++f) {
    const std::string& kind = kinds[f];
    ReadOptions typed = read;
    const bool asked =
        !kind.empty() && std::find(read.attributes.begin(), read.attributes.end(), kind) == read.attributes.end();
    if (asked) typed.attributes.push_back(kind);
    parts.push_back(std::make_unique<TypedSource>(openParticleFile(input.files[f], typed), kind, asked));
  }
  return joined(std::move(parts));
}

/// The kind attribute of `part` (a file) as ConvertOptions::kindAttribute asks (empty: none).
/// Throws FileError for a named attribute that is not one integer a particle.
std::string kindAttributeOf(const std::optional<std::string>& asked, const ParticleSource& part) {
  if (!asked) return part.kindAttribute().value_or("");
  if (*asked == "none") return "";
  for (const AttributeDesc& a : part.attributes())
    if (a.name == *asked) {
      if (!isIntegerType(a.type) || a.arity != 1)
        throw FileError(part.name(), "--kind-attribute: attribute '" + a.name + "' is " +
                                         std::string(valueTypeName(a.type)) +
                                         (a.arity == 1 ? "" : " x" + std::to_string(a.arity)) +
                                         ", not one integer a particle (Mantaflow's type flags)");
      return a.name;
    }
  return "";
}

/// The input files for a message: the first three, then how many more.
std::string inputFileNames(const std::vector<FrameInput>& inputs) {
  std::string names;
  std::size_t count = 0, shown = 0;
  for (const auto& input : inputs)
    for (const auto& file : input.files) {
      if (++count > 3) continue;
      names += (shown++ ? ", " : "") + file.string();
    }
  if (count > 3) names += " and " + std::to_string(count - 3) + " more files";
  return names;
}

/// `source`, or a PrefetchingSource over it in `ahead` with `readAhead`.
ParticleSource& readingAhead(ParticleSource& source, bool readAhead, std::optional<PrefetchingSource>& ahead) {
  if (!readAhead) return source;
  return ahead.emplace(source);
}

/// The bounds of the finite positions of `source`: ranges of it on every core at once where the
/// source reads ranges (readPositionRangesInParallel), else chunks in order.
Box scanBounds(ParticleSource& source, std::size_t chunkParticles, bool readAhead, Progress* progress) {
  tbb::enumerable_thread_specific<Box> rangeBounds;
  const auto addRange = [&](std::span<const glm::vec3> positions, std::uint64_t) {
    rangeBounds.local().extend(finiteBounds(positions).bounds);
  };
  Box bounds;
  if (readPositionRangesInParallel(source, addRange, progress)) {
    for (const Box& b : rangeBounds) bounds.extend(b);
    return bounds;
  }
  ParticleChunk chunk;
  std::optional<PrefetchingSource> ahead;
  ParticleSource& input = readingAhead(source, readAhead, ahead);
  while (input.read(chunk, chunkParticles)) {
    bounds.extend(finiteBounds(chunk.positions).bounds);
    if (progress) progress->advance(chunk.size());
  }
  source.rewind();
  return bounds;
}

/// What a pass over the positions alone reads: no velocities, no attributes.
ReadOptions positionsOnly(ReadOptions read) {
  read.velocity = false;
  read.attributes.clear();
  read.allAttributes = false;
  return read;
}

/// scanInputBounds(), but frame i's bounds are known[i] where it holds them (not read again).
Box scanInputBounds(const std::vector<FrameInput>& inputs, const ConvertOptions& options, std::uint64_t particles,
                    const std::vector<std::optional<Box>>& known) {
  const ReadOptions read = positionsOnly(options.read);
  const MemoryPlan plan(options.memoryBudget, false);
  Box bounds;
  std::optional<Progress> progress;  // none when every frame's bounds are known
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    if (i < known.size() && known[i]) {
      bounds.extend(*known[i]);
      continue;
    }
    if (!progress) progress.emplace("scan bounds", particles, "particles", options.progress);
    bounds.extend(scanBounds(*openFrame(inputs[i], read), plan.chunkParticles, options.readAhead, &*progress));
  }
  if (progress) progress->finish();
  return bounds;
}

/// The particle spacing of the first frame; of the next ones (up to 4 frames) while unknown.
/// `bounds[i]`: the bounds of frame i when measuring it read all of it (SpacingEstimate::bounds).
SpacingEstimate measureSpacing(const std::vector<FrameInput>& inputs, const ConvertOptions& options,
                               std::vector<std::optional<Box>>& bounds) {
  bounds.assign(inputs.size(), std::nullopt);
  SpacingEstimate estimate;
  for (std::size_t i = 0; i < std::min<std::size_t>(inputs.size(), 4); ++i) {
    auto source = openFrame(inputs[i], positionsOnly(options.read));
    const std::string frame = "frame " + std::to_string(inputs[i].frame);
    std::optional<Progress> progress;  // the metadata estimate reads nothing
    if (!source->spacingHint()) progress.emplace("particle spacing of " + frame, 0, "particles", options.progress);
    std::optional<PrefetchingSource> ahead;
    estimate = estimateParticleSpacing(readingAhead(*source, options.readAhead, ahead),
                                       progress ? &*progress : nullptr);
    bounds[i] = estimate.bounds;
    if (progress) progress->finish();
    estimate.origin = frame + ": " + estimate.origin;
    if (estimate.known()) break;
  }
  return estimate;
}

/// The attribute a convert stores.
struct StoredAttribute {
  AttributeKind kind = AttributeKind::None;
  std::string name;  ///< the input's attribute (Scalar, Magnitude), "speed" (Speed)
  bool operator==(const StoredAttribute&) const = default;
};

/// What ConvertOptions::attribute asks for, given the inputs (opened with `probe`: headers only)
/// and the attributes each holds. Throws FileError, naming the first input without it and what
/// that holds, for a missing name.
StoredAttribute chooseAttribute(const std::optional<std::string>& asked, const std::vector<FrameInput>& inputs,
                                const std::vector<std::vector<AttributeDesc>>& held, const ReadOptions& probe,
                                bool allVelocity) {
  if (!asked) return {allVelocity ? AttributeKind::Speed : AttributeKind::None, allVelocity ? "speed" : ""};
  if (*asked == "none") return {};
  if (asked->empty()) throw InputError("--attribute: an attribute name, speed, auto or none, not ''");
  std::optional<int> arity;
  const FrameInput* lacking = nullptr;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const FrameInput& input = inputs[i];
    const auto& attributes = held[i];
    auto found =
        std::find_if(attributes.begin(), attributes.end(), [&](const AttributeDesc& a) { return a.name == *asked; });
    if (found == attributes.end()) {
      lacking = &input;
      break;
    }
    if (arity && *arity != found->arity)
      throw FileError(input.files.front(), "attribute '" + *asked + "' has " + std::to_string(found->arity) +
                                               " components, but " + std::to_string(*arity) +
                                               " in the frames before; convert them into separate stores");
    arity = found->arity;
  }
  if (!lacking) return {*arity == 1 ? AttributeKind::Scalar : AttributeKind::Magnitude, *asked};
  if (*asked == "speed" && allVelocity) return {AttributeKind::Speed, "speed"};
  // The reader says it: the file, the attribute, and what the file holds.
  ReadOptions ask = probe;
  ask.attributes = {*asked};
  openFrame(*lacking, ask);
  throw FileError(lacking->files.front(), "has no attribute '" + *asked + "'");
}

/// The cells of `cellSize` that span `length` from its start: the far end lands in the last one.
double cellsAlong(double length, double cellSize) { return std::floor(length / cellSize) + 1; }

/// For a domain too long for one cell per particle spacing: where the particles the spacing
/// estimate sampled lie in a box that is not (the rest, a few flung far away, unsampled), that
/// box grown by a tenth each side, as the --domain to give; else nothing.
std::string sampledDomainHint(const SpacingEstimate& spacing) {
  if (!spacing.sampledBounds || spacing.sampledBounds->isEmpty() || !spacing.known()) return {};
  const Box& sampled = *spacing.sampledBounds;
  const glm::dvec3 margin = glm::max(sampled.extent() * 0.1, glm::dvec3(2 * spacing.spacing));
  // Rounded out to a hundredth of the longest side's power of ten, to read and type.
  const glm::dvec3 grown = sampled.extent() + 2.0 * margin;
  const double step = std::pow(10.0, std::floor(std::log10(std::max({grown.x, grown.y, grown.z}) / 100)));
  const Box domain{glm::floor((sampled.min - margin) / step) * step, glm::ceil((sampled.max + margin) / step) * step};
  const glm::dvec3 extent = domain.extent();
  if (cellsAlong(std::max({extent.x, extent.y, extent.z}), spacing.spacing) > kMaxCellsPerAxis) return {};
  std::string box;
  for (const double v : {domain.min.x, domain.min.y, domain.min.z, domain.max.x, domain.max.y, domain.max.z})
    box += (box.empty() ? "" : ",") + numberText(v);
  return ". The particles sampled for the spacing all lie within --domain " + box +
         " (their box grown by a tenth): given that, convert renders them at one cell per particle spacing " +
         "and leaves out the particles beyond it";
}

/// The header of a new store: the cell size as ConvertOptions documents it.
StoreHeader chooseHeader(const Box& bounds, const ConvertOptions& options, const StoredAttribute& attribute,
                         const SpacingEstimate& spacing, ConvertReport& report) {
  ConvertOptions o = options;
  o.particleSpacing = spacing.spacing;
  report.spacingOrigin = spacing.origin;
  if (options.cellSize) {
    report.cellSizeOrigin = "--cell-size";
    return makeStoreHeader(bounds, o, attribute.kind, attribute.name);
  }
  if (options.resolution) {
    report.cellSizeOrigin = std::to_string(*options.resolution) + " cells along the longest axis";
    return makeStoreHeader(bounds, o, attribute.kind, attribute.name);
  }
  if (spacing.known()) {
    const glm::dvec3 extent = bounds.isEmpty() ? glm::dvec3(0) : bounds.extent();
    const double longest = std::max({extent.x, extent.y, extent.z});
    const double cells = cellsAlong(longest, spacing.spacing);
    if (cells <= kMaxCellsPerAxis) {
      o.cellSize = spacing.spacing;
      report.cellSizeOrigin = "one cell per particle spacing";
      return makeStoreHeader(bounds, o, attribute.kind, attribute.name);
    }
    // The finest grid a store holds, the nearest to one cell per spacing (longest / resolution
    // puts the far corner in cell resolution + 1).
    o.resolution = kMaxCellsPerAxis - 1;
    report.warnings.push_back("one cell per particle spacing (" + numberText(spacing.spacing) +
                              ") would make the domain " + numberText(cells) + " cells long, more than " +
                              std::to_string(kMaxCellsPerAxis) + "; using " + std::to_string(*o.resolution) +
                              " cells along the longest axis instead, the most a store holds (" +
                              numberText(longest / *o.resolution / spacing.spacing) + " particle spacings a cell)" +
                              sampledDomainHint(spacing));
    report.cellSizeOrigin =
        std::to_string(*o.resolution) + " cells along the longest axis (the most; one per spacing would not fit)";
    return makeStoreHeader(bounds, o, attribute.kind, attribute.name);
  }
  report.warnings.push_back("the particle spacing is unknown (" + spacing.origin + "); using " +
                            std::to_string(kDefaultResolution) + " cells along the longest axis instead");
  o.resolution = kDefaultResolution;
  report.cellSizeOrigin = std::to_string(kDefaultResolution) + " cells along the longest axis (default)";
  return makeStoreHeader(bounds, o, attribute.kind, attribute.name);
}

/// The store directory for the length of a convert: created when missing (and then removed
/// again, on failure or SIGINT/SIGTERM/SIGHUP, if nothing is left in it), and the writer lock
/// held on it (StoreLock.h): exclusive while this convert is the only writer and cleans up,
/// then shared, so that any number of converts add frames to it at once.
class StoreDirectory {
 public:
  explicit StoreDirectory(const std::filesystem::path& dir) : mDir(dir) {
    std::error_code ec;
    {
      const DeferCleanupSignals step;  // registered and created as one step
      if (!std::filesystem::exists(dir, ec)) {
        mCleanup = CleanupOnSignal(dir, CleanupOnSignal::Kind::Directory);
        if (!std::filesystem::create_directories(dir, ec) && ec)
          throw OutputError(dir, "cannot create the store directory: " + ec.message());
        mCreated = true;
      } else if (!std::filesystem::is_directory(dir, ec)) {
        throw FileError(dir, "exists and is not a directory (a brick store is one)");
      }
    }
    try {
      // Registered and created as one step: a signal between the two left the lock file behind,
      // and with it the directory of a store that never had a frame.
      const DeferCleanupSignals step;
      if (!BrickStore::exists(dir)) mLockCleanup = CleanupOnSignal(dir / kStoreLockName);
      mLock.emplace(dir);
      stopPoint("lock");
    } catch (...) {
      if (mCreated) std::filesystem::remove(dir, ec);
      throw;
    }
  }
  ~StoreDirectory() {
    // No store left (a failed first convert) and no other writer: the lock file goes too, and
    // the directory when this convert created it.
    std::error_code ec;
    try {
      if (!BrickStore::exists(mDir)) mLock->removeFileIfAlone();
    } catch (const std::exception&) {  // the lock file stays; it is harmless
    }
    if (mCreated && std::filesystem::is_empty(mDir, ec)) std::filesystem::remove(mDir, ec);
  }
  StoreDirectory(const StoreDirectory&) = delete;
  StoreDirectory& operator=(const StoreDirectory&) = delete;

  /// No other convert writes this store: this one may remove what dead writers left.
  bool alone() const { return mLock->alone(); }
  /// The filesystem supports the store's locks (StoreLock.h).
  bool locking() const { return mLock->locking(); }
  /// This convert made the directory.
  bool created() const { return mCreated; }
  /// Housekeeping done: other writers may join.
  void share() { mLock->share(); }
  /// The store has a frame (or a header to keep): the lock file stays with it.
  void keepLockFile() { mLockCleanup.release(); }

 private:
  std::filesystem::path mDir;
  CleanupOnSignal mCleanup;
  CleanupOnSignal mLockCleanup;
  std::optional<StoreWriterLock> mLock;
  bool mCreated = false;
};

/// store.fsh of a store that this convert created and that has no frame yet: removed again when
/// the convert fails (an exception) before its first frame, unless another writer listed one
/// meanwhile (BrickStore::removeIfFrameless), so that a failed convert never leaves a store of
/// only store.fsh. SIGINT, SIGTERM and SIGHUP remove it too, as long as this convert created the
/// store directory (no other writer can have joined a store that did not exist); SIGKILL leaves
/// it: that store has no frames and reports itself incomplete.
class FramelessHeader {
 public:
  FramelessHeader(const std::filesystem::path& dir, const StoreId& id, bool createdDirectory)
      : mDir(dir), mId(id) {
    if (createdDirectory) mCleanup = CleanupOnSignal(dir / kStoreHeaderName);
  }
  ~FramelessHeader() {
    if (!mArmed) return;
    try {
      BrickStore::removeIfFrameless(mDir, mId);
    } catch (const std::exception&) {  // a damaged store.fsh: leave it for `info` to name
    }
  }
  FramelessHeader(const FramelessHeader&) = delete;
  FramelessHeader& operator=(const FramelessHeader&) = delete;
  /// The store has a frame: keep store.fsh.
  void keep() {
    mArmed = false;
    mCleanup.release();
  }

 private:
  std::filesystem::path mDir;
  StoreId mId;
  CleanupOnSignal mCleanup;
  bool mArmed = true;
};

std::uint64_t fileBytes(const std::filesystem::path& file) {
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(file, ec);
  return ec ? 0 : bytes;
}

/// The PID in a spill file name (`.flipscope-spill-<pid>-...`).
std::optional<long> spillFileOwner(std::string_view name) {
  if (name.substr(0, kSpillPrefix.size()) != kSpillPrefix) return std::nullopt;
  name.remove_prefix(kSpillPrefix.size());
  long pid = 0;
  std::size_t i = 0;
  for (; i < name.size() && i < 18 && name[i] >= '0' && name[i] <= '9'; ++i) pid = pid * 10 + (name[i] - '0');
  if (i == 0 || i >= name.size() || name[i] != '-' || pid <= 0) return std::nullopt;
  return pid;
}

void noteStaleFiles(const StaleFiles& stale, const std::string& where, ConvertReport& report) {
  if (stale.files == 0) return;
  report.warnings.push_back("removed " + std::to_string(stale.files) + " stale temporary or spill file(s) (" +
                            Progress::humanCount(double(stale.bytes)) + "B) that an interrupted convert left in " +
                            where);
}

}  // namespace

StaleFiles removeStaleFiles(const std::filesystem::path& dir, bool temporaries) {
  StaleFiles removed;
  std::error_code ec;
  const long self = long(::getpid());
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    std::optional<long> owner = spillFileOwner(name);
    if (!owner && temporaries) owner = temporaryFileOwner(name);
    if (!owner || *owner == self || processExists(*owner)) continue;
    const std::uint64_t bytes = fileBytes(entry.path());
    std::error_code removeError;
    if (std::filesystem::remove(entry.path(), removeError)) {
      ++removed.files;
      removed.bytes += bytes;
    }
  }
  return removed;
}

Box scanInputBounds(const std::vector<FrameInput>& inputs, const ConvertOptions& options, std::uint64_t particles) {
  return scanInputBounds(inputs, options, particles, {});
}

StoreHeader makeStoreHeader(const Box& bounds, const ConvertOptions& options, AttributeKind attribute,
                            const std::string& attributeName) {
  if (options.brickSize != 32 && options.brickSize != 64 && options.brickSize != 128)
    throw InputError("brick size must be 32, 64 or 128, not " + std::to_string(options.brickSize));
  if (bounds.isEmpty()) throw InputError("no finite particle positions: cannot derive a domain (give --domain)");
  const glm::dvec3 extent = bounds.extent();
  const double longest = std::max({extent.x, extent.y, extent.z});
  double cellSize = 0;
  if (options.cellSize) {
    cellSize = *options.cellSize;
  } else {
    const std::uint32_t resolution = options.resolution.value_or(kDefaultResolution);
    if (resolution == 0) throw InputError("resolution must be positive");
    cellSize = longest > 0 ? longest / resolution : 1.0;
  }
  if (!(std::isfinite(cellSize) && cellSize > 0)) throw InputError("cell size must be a positive number");
  const double spacing = options.particleSpacing.value_or(0);
  if (!(std::isfinite(spacing) && spacing >= 0)) throw InputError("particle spacing must be a positive number or 0");
  StoreHeader h;
  h.particleSpacing = spacing;
  h.brickSize = options.brickSize;
  h.cellSize = cellSize;
  h.origin = bounds.min;
  h.attribute = attribute;
  h.attributeName = attribute == AttributeKind::Speed  ? std::string("speed")
                    : attribute == AttributeKind::None ? std::string()
                                                       : attributeName;
  if ((attribute == AttributeKind::Scalar || attribute == AttributeKind::Magnitude) &&
      (h.attributeName.empty() || h.attributeName.size() > kMaxAttributeNameBytes))
    throw InputError("--attribute: an attribute name of 1 to " + std::to_string(kMaxAttributeNameBytes) +
                     " bytes, not '" + h.attributeName.substr(0, 64) + "'");
  for (char c : h.attributeName)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      throw InputError("--attribute: the attribute name has a control character");
  for (int a = 0; a < 3; ++a) {
    const double cells = cellsAlong(extent[a], cellSize);
    if (cells > kMaxCellsPerAxis)
      throw InputError("the domain is " + std::to_string(std::uint64_t(cells)) + " cells long on axis " + "xyz"[a] +
                       ", more than " + std::to_string(kMaxCellsPerAxis) + "; use a larger --cell-size");
    h.brickGrid[a] = std::uint32_t((std::uint64_t(cells) + h.brickSize - 1) / h.brickSize);
  }
  return h;
}

namespace {

/// convertFrame(); `frameless`: store.fsh of a store without frames, kept once this frame is listed.
/// `keys`: FrameBinner's, kept by convert() from frame to frame: the pages of the frame's keys
/// (4, 8 or 12 bytes a particle) are then fresh memory only once. The kernel zeroing fresh pages was
/// the largest part of a convert's profile on the development VM (up to 41 % of the samples of
/// the 100 M particle frame's).
FrameReport convertOneFrame(ParticleSource& source, BrickStore& store, int frame, const ConvertOptions& options,
                            Progress* progress, FramelessHeader* frameless, KeyBatch& keys) {
  const auto start = std::chrono::steady_clock::now();
  const StoreHeader& header = store.header();
  const AttributeKind kind = header.attribute;
  if (kind == AttributeKind::Speed && !source.hasVelocity())
    throw FileError(source.name(), "has no velocities, but the store keeps a speed attribute");
  const KeyGrid grid(header, options.domain);
  const MemoryPlan plan(options.memoryBudget, grid.valuesBesideKeys());
  const std::filesystem::path scratch = options.scratchDir.empty() ? store.directory() : options.scratchDir;

  FrameBinner binner(grid, plan, options, scratch, frame, source.countHint(), keys);
  ParticleChunk chunk;
  std::optional<PrefetchingSource> ahead;  // the next chunk is read while this one is binned
  ParticleSource& input = readingAhead(source, options.readAhead, ahead);
  while (input.read(chunk, plan.chunkParticles)) {
    const std::size_t storedColumns = kind == AttributeKind::Scalar || kind == AttributeKind::Magnitude ? 1 : 0;
    if (header.particleKinds && (chunk.attributes.size() != storedColumns + 1 || chunk.attributes.back().arity != 1))
      throw FileError(source.name(), "was read without the column of particle types that the store keeps");
    if (kind == AttributeKind::Scalar || kind == AttributeKind::Magnitude) {
      // The source must have been opened with ReadOptions::attributes = {the store's attribute}.
      if (chunk.attributes.empty() || chunk.attributes.front().name != header.attributeName)
        throw FileError(source.name(),
                        "was read without the attribute '" + header.attributeName + "' that the store keeps");
      const int arity = chunk.attributes.front().arity;
      if ((kind == AttributeKind::Scalar) != (arity == 1))
        throw FileError(source.name(), "attribute '" + header.attributeName + "' has " + std::to_string(arity) +
                                           " components here, but the store keeps " +
                                           (kind == AttributeKind::Scalar ? "a scalar" : "the magnitude of a vector"));
    }
    binner.add(chunk);
    if (progress) progress->advance(chunk.size());
    stopPoint("chunk");
  }
  FrameWriter writer(store.framePath(frame), header, frame);
  FrameReport report;
  report.frame = frame;
  report.stats = binner.finish(writer);
  // A frame the table does not list yet goes again if the convert stops before the table lists
  // it: the store never keeps a frame file it does not know.
  const bool listed = store.hasFrame(frame);
  CleanupOnSignal unlisted;
  std::optional<FrameIndex> committed;
  {
    const DeferCleanupSignals step;  // registered and renamed into place as one step
    if (!listed) unlisted = CleanupOnSignal(store.framePath(frame));
    committed = writer.finish(report.stats);
  }
  const FrameIndex& index = *committed;
  stopPoint("frame-file");
  {
    // Listing the frame and keeping its file (and store.fsh) is one step for the signal handler.
    const DeferCleanupSignals commit;
    try {
      store.addFrame(frame, report.stats);
    } catch (...) {
      std::error_code ec;
      if (!listed) std::filesystem::remove(store.framePath(frame), ec);
      throw;
    }
    unlisted.release();
    if (frameless) frameless->keep();
  }
  stopPoint("frame");
  report.bricks = std::uint32_t(index.bricks.size());
  report.storeBytes = index.fileBytes;
  report.spillBuckets = binner.spillBuckets();
  report.spillBytes = binner.spillBytes();
  report.seconds = secondsSince(start);
  return report;
}

}  // namespace

FrameReport convertFrame(ParticleSource& source, BrickStore& store, int frame, const ConvertOptions& options,
                         Progress* progress) {
  KeyBatch keys;
  return convertOneFrame(source, store, frame, options, progress, nullptr, keys);
}

void testStopPoint(const char* point) { stopPoint(point); }

ConvertReport convert(const std::vector<FrameInput>& inputs, const std::filesystem::path& storeDir,
                      const ConvertOptions& options) {
  if (inputs.empty()) throw InputError("convert: no input frames");
  for (const auto& input : inputs)
    if (input.frame < 0 || input.frame > kMaxFrame)
      throw InputError("convert: frame " + std::to_string(input.frame) + " is outside the frames a store holds, 0 to " +
                       std::to_string(kMaxFrame));
  // Open every frame once to learn velocities, attributes and counts (headers only).
  ReadOptions probe = options.read;
  probe.attributes.clear();
  probe.allAttributes = false;
  const bool byName = options.attribute && *options.attribute != "none";
  bool allVelocity = true;
  std::uint64_t hinted = 0;
  std::vector<std::vector<AttributeDesc>> held;  // with a name asked for: what each input holds
  KindAttributes kindAttributes;
  bool kinds = false;
  std::vector<AttributeDesc> firstHeld;  // what the first file holds: for a kind attribute no file has
  UpAxis filesUp = UpAxis::Unknown;       // the first file's that states one
  std::string filesUpOrigin, filesUpConflict;
  for (const auto& input : inputs) {
    std::vector<std::unique_ptr<ParticleSource>> parts;
    kindAttributes.emplace_back();
    for (const auto& file : input.files) {
      parts.push_back(openParticleFile(file, probe));
      if (const UpAxis up = parts.back()->upAxis(); up != UpAxis::Unknown) {
        if (filesUp == UpAxis::Unknown)
          filesUp = up, filesUpOrigin = file.string();
        else if (up != filesUp && filesUpConflict.empty())
          filesUpConflict = file.string() + " is " + std::string(upAxisName(up)) + " up, " + filesUpOrigin + " " +
                            std::string(upAxisName(filesUp)) + " up";
      }
      kindAttributes.back().push_back(kindAttributeOf(options.kindAttribute, *parts.back()));
      kinds = kinds || !kindAttributes.back().back().empty();
      if (&input == &inputs.front() && &file == &input.files.front()) firstHeld = parts.back()->attributes();
    }
    auto source = joined(std::move(parts));
    allVelocity = allVelocity && source->hasVelocity();
    hinted += source->countHint().value_or(0);
    if (byName) held.push_back(source->attributes());
  }
  StoredAttribute attribute = chooseAttribute(options.attribute, inputs, held, probe, allVelocity);
  const bool kindsByName = options.kindAttribute && *options.kindAttribute != "none";
  if (kindsByName && options.kindAttribute->empty())
    throw InputError("--kind-attribute: an attribute name, auto or none, not ''");
  if (kindsByName && !kinds) {
    std::string names;
    for (const auto& a : firstHeld) names += (names.empty() ? "" : ", ") + a.name;
    throw FileError(inputs.front().files.front(),
                    "has no attribute '" + *options.kindAttribute + "' (--kind-attribute), nor has any other input (" +
                        (names.empty() ? std::string("it holds positions only") : "it holds: " + names) + ")");
  }

  ConvertReport report;
  StoreDirectory directory(storeDir);
  stopPoint("directory");
  // Left by a killed convert (their writer's PID is gone): temporaries, spill files, and frame
  // files of this store that its table does not list. Only a writer alone in the store removes
  // them: another writer's are not stale, and a PID says nothing about another machine's.
  if (directory.alone()) noteStaleFiles(removeStaleFiles(storeDir, true), storeDir.string(), report);
  if (!options.scratchDir.empty() && std::filesystem::is_directory(options.scratchDir))
    noteStaleFiles(removeStaleFiles(options.scratchDir, false), options.scratchDir.string(), report);
  StoreHeader header;
  bool keepHeader = false;
  if (options.append && !directory.locking())
    throw FileError(storeDir, std::string("--append: the filesystem does not support file locks, so concurrent "
                                          "converts into this store would be unsafe (NFS: mount without nolock)"));
  if (!directory.locking())
    report.warnings.push_back(storeDir.string() + ": the filesystem does not support file locks; do not run another "
                                                  "convert into this store at the same time");
  if (options.append && !BrickStore::exists(storeDir))
    throw FileError(storeDir, std::string("--append: not a brick store (no ") + kStoreHeaderName +
                                  "); make it with a first convert, or convert --prepare");
  if (BrickStore::exists(storeDir)) {
    const BrickStore existing = BrickStore::open(storeDir);
    StaleFiles unlisted;
    for (const auto& file : directory.alone() ? existing.unlistedFrameFiles() : std::vector<std::filesystem::path>{}) {
      try {
        readFrameIndex(file, existing.header());  // a complete frame of this store, never listed
      } catch (const FileError&) {
        report.warnings.push_back(file.string() +
                                  ": not in the store's frame table and not one of its frames; left alone");
        continue;
      }
      const std::uint64_t bytes = fileBytes(file);
      std::error_code ec;
      if (std::filesystem::remove(file, ec)) ++unlisted.files, unlisted.bytes += bytes;
    }
    noteStaleFiles(unlisted, storeDir.string() + " (frame files never listed in store.fsh)", report);
    if (!existing.incomplete() || options.append) {
      header = existing.header();
      keepHeader = true;
      const StoredAttribute kept{header.attribute, header.attributeName};
      if (options.attribute && attribute != kept)
        throw InputError(
            storeDir.string() + ": the store keeps " +
            (kept.kind == AttributeKind::None ? std::string("no attribute") : "the attribute '" + kept.name + "'") +
            ", not " + (attribute.kind == AttributeKind::None ? std::string("none") : "'" + attribute.name + "'") +
            " (--attribute); convert into a new store to keep another");
      attribute = kept;
      if (kinds && !header.particleKinds) {
        if (kindsByName)
          throw InputError(storeDir.string() + ": the store has no particle kinds (store version " +
                           std::to_string(header.version) + "), not '" + *options.kindAttribute +
                           "' (--kind-attribute); convert into a new store to keep them");
        report.warnings.push_back(storeDir.string() +
                                  ": the store has no particle kinds; the inputs' kinds are not kept");
      }
      kinds = header.particleKinds;
      if (options.upAxis && *options.upAxis != header.upAxis)
        throw InputError(storeDir.string() + ": the store records " +
                         (header.upAxis == UpAxis::Unknown ? std::string("no up axis")
                                                           : std::string(upAxisName(header.upAxis)) + " up") +
                         " (store version " + std::to_string(header.version) + "), not " +
                         std::string(upAxisName(*options.upAxis)) + " (--up); convert into a new store to change it");
      if (options.cellSize && *options.cellSize != header.cellSize)
        throw InputError(storeDir.string() + ": the store's cells are " + exactNumberText(header.cellSize) +
                         " world units, not " + exactNumberText(*options.cellSize) +
                         " (--cell-size); convert into a new store to change them");
      if (options.particleSpacing && *options.particleSpacing != header.particleSpacing)
        throw InputError(storeDir.string() + ": the store's particle spacing is " +
                         (header.particleSpacing > 0 ? exactNumberText(header.particleSpacing) + " world units"
                                                     : std::string("unknown (0)")) +
                         ", not " + exactNumberText(*options.particleSpacing) +
                         " (--particle-spacing); convert into a new store to change it");
      report.cellSizeOrigin = "kept from the existing store";
      report.spacingOrigin = "the existing store";
      report.upAxisOrigin = header.version >= 6 ? "the existing store" : "a store older than version 6 records none";
    } else if (directory.alone()) {
      // Left by an interrupted or failed first convert: removed while no other writer can
      // have joined it. (A store without frames that another writer is creating now is joined.)
      std::error_code ec;
      std::filesystem::remove(storeDir / kStoreHeaderName, ec);
      report.warnings.push_back(storeDir.string() +
                                ": the store has no frames (an interrupted or failed convert); starting it anew");
    }
  }
  // Housekeeping done: from here on other writers may add frames beside this one.
  directory.share();
  // What every later pass reads: the stored attribute's column, velocities only for speed.
  ConvertOptions reading = options;
  reading.read = probe;
  reading.read.velocity = probe.velocity && attribute.kind == AttributeKind::Speed;
  if (attribute.kind == AttributeKind::Scalar || attribute.kind == AttributeKind::Magnitude)
    reading.read.attributes = {attribute.name};
  if (!keepHeader) {
    SpacingEstimate spacing;
    std::vector<std::optional<Box>> measuredBounds;  // of the frames the spacing estimate read whole
    if (options.particleSpacing) {
      spacing.spacing = *options.particleSpacing;
      spacing.origin = spacing.spacing > 0 ? "--particle-spacing" : "not measured (--particle-spacing 0)";
      if (!(std::isfinite(spacing.spacing) && spacing.spacing >= 0))
        throw InputError("particle spacing must be a positive number or 0");
    } else {
      spacing = measureSpacing(inputs, reading, measuredBounds);
    }
    Box bounds;
    if (options.domain) {
      bounds = *options.domain;
    } else {
      bounds = scanInputBounds(inputs, reading, hinted, measuredBounds);
      if (bounds.isEmpty())
        throw InputError(inputFileNames(inputs) +
                         ": no finite particle positions (no particles, or only NaN/Inf ones): cannot derive a "
                         "domain (give --domain)");
    }
    header = chooseHeader(bounds, options, attribute, spacing, report);
    header.particleKinds = kinds;
    header.upAxis = options.upAxis.value_or(filesUp);
    report.upAxisOrigin = options.upAxis                  ? "--up"
                          : filesUp != UpAxis::Unknown ? "the conventions of " + filesUpOrigin
                                                       : "the input files do not say; give --up";
    if (!options.upAxis && !filesUpConflict.empty())
      report.warnings.push_back("the inputs disagree on the up axis (" + filesUpConflict + "); the store records " +
                                std::string(upAxisName(filesUp)) + " up (give --up to choose)");
  }
  std::optional<FramelessHeader> framelessHeader;
  std::optional<BrickStore> created;
  {
    const DeferCleanupSignals step;  // store.fsh written and registered as one step
    bool wrote = false;
    created = BrickStore::createOrAppend(storeDir, header, BrickStore::FramelessStore::Join, &wrote);
    if (wrote) framelessHeader.emplace(storeDir, created->header().id, directory.created());
  }
  BrickStore& store = *created;
  report.header = store.header();
  stopPoint("header");
  if (options.prepareOnly) {
    if (framelessHeader) framelessHeader->keep();
    directory.keepLockFile();
    return report;
  }
  Progress progress("convert", hinted, "particles", options.progress);
  KeyBatch frameKeys;  // binned in memory, frame after frame in the same pages
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    progress.setLabel("convert frame " + std::to_string(inputs[i].frame) + " (" + std::to_string(i + 1) + "/" +
                      std::to_string(inputs.size()) + ")");
    ReadOptions binning = reading.read;  // the frame's last read
    binning.readOnceAheadBytes = MemoryPlan(reading.memoryBudget, false).readAheadBytes;
    auto source = openTypedFrame(inputs[i], binning, kinds, kindAttributes[i]);
    report.frames.push_back(convertOneFrame(*source, store, inputs[i].frame, reading, &progress,
                                            framelessHeader ? &*framelessHeader : nullptr, frameKeys));
    framelessHeader.reset();  // kept: the store has a frame
    directory.keepLockFile();
  }
  progress.setLabel("convert");
  std::uint64_t bricks = 0, bytes = 0;
  for (const auto& f : report.frames) bricks += f.bricks, bytes += f.storeBytes;
  progress.finish(", " + std::to_string(report.frames.size()) + " frames, " + std::to_string(bricks) + " bricks, " +
                  Progress::humanCount(double(bytes)) + "B");
  return report;
}

}  // namespace flipscope
