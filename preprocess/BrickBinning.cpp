// Binning of particle keys into encoded bricks (layout in BrickBinning.h).
// Sorting by brick Morton code, a block of keys at a time (a counting sort through a buffer in
// the cache), so a brick's keys are a run in each block that has some: computeKeys sorts each
// task's 16 Ki keys as it makes them where the grid has at most 512 bricks and 64 along an axis
// and the values lie in the keys (and the keys are not spilled); else binKeys sorts blocks of 64
// Ki keys (more for grids of over 2 Ki bricks). Grids of more than 32 Ki bricks or 64 along an
// axis instead go through an in-place MSD radix sort in 16-bit digits (American flag sort) in a
// stripe of the keys per task. Then per brick either a cell histogram (dense bricks) or a
// comparison sort (sparse bricks). Nothing is allocated in proportion to the keys but their runs
// (at most 24 bytes a 32 keys), because fresh memory is what binning pays most for: on the
// virtual machines of farms and clouds the first touch of a page costs more than the sort's moves.
#include "preprocess/BrickBinning.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <span>

#include <glm/geometric.hpp>

#include "core/Error.h"
#include "core/Morton.h"
#include "preprocess/CellValueSort.h"
#include "preprocess/GridCells.h"

namespace flipscope::detail {

KeyGrid::KeyGrid(const StoreHeader& h, std::optional<Box> clipBox)
    : header(h),
      clip(clipBox),
      invCellSize(1.0 / h.cellSize),
      cells(glm::u64vec3(h.brickGrid) * std::uint64_t(h.brickSize)),
      brickShift(std::uint32_t(std::countr_zero(h.brickSize))),
      cellBits(3 * brickShift),
      codeBits(3 * octreeLevelsFor(std::max({h.brickGrid.x, h.brickGrid.y, h.brickGrid.z}))),
      valueInKey(h.attribute != AttributeKind::None && cellBits + codeBits <= kPackedCellBits) {
  FLIPSCOPE_CHECK(cellBits + codeBits + 16 <= 64, "grid too large for 64-bit keys");
  const std::uint32_t mask = h.brickSize - 1;
  for (int a = 0; a < 3; ++a) {
    axisKeys[a].resize(cells[a]);
    for (std::uint32_t c = 0; c < cells[a]; ++c) {
      glm::uvec3 brick(0);
      brick[a] = c >> brickShift;
      axisKeys[a][c] = (std::uint64_t(mortonEncode3(brick.x, brick.y, brick.z)) << cellBits) |
                       (std::uint64_t(c & mask) << (std::uint32_t(a) * brickShift));
    }
  }
}

static_assert(kParticleKindCount == 4, "a batch key keeps a particle's kind in two bits");

std::uint64_t KeyGrid::batchKeyBits() const {
  const std::uint64_t cellKey = (std::uint64_t(1) << (cellBits + codeBits)) - 1;
  const std::uint64_t kindBits = std::uint64_t(kParticleKindCount - 1);
  const bool kinds = header.particleKinds;
  if (valueInKey) return ((cellKey | (kinds ? kindBits << kPackedCellBits : 0)) << 32) | 0xffffffffull;
  return cellKey | (kinds ? kindBits << kKindShift : 0);
}

namespace {

/// Keys a block holds at least (splitBlocksByBrick): 512 KiB, which with its copy sorted by
/// brick stays in a core's L2 cache.
constexpr std::size_t kBlockKeys = std::size_t(1) << 16;
/// A block sorted by brick in binKeys holds at least this many keys a brick of the grid, so that
/// its runs, one a brick it holds, are at most one per kKeysPerRun keys whatever the order.
constexpr std::size_t kBlockKeysPerBrick = kKeysPerRun;
/// Grids of at most this many bricks, whose brick codes have at most kBlockSplitCodeBits bits (a
/// counter a code: 1 MiB a thread), are sorted by blocks (of up to 1 Mi keys, 8 MiB); others (a
/// larger or a long, thin grid) split by stripes, in place.
constexpr std::uint64_t kBlockSplitBricks = std::uint64_t(1) << 15;
constexpr std::uint32_t kBlockSplitCodeBits = 18;

std::uint64_t gridBricks(const KeyGrid& grid) {
  const glm::u64vec3 bricks(grid.header.brickGrid);
  return bricks.x * bricks.y * bricks.z;
}

/// sortBlockByBrick's counters, kept by each thread from block to block.
struct BlockSortCounters {
  std::vector<std::uint32_t> counts;   ///< a code's keys, then its next place; zero between blocks
  std::vector<std::uint32_t> present;  ///< the codes of the block
  bool countsZero = true;              ///< false only where a block threw before its reset
};
BlockSortCounters& threadBlockSortCounters() {
  thread_local BlockSortCounters counters;
  return counters;
}

/// Sorts block[0, size) by brick code (`codeBits` bits from `lowBit`): a count of each code,
/// then every key copied to its code's place in a buffer of the thread's and back. Appends one
/// run per code, ascending, at `first` plus its place in the block. Each key is read three times
/// and written twice, within the cache for blocks of up to 64 Ki keys, where the in-place split
/// (splitByBrick) swaps each key once into a place anywhere in its stripe: a miss a key. On the
/// 20 M particle PLY's 20 M keys that split was 14 % of the convert. The thread keeps its buffer
/// (its largest block, 4 or 8 bytes a key) and counters (4 bytes a code, one set for both key
/// sizes: BlockSortCounters) for the next block.
template <class Key>
void sortBlockByBrick(Key* block, std::size_t size, std::size_t first, std::uint32_t lowBit, std::uint32_t codeBits,
                      std::vector<CodedRun>& runs) {
  if (size == 0) return;
  const std::uint64_t mask = (std::uint64_t(1) << codeBits) - 1;
  thread_local UninitializedVector<Key> sorted;
  BlockSortCounters& counters = threadBlockSortCounters();
  std::vector<std::uint32_t>& counts = counters.counts;
  std::vector<std::uint32_t>& present = counters.present;
  bool& countsZero = counters.countsZero;
  if (!countsZero) std::fill(counts.begin(), counts.end(), 0u);
  countsZero = false;
  counts.resize(std::size_t(1) << codeBits);
  present.clear();
  for (std::size_t i = 0; i < size; ++i) {
    const auto code = std::uint32_t((std::uint64_t(block[i]) >> lowBit) & mask);
    if (counts[code]++ == 0) present.push_back(code);
  }
  std::sort(present.begin(), present.end());
  std::uint32_t offset = 0;
  for (std::uint32_t code : present) {
    const std::uint32_t count = counts[code];
    runs.push_back({code, {first + offset, first + offset + count}});
    counts[code] = offset;  // now the code's next place
    offset += count;
  }
  sorted.resize(size);
  for (std::size_t i = 0; i < size; ++i)
    sorted[counts[std::uint32_t((std::uint64_t(block[i]) >> lowBit) & mask)]++] = block[i];
  std::memcpy(block, sorted.data(), size * sizeof(Key));
  for (std::uint32_t code : present) counts[code] = 0;
  countsZero = true;
}

}  // namespace

float attributeValue(const ParticleChunk& chunk, AttributeKind kind, std::size_t i) {
  switch (kind) {
    case AttributeKind::None:
      return 0.0f;
    case AttributeKind::Speed:
      return glm::length(chunk.velocities[i]);
    case AttributeKind::Scalar:
      return chunk.attributes.front().values[i];
    case AttributeKind::Magnitude: {
      const AttributeColumn& column = chunk.attributes.front();
      const float* v = column.values.data() + i * std::size_t(column.arity);
      float sum = 0;
      for (int c = 0; c < column.arity; ++c) sum += v[c] * v[c];
      return std::sqrt(sum);
    }
  }
  return 0.0f;
}

ParticleKind kindOfTypeValue(float flags) {
  if (!(flags >= -2147483648.0f && flags < 2147483648.0f)) return ParticleKind::Liquid;  // NaN too
  return fromMantaflowType(std::int32_t(flags));
}

namespace {

/// computeKeys() into `keyVector`, out's cellKeys or narrowKeys (Key: 8 or 4 bytes).
template <class Key>
KeyTally computeKeysInto(const ParticleChunk& chunk, const KeyGrid& grid, KeyBatch& out,
                         UninitializedVector<Key>& keyVector, const AttributeColumn* types);

}  // namespace

KeyTally computeKeys(const ParticleChunk& chunk, const KeyGrid& grid, KeyBatch& out, const AttributeColumn* types) {
  const std::size_t n = chunk.size();
  const AttributeKind kind = grid.header.attribute;
  FLIPSCOPE_CHECK(!out.narrow || grid.narrowKeys(), "narrow keys for a grid whose keys need more than 32 bits");
  FLIPSCOPE_CHECK(!out.narrow || !types, "narrow keys carry no kinds");
  FLIPSCOPE_CHECK(!types || (types->arity == 1 && types->values.size() == n),
                  "a type column needs one value a particle");
  FLIPSCOPE_CHECK(kind != AttributeKind::Speed || chunk.velocities.size() == n, "speed needs velocities");
  FLIPSCOPE_CHECK(kind != AttributeKind::Scalar || (!chunk.attributes.empty() && chunk.attributes.front().arity == 1 &&
                                                    chunk.attributes.front().values.size() == n),
                  "a scalar attribute needs its column");
  FLIPSCOPE_CHECK(kind != AttributeKind::Magnitude ||
                      (!chunk.attributes.empty() &&
                       chunk.attributes.front().values.size() == n * std::size_t(chunk.attributes.front().arity)),
                  "a vector attribute needs its column");
  return out.withKeys([&](auto& keys) { return computeKeysInto(chunk, grid, out, keys, types); });
}

namespace {

template <class Key>
KeyTally computeKeysInto(const ParticleChunk& chunk, const KeyGrid& grid, KeyBatch& out,
                         UninitializedVector<Key>& keyVector, const AttributeColumn* types) {
  const std::size_t n = chunk.size();
  const AttributeKind kind = grid.header.attribute;
  const bool attribute = grid.attribute();
  const bool separateValues = grid.valuesBesideKeys();
  const std::size_t base = keyVector.size();
  keyVector.resize(base + n);
  if (separateValues) out.values.resize(base + n);
  Key* keys = keyVector.data() + base;
  float* values = separateValues ? out.values.data() + base : nullptr;
  // Fixed blocks, each compacted in place by its own task; skipped particles close up after.
  struct Tally {
    std::size_t kept = 0;
    std::uint64_t invalid = 0, outside = 0;
    float valueMin = std::numeric_limits<float>::infinity(), valueMax = -std::numeric_limits<float>::infinity();
  };
  constexpr std::size_t kBlock = 1 << 14;
  std::vector<Tally> tallies((n + kBlock - 1) / kBlock);
  // On grids of few bricks, each block's keys are sorted by brick while they are in the cache,
  // and their runs kept (KeyBatch::runs), unless the batch holds other keys or will be spilled.
  const bool sortBlocks = out.sortRuns && out.sortedKeys == base && !separateValues &&
                          grid.codeBits <= kBlockSplitCodeBits && gridBricks(grid) * kKeysPerRun <= kBlock;
  const std::uint32_t codeShift = grid.cellKeyShift() + grid.cellBits;
  std::vector<std::vector<CodedRun>> blockRuns(sortBlocks ? tallies.size() : 0);
  const GridCells gridCells(grid.header.origin, grid.invCellSize, grid.cells, grid.clip);
  tbb::parallel_for(std::size_t(0), tallies.size(), [&](std::size_t b) {
    // The loop's inputs as the task's locals, not the grid's members nor the closure's
    // references: the compiler need not load them again (twice, through a reference) after
    // each key stored.
    const glm::vec3* positions = chunk.positions.data();
    // Speed, the default attribute, inline: attributeValue is a call and a switch a particle.
    const glm::vec3* velocities = kind == AttributeKind::Speed ? chunk.velocities.data() : nullptr;
    const float* typeValues = types ? types->values.data() : nullptr;
    const std::uint64_t *keysX = grid.axisKeys[0].data(), *keysY = grid.axisKeys[1].data(),
                        *keysZ = grid.axisKeys[2].data();
    Key* const keyOut = keys;
    float* const valueOut = values;
    const GridCells cellsOf = gridCells;
    const bool valueInKey = grid.valueInKey, withAttribute = attribute;
    Tally t;
    const std::size_t begin = b * kBlock, end = std::min(n, begin + kBlock);
    std::size_t to = begin;
    // Particle i, in `cell`, kept.
    const auto keep = [&](std::size_t i, std::uint32_t cellX, std::uint32_t cellY, std::uint32_t cellZ) {
      const std::uint64_t cellKey = keysX[cellX] | keysY[cellY] | keysZ[cellZ];
      if constexpr (std::is_same_v<Key, std::uint32_t>) {
        keyOut[to] = Key(cellKey);  // narrow: no attribute, no kinds (KeyGrid::narrowKeys)
      } else {
        const std::uint64_t particleKind = typeValues ? std::uint64_t(kindOfTypeValue(typeValues[i])) : 0;
        const float s = velocities ? glm::length(velocities[i]) : withAttribute ? attributeValue(chunk, kind, i) : 0.0f;
        if (withAttribute && std::isfinite(s)) {
          t.valueMin = std::min(t.valueMin, s);
          t.valueMax = std::max(t.valueMax, s);
        }
        if (valueInKey) {
          keyOut[to] = Key((((particleKind << kPackedCellBits) | cellKey) << 32) | std::bit_cast<std::uint32_t>(s));
        } else {
          keyOut[to] = Key((particleKind << kKindShift) | cellKey);
          if (valueOut) valueOut[to] = s;
        }
      }
      ++to;
    };
    // Particle i on its own: kept, or counted as invalid or outside.
    const auto sortOut = [&](std::size_t i) {
      const glm::vec3 p = positions[i];
      glm::uvec3 cell;
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        ++t.invalid;
      } else if (!cellsOf.one(p, cell)) {  // outside the grid or the clip box
        ++t.outside;
      } else {
        keep(i, cell.x, cell.y, cell.z);
      }
    };
    // Four at a time; a four with a particle that is not kept, one at a time.
    std::size_t i = begin;
    CellsOfFour four;
    for (; i + 4 <= end; i += 4) {
      if (cellsOf.four(positions + i, four)) {
        for (std::size_t k = 0; k < 4; ++k) keep(i + k, four.x[k], four.y[k], four.z[k]);
      } else {
        for (std::size_t k = 0; k < 4; ++k) sortOut(i + k);
      }
    }
    for (; i < end; ++i) sortOut(i);
    t.kept = to - begin;
    tallies[b] = t;
    if (sortBlocks) sortBlockByBrick(keys + begin, t.kept, 0, codeShift, grid.codeBits, blockRuns[b]);
  });

  KeyTally result;
  std::size_t kept = 0;
  for (std::size_t b = 0; b < tallies.size(); ++b) {
    const Tally& t = tallies[b];
    if (kept != b * kBlock && t.kept) {  // rare: close up after skipped particles, in order
      std::memmove(keys + kept, keys + b * kBlock, t.kept * sizeof(*keys));
      if (values) std::memmove(values + kept, values + b * kBlock, t.kept * sizeof(*values));
    }
    if (sortBlocks)
      for (const CodedRun& r : blockRuns[b])
        out.runs.push_back({r.code, {base + kept + r.run.begin, base + kept + r.run.end}});
    kept += t.kept;
    result.invalid += t.invalid;
    result.outside += t.outside;
    if (attribute && t.valueMin <= t.valueMax) {
      result.valueMin = result.ranged ? std::min(result.valueMin, t.valueMin) : t.valueMin;
      result.valueMax = result.ranged ? std::max(result.valueMax, t.valueMax) : t.valueMax;
      result.ranged = true;
    }
  }
  result.kept = kept;
  // Blocks thinned by skipped particles, or short (small chunks under a small --mem), can hold a
  // run for few keys: past one per kKeysPerRun keys (plus one a brick), no runs are kept.
  if (sortBlocks && out.runs.size() <= (base + kept) / kKeysPerRun + gridBricks(grid)) {
    out.sortedKeys = base + kept;
  } else if (sortBlocks) {
    std::vector<CodedRun>().swap(out.runs);  // out.sortedKeys stays short: binKeys sorts the keys
  }
  keyVector.resize(base + kept);
  if (values) out.values.resize(base + kept);
  return result;
}

}  // namespace

std::uint16_t quantizeAttribute(float s, float min, float max) {
  if (!(max > min) || std::isnan(s)) return 0;
  const float t = (s - min) / (max - min);
  if (!(t > 0.0f)) return 0;
  if (!(t < 1.0f)) return 65535;
  // std::lround without the library call (a third of the quantizing pass): x - floor(x) is
  // exact for 0 < x < 2^23.
  const float x = t * 65535.0f, whole = std::floor(x);
  return std::uint16_t(std::uint16_t(whole) + (x - whole >= 0.5f ? 1 : 0));
}

namespace {

/// Turns the batch keys of `batch`, whose values lie beside them (KeyGrid::valuesBesideKeys), into
/// binning keys in place, the values quantized over [min, max], and frees the values: the split
/// by brick moves the keys alone.
void makeBinningKeys(KeyBatch& batch, const KeyGrid& grid, float min, float max) {
  const bool kinds = grid.header.particleKinds;
  std::uint64_t* keys = batch.cellKeys.data();
  const float* values = batch.values.data();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, batch.cellKeys.size(), 1 << 16), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i)
      keys[i] = binningKey(keys[i], quantizeAttribute(values[i], min, max), kinds);
  });
  ValueVector().swap(batch.values);
}

constexpr std::uint32_t kDigitBits = 16;
constexpr std::size_t kParallelThreshold = 1 << 16;

/// Sorts keys[begin,end) in place by the bits [lowBit, highBit) (the brick code), most
/// significant digit first (American flag sort: a histogram, then each key swapped into its
/// digit's range); appends one run per distinct code in ascending code order.
void splitByBrick(std::uint64_t* keys, std::size_t begin, std::size_t end, std::uint32_t lowBit, std::uint32_t highBit,
                  std::vector<BrickRun>& runs) {
  if (begin == end) return;
  if (highBit <= lowBit) {
    runs.push_back({begin, end});
    return;
  }
  const std::uint32_t bits = std::min(kDigitBits, highBit - lowBit);
  const std::uint32_t shift = highBit - bits;
  const std::uint64_t mask = (1ull << bits) - 1;
  auto digit = [&](std::uint64_t key) { return std::size_t((key >> shift) & mask); };
  std::uint64_t* const a = keys + begin;
  const std::size_t n = end - begin;
  // Fast path: every key has the same digit.
  const std::size_t first = digit(a[0]);
  bool uniform = true;
  for (std::size_t i = 1; i < n && uniform; ++i) uniform = digit(a[i]) == first;
  if (uniform) return splitByBrick(keys, begin, end, lowBit, shift, runs);

  const std::size_t buckets = std::size_t(1) << bits;
  const std::size_t blocks = n >= kParallelThreshold ? 8 : 1;
  const std::size_t blockSize = (n + blocks - 1) / blocks;
  std::vector<std::vector<std::size_t>> histograms(blocks, std::vector<std::size_t>(buckets, 0));
  tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t b) {
    auto& h = histograms[b];
    const std::size_t e = std::min(n, (b + 1) * blockSize);
    for (std::size_t i = b * blockSize; i < e; ++i) ++h[digit(a[i])];
  });
  std::vector<std::size_t> heads(buckets + 1, 0);  // heads[d]: next slot of digit d; ends: heads[d + 1] at start
  for (std::size_t d = 0; d < buckets; ++d) {
    heads[d + 1] = heads[d];
    for (const auto& h : histograms) heads[d + 1] += h[d];
  }
  const std::vector<std::size_t> starts = heads;
  for (std::size_t d = 0; d < buckets; ++d) {
    const std::size_t stop = starts[d + 1];
    while (heads[d] < stop) {
      std::uint64_t key = a[heads[d]];
      for (std::size_t e = digit(key); e != d; e = digit(key)) std::swap(key, a[heads[e]++]);
      a[heads[d]++] = key;
    }
  }
  if (shift == lowBit) {
    for (std::size_t d = 0; d < buckets; ++d)
      if (starts[d] != starts[d + 1]) runs.push_back({begin + starts[d], begin + starts[d + 1]});
    return;
  }
  // Deeper digits: the digit's ranges are sorted independently, their runs kept in order.
  std::vector<std::vector<BrickRun>> sub(buckets);
  tbb::parallel_for(std::size_t(0), buckets, [&](std::size_t d) {
    splitByBrick(keys, begin + starts[d], begin + starts[d + 1], lowBit, shift, sub[d]);
  });
  for (const auto& r : sub) runs.insert(runs.end(), r.begin(), r.end());
}

/// Up to this many stripes of the keys are split by brick independently, one task each.
constexpr std::size_t kMaxStripes = 8;
/// Keys a stripe holds at least.
constexpr std::size_t kStripeKeys = std::size_t(1) << 20;

/// The keys of a block for a grid of `bricks` bricks: kBlockKeys, or more for large grids.
std::size_t blockKeysFor(std::uint64_t bricks) {
  return std::max(kBlockKeys, std::bit_ceil(std::size_t(bricks) * kBlockKeysPerBrick));
}

/// Sorts each block of `blockKeys` keys by brick code (sortBlockByBrick), in parallel. Appends
/// the runs, blocks in order.
template <class Key>
void splitBlocksByBrick(Key* keys, std::size_t n, std::uint32_t lowBit, std::uint32_t codeBits, std::size_t blockKeys,
                        std::vector<CodedRun>& runs) {
  const std::size_t blocks = (n + blockKeys - 1) / blockKeys;
  std::vector<std::vector<CodedRun>> blockRuns(blocks);
  tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t b) {
    sortBlockByBrick(keys + b * blockKeys, std::min(blockKeys, n - b * blockKeys), b * blockKeys, lowBit, codeBits,
                     blockRuns[b]);
  });
  for (const auto& r : blockRuns) runs.insert(runs.end(), r.begin(), r.end());
}

/// The keys of one brick: its runs (of the blocks, or of the stripes, that hold some).
struct BrickParts {
  std::uint64_t code = 0;
  std::span<const CodedRun> runs;  ///< in binKeys' list, each of this code
  std::size_t keys() const {
    std::size_t n = 0;
    for (const CodedRun& r : runs) n += r.run.end - r.run.begin;
    return n;
  }
};

/// Where the fields of a key lie as binKeys reads it: the brick code, the cell in the brick,
/// the kind and the 16-bit attribute. Binning keys (binningKey); or batch keys read as they are,
/// their attribute quantized as it is read, so that no pass over the keys turns them into
/// binning keys first (KeyBatch's layouts: Packed, [kind][cell key: 30][value]; Plain, a store
/// without an attribute, [kind at 48][cell key]). Each field is the binning key's.
struct KeyFields {
  enum class Layout { Binning, Packed, Plain };
  Layout layout = Layout::Binning;
  bool kinds = false;
  float min = 0, max = 0;  ///< the attribute's quantization range (Packed)
  std::uint32_t cellBits = 0;

  /// The cell key's lowest bit.
  std::uint32_t cellShift() const { return layout == Layout::Binning ? 16 : layout == Layout::Packed ? 32 : 0; }
  /// The brick code's lowest bit.
  std::uint32_t codeShift() const { return cellShift() + cellBits; }
  std::uint32_t cellOf(std::uint64_t key) const {
    return std::uint32_t((key >> cellShift()) & ((std::uint64_t(1) << cellBits) - 1));
  }
  ParticleKind kindOf(std::uint64_t key) const {
    switch (layout) {
      case Layout::Binning:
        return ParticleKind(key & 3);
      case Layout::Packed:
        return ParticleKind(key >> (32 + kPackedCellBits));
      case Layout::Plain:
        break;
    }
    return ParticleKind((key >> kKindShift) & 3);
  }
  /// The binning key's attribute field, widened back to 16 bits with kinds (14 stored).
  std::uint16_t attributeOf(std::uint64_t key) const {
    if (layout == Layout::Plain) return 0;
    const std::uint64_t binning = layout == Layout::Binning ? key : binningKeyOf(key);
    if (!kinds) return std::uint16_t(binning & 0xffff);
    const auto narrow = std::uint32_t((binning >> 2) & 0x3fff);
    return std::uint16_t((narrow << 2) | (narrow >> 12));  // 14 bits widened: 0 -> 0, 16383 -> 65535
  }
  /// What makeBinningKeys would make of `key`.
  std::uint64_t binningKeyOf(std::uint64_t key) const {
    switch (layout) {
      case Layout::Binning:
        return key;
      case Layout::Packed: {
        const auto high = std::uint32_t(key >> 32);
        const std::uint64_t cellKey =
            (high & ((1u << kPackedCellBits) - 1)) | (std::uint64_t(high >> kPackedCellBits) << kKindShift);
        return binningKey(cellKey, quantizeAttribute(std::bit_cast<float>(std::uint32_t(key)), min, max), kinds);
      }
      case Layout::Plain:
        break;
    }
    return binningKey(key, 0, kinds);
  }
};

/// What decodeRun reuses from one brick to the next (one a thread).
struct DecodeScratch {
  std::vector<std::uint32_t> histogram;  ///< per cell of a dense brick: its keys, then its first attribute slot
  std::vector<ParticleKind> cellKinds;   ///< per cell of a dense brick
  std::vector<std::uint64_t> gathered;   ///< a sparse brick's binning keys, in one piece to sort
  UninitializedVector<std::uint32_t> cells, counts;  ///< a dense brick's occupied cells, written without a branch
};

/// Encodes one brick's keys (same brick code, any order, in the runs of `parts` of `all`, their
/// fields where `fields` says) into `out` (reuses its vectors); with kinds, a cell's kind is the
/// smallest of its keys'.
template <class Key>
void decodeRun(Key* all, const BrickParts& parts, const KeyGrid& grid, const KeyFields& fields, bool attribute,
               DecodedBrick& out, DecodeScratch& scratch) {
  const bool kinds = fields.kinds;
  std::vector<std::uint32_t>& histogram = scratch.histogram;
  std::vector<ParticleKind>& cellKinds = scratch.cellKinds;
  std::vector<std::uint64_t>& gathered = scratch.gathered;
  out.cells.clear();
  out.counts.clear();
  out.attributes.clear();
  out.kinds.clear();
  const std::uint32_t cellsPerBrick = grid.header.cellsPerBrick();
  const auto cellOf = [&](std::uint64_t key) { return fields.cellOf(key); };
  const auto kindOf = [&](std::uint64_t key) { return fields.kindOf(key); };
  const auto attributeOf = [&](std::uint64_t key) { return fields.attributeOf(key); };
  const std::size_t total = parts.keys();
  auto forEachKey = [&](auto f) {
    for (const CodedRun& r : parts.runs)
      for (std::size_t i = r.run.begin; i != r.run.end; ++i) f(all[i]);
  };
  if (total * 16 < cellsPerBrick) {
    // Sparse: sort the binning keys, (cell, attribute), directly.
    // In place where the brick's keys are one run of binning keys; else gathered as binning keys.
    std::span<std::uint64_t> keys;
    bool inPlace = false;
    if constexpr (std::is_same_v<Key, std::uint64_t>) {
      const BrickRun& first = parts.runs[0].run;
      inPlace = parts.runs.size() == 1 && fields.layout == KeyFields::Layout::Binning;
      if (inPlace) keys = {all + first.begin, first.end - first.begin};
    }
    if (!inPlace) {
      gathered.clear();
      forEachKey([&](std::uint64_t k) { gathered.push_back(fields.binningKeyOf(k)); });
      keys = gathered;
    }
    std::sort(keys.begin(), keys.end());
    KeyFields sorted = fields;
    sorted.layout = KeyFields::Layout::Binning;
    const auto cellOf = [&](std::uint64_t key) { return sorted.cellOf(key); };
    const auto kindOf = [&](std::uint64_t key) { return sorted.kindOf(key); };
    const auto attributeOf = [&](std::uint64_t key) { return sorted.attributeOf(key); };
    for (std::size_t i = 0; i < keys.size(); ++i) {
      const std::uint32_t cell = cellOf(keys[i]);
      if (out.cells.empty() || out.cells.back() != cell) {
        out.cells.push_back(cell);
        out.counts.push_back(0);
        if (kinds) out.kinds.push_back(kindOf(keys[i]));
      }
      ++out.counts.back();
      if (kinds) out.kinds.back() = std::min(out.kinds.back(), kindOf(keys[i]));
      if (attribute) out.attributes.push_back(attributeOf(keys[i]));
    }
    return;
  }
  // Dense: histogram over the brick's cells.
  histogram.assign(cellsPerBrick, 0);
  forEachKey([&](std::uint64_t k) { ++histogram[cellOf(k)]; });
  if (kinds) {
    cellKinds.assign(cellsPerBrick, ParticleKind(kParticleKindCount - 1));
    forEachKey([&](std::uint64_t k) { cellKinds[cellOf(k)] = std::min(cellKinds[cellOf(k)], kindOf(k)); });
  }
  // The occupied cells, without a branch on each (about half of a liquid brick's are empty).
  scratch.cells.resize(cellsPerBrick);
  scratch.counts.resize(cellsPerBrick);
  std::uint32_t offset = 0, occupied = 0;
  for (std::uint32_t c = 0; c < cellsPerBrick; ++c) {
    const std::uint32_t count = histogram[c];
    scratch.cells[occupied] = c;
    scratch.counts[occupied] = count;
    histogram[c] = offset;  // becomes the cell's first attribute slot
    offset += count;
    occupied += count != 0;
  }
  out.cells.assign(scratch.cells.begin(), scratch.cells.begin() + occupied);
  out.counts.assign(scratch.counts.begin(), scratch.counts.begin() + occupied);
  if (kinds)
    for (std::uint32_t c : out.cells) out.kinds.push_back(cellKinds[c]);
  if (!attribute) return;
  out.attributes.resize(total);
  forEachKey([&](std::uint64_t k) { out.attributes[histogram[cellOf(k)]++] = attributeOf(k); });
  std::uint16_t* cellValues = out.attributes.data();
  for (auto count : out.counts) {
    sortCellValues(cellValues, count);
    cellValues += count;
  }
}

/// What binKeys keeps, a set a thread, from brick to brick (one set for both key sizes).
std::pair<DecodedBrick, DecodeScratch>& threadEncodeScratch() {
  thread_local std::pair<DecodedBrick, DecodeScratch> scratch;
  return scratch;
}

/// Narrow keys are never split by stripes: their grids' cell keys fit 32 bits, of which the
/// cell in a brick takes 15 at least (bricks of 32^3), which leaves at most 15 bits of brick code
/// (3 a level of the octree): at most 32^3 bricks.
constexpr std::uint32_t kNarrowCodeBits = (32 - 15) / 3 * 3;
static_assert(kNarrowCodeBits <= kBlockSplitCodeBits && (std::uint64_t(1) << kNarrowCodeBits) <= kBlockSplitBricks);

/// binKeys() of `keys`, keyBatch's cellKeys or narrowKeys, whose fields lie where `fields` says.
template <class Key>
void binKeysOf(std::span<Key> keys, KeyBatch& keyBatch, const KeyGrid& grid, const KeyFields& fields, int zstdLevel,
               const std::function<void(const EncodedBrick&)>& sink) {
  if (keys.empty()) return;
  const bool attribute = grid.attribute();
  const std::uint32_t lowBit = fields.codeShift();
  const std::uint64_t codeMask = (std::uint64_t(1) << grid.codeBits) - 1;
  // A brick's keys end up in runs, of the blocks or of the stripes (decodeRun does not need them
  // in one piece, nor in order).
  std::vector<CodedRun> coded;
  if (keyBatch.sortedKeys == keys.size() && !grid.valuesBesideKeys()) {
    coded.swap(keyBatch.runs);  // computeKeys sorted them already
  } else if (gridBricks(grid) <= kBlockSplitBricks && grid.codeBits <= kBlockSplitCodeBits) {
    splitBlocksByBrick(keys.data(), keys.size(), lowBit, grid.codeBits, blockKeysFor(gridBricks(grid)), coded);
  } else if constexpr (!std::is_same_v<Key, std::uint64_t>) {
    FLIPSCOPE_CHECK(false, "narrow keys on a grid of " << gridBricks(grid) << " bricks, split by stripes");
  } else {
    // The in-place split moves keys one at a time: stripes of the keys are split on their own,
    // in parallel.
    const std::size_t stripes = std::clamp<std::size_t>(
        std::min<std::size_t>(keys.size() / kStripeKeys, std::size_t(tbb::this_task_arena::max_concurrency())), 1,
        kMaxStripes);
    std::vector<std::vector<BrickRun>> stripeRuns(stripes);
    tbb::parallel_for(std::size_t(0), stripes, [&](std::size_t s) {
      splitByBrick(keys.data(), keys.size() * s / stripes, keys.size() * (s + 1) / stripes, lowBit,
                   lowBit + grid.codeBits, stripeRuns[s]);
    });
    for (const auto& runs : stripeRuns)
      for (const BrickRun& run : runs) coded.push_back({(keys[run.begin] >> lowBit) & codeMask, run});
  }
  keyBatch.runs.clear();  // used or stale: a second call on this batch sorts the keys itself
  keyBatch.sortedKeys = 0;
  // Ascending codes, a brick's runs in key order (the runs do not overlap: a total order).
  std::sort(coded.begin(), coded.end(), [](const CodedRun& a, const CodedRun& b) {
    return a.code != b.code ? a.code < b.code : a.run.begin < b.run.begin;
  });
  std::vector<BrickParts> bricks;
  for (std::size_t i = 0; i < coded.size(); ++i) {
    if (bricks.empty() || bricks.back().code != coded[i].code) bricks.push_back({coded[i].code, {&coded[i], 0}});
    bricks.back().runs = {bricks.back().runs.data(), bricks.back().runs.size() + 1};
  }

  // Bricks are encoded in parallel and handed to the sink in order as each is done, through a
  // ring of kept payload buffers: brick k goes to slot k % slots, free by then since a pipeline
  // of that many tokens starts brick k only when brick k - slots has left the sink.
  const std::size_t slots = 2 * std::size_t(tbb::this_task_arena::max_concurrency());
  std::vector<EncodedBrick> ring(slots);
  std::size_t next = 0;
  const auto eachBrick = [&](tbb::flow_control& control) {
    if (next == bricks.size()) control.stop();
    return next++;
  };
  const auto encode = [&](std::size_t k) {
    const BrickParts& parts = bricks[k];
    auto& [brick, scratch] = threadEncodeScratch();
    decodeRun(keys.data(), parts, grid, fields, attribute, brick, scratch);
    EncodedBrick& e = ring[k % slots];
    e.kindCells = {};
    for (ParticleKind kind : brick.kinds) ++e.kindCells[std::size_t(kind)];
    e.coord = glm::uvec3(mortonDecode3(std::uint32_t(parts.code)));
    e.particles = std::uint32_t(parts.keys());
    e.cells = std::uint32_t(brick.cells.size());
    encodeBrickInto(brick, zstdLevel, e.payload, attributeCodingOf(grid.header.version));
    return k;
  };
  const auto write = [&](std::size_t k) { sink(ring[k % slots]); };
  tbb::parallel_pipeline(slots, tbb::make_filter<void, std::size_t>(tbb::filter_mode::serial_in_order, eachBrick) &
                                    tbb::make_filter<std::size_t, std::size_t>(tbb::filter_mode::parallel, encode) &
                                    tbb::make_filter<std::size_t, void>(tbb::filter_mode::serial_in_order, write));
}

}  // namespace

void binKeys(KeyBatch& keyBatch, const KeyGrid& grid, float min, float max, int zstdLevel,
             const std::function<void(const EncodedBrick&)>& sink) {
  KeyFields fields;
  fields.kinds = grid.header.particleKinds;
  fields.min = min;
  fields.max = max;
  fields.cellBits = grid.cellBits;
  if (grid.valuesBesideKeys())  // the values must travel with the keys through the split
    makeBinningKeys(keyBatch, grid, min, max);
  else
    fields.layout = grid.attribute() ? KeyFields::Layout::Packed : KeyFields::Layout::Plain;
  // A narrow key is a Plain one whose upper half is 0 (KeyGrid::narrowKeys): the same fields.
  FLIPSCOPE_CHECK(!keyBatch.narrow || grid.narrowKeys(), "narrow keys for a grid whose keys need more than 32 bits");
  keyBatch.withKeys([&](auto& keys) { binKeysOf(std::span(keys), keyBatch, grid, fields, zstdLevel, sink); });
}

}  // namespace flipscope::detail
