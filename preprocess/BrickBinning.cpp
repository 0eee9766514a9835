// Binning of particle keys into encoded bricks (layout in BrickBinning.h).
// Sorting: an MSD counting sort on the brick Morton code in 16-bit digits (one parallel pass
// for the grids of practice, whose codes have at most 18 bits), then per brick either a cell
// histogram (dense bricks) or a comparison sort (sparse bricks).
#include "preprocess/BrickBinning.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "core/Error.h"
#include "core/FastFloor.h"
#include "core/Morton.h"

namespace flipscope::detail {

KeyGrid::KeyGrid(const StoreHeader& h, std::optional<Box> clipBox)
    : header(h),
      clip(clipBox),
      invCellSize(1.0 / h.cellSize),
      cells(glm::u64vec3(h.brickGrid) * std::uint64_t(h.brickSize)),
      brickShift(std::uint32_t(std::countr_zero(h.brickSize))),
      cellBits(3 * brickShift),
      codeBits(3 * octreeLevelsFor(std::max({h.brickGrid.x, h.brickGrid.y, h.brickGrid.z}))) {
  FLIPSCOPE_CHECK(cellBits + codeBits + 16 <= 64, "grid too large for 64-bit keys");
}

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

KeyTally computeKeys(const ParticleChunk& chunk, const KeyGrid& grid, AttributeKind kind, KeyBatch& out,
                     const AttributeColumn* types) {
  const std::size_t n = chunk.size();
  FLIPSCOPE_CHECK(!types || (types->arity == 1 && types->values.size() == n), "a type column needs one value a particle");
  const bool attribute = kind != AttributeKind::None;
  FLIPSCOPE_CHECK(kind != AttributeKind::Speed || chunk.velocities.size() == n, "speed needs velocities");
  FLIPSCOPE_CHECK(kind != AttributeKind::Scalar || (!chunk.attributes.empty() && chunk.attributes.front().arity == 1 &&
                                                    chunk.attributes.front().values.size() == n),
                  "a scalar attribute needs its column");
  FLIPSCOPE_CHECK(kind != AttributeKind::Magnitude ||
                      (!chunk.attributes.empty() &&
                       chunk.attributes.front().values.size() == n * std::size_t(chunk.attributes.front().arity)),
                  "a vector attribute needs its column");
  constexpr std::uint64_t kInvalid = ~0ull, kOutside = ~0ull - 1;
  const std::size_t base = out.cellKeys.size();
  out.cellKeys.resize(base + n);
  if (attribute) out.values.resize(base + n);
  std::uint64_t* keys = out.cellKeys.data() + base;
  float* values = attribute ? out.values.data() + base : nullptr;
  const std::uint32_t mask = grid.header.brickSize - 1;

  struct Tally {
    std::uint64_t invalid = 0, outside = 0;
    float valueMin = std::numeric_limits<float>::infinity(), valueMax = -std::numeric_limits<float>::infinity();
  };
  const Tally tally = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, 1 << 14), Tally{},
      [&](const auto& range, Tally t) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          const glm::vec3 p = chunk.positions[i];
          if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
            keys[i] = kInvalid;
            ++t.invalid;
            continue;
          }
          const glm::dvec3 q(p);
          const glm::dvec3 c = fastFloor((q - grid.header.origin) * grid.invCellSize);
          if ((grid.clip && !grid.clip->contains(q)) || c.x < 0 || c.y < 0 || c.z < 0 ||
              c.x >= double(grid.cells.x) || c.y >= double(grid.cells.y) || c.z >= double(grid.cells.z)) {
            keys[i] = kOutside;
            ++t.outside;
            continue;
          }
          const glm::uvec3 cell(c);
          const glm::uvec3 brick = cell >> grid.brickShift;
          const glm::uvec3 local = cell & mask;
          const std::uint64_t code = mortonEncode3(brick.x, brick.y, brick.z);
          const std::uint64_t inBrick = local.x | (local.y << grid.brickShift) | (local.z << (2 * grid.brickShift));
          keys[i] = (code << grid.cellBits) | inBrick;
          if (types) keys[i] |= std::uint64_t(kindOfTypeValue(types->values[i])) << kKindShift;
          if (values) {
            const float s = attributeValue(chunk, kind, i);
            values[i] = s;
            if (std::isfinite(s)) {
              t.valueMin = std::min(t.valueMin, s);
              t.valueMax = std::max(t.valueMax, s);
            }
          }
        }
        return t;
      },
      [](Tally a, const Tally& b) {
        a.invalid += b.invalid;
        a.outside += b.outside;
        a.valueMin = std::min(a.valueMin, b.valueMin);
        a.valueMax = std::max(a.valueMax, b.valueMax);
        return a;
      });

  const std::size_t skipped = tally.invalid + tally.outside;
  KeyTally result{n - skipped, tally.invalid, tally.outside};
  if (attribute && tally.valueMin <= tally.valueMax) {
    result.ranged = true;
    result.valueMin = tally.valueMin;
    result.valueMax = tally.valueMax;
  }
  if (skipped == 0) return result;
  // Rare: compact in order (keeps the stream deterministic).
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (keys[i] == kInvalid || keys[i] == kOutside) continue;
    keys[kept] = keys[i];
    if (values) values[kept] = values[i];
    ++kept;
  }
  out.cellKeys.resize(base + kept);
  if (attribute) out.values.resize(base + kept);
  return result;
}

std::uint16_t quantizeAttribute(float s, float min, float max) {
  if (!(max > min) || std::isnan(s)) return 0;
  const float t = (s - min) / (max - min);
  if (!(t > 0.0f)) return 0;
  if (!(t < 1.0f)) return 65535;
  return std::uint16_t(std::lround(t * 65535.0f));
}

namespace {

constexpr std::uint32_t kDigitBits = 16;
constexpr std::size_t kParallelThreshold = 1 << 16;

/// Stable counting sort of keys[begin,end) by the digit (key >> shift) & (2^bits - 1) into
/// out[begin,end); returns the start offset of each digit value (size 2^bits + 1).
std::vector<std::size_t> countingSort(const std::uint64_t* in, std::uint64_t* out, std::size_t n, std::uint32_t shift,
                                      std::uint32_t bits) {
  const std::size_t buckets = std::size_t(1) << bits;
  const std::uint64_t mask = buckets - 1;
  const std::size_t blocks = n >= kParallelThreshold ? 8 : 1;
  const std::size_t blockSize = (n + blocks - 1) / blocks;
  std::vector<std::vector<std::size_t>> histograms(blocks, std::vector<std::size_t>(buckets, 0));
  tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t b) {
    auto& h = histograms[b];
    const std::size_t e = std::min(n, (b + 1) * blockSize);
    for (std::size_t i = b * blockSize; i < e; ++i) ++h[(in[i] >> shift) & mask];
  });
  std::vector<std::size_t> starts(buckets + 1, 0);
  std::size_t offset = 0;
  for (std::size_t d = 0; d < buckets; ++d) {
    starts[d] = offset;
    for (std::size_t b = 0; b < blocks; ++b) {
      const std::size_t count = histograms[b][d];
      histograms[b][d] = offset;
      offset += count;
    }
  }
  starts[buckets] = offset;
  tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t b) {
    auto& h = histograms[b];
    const std::size_t e = std::min(n, (b + 1) * blockSize);
    for (std::size_t i = b * blockSize; i < e; ++i) out[h[(in[i] >> shift) & mask]++] = in[i];
  });
  return starts;
}

struct BrickRun {
  std::size_t begin, end;  // in the array that holds the run after sorting
  bool inScratch;
};

/// MSD counting sort by brick code; appends one run per brick in ascending code order.
void splitByBrick(std::uint64_t* keys, std::uint64_t* scratch, std::size_t begin, std::size_t end,
                  std::uint32_t lowBit, std::uint32_t highBit, bool inScratch, std::vector<BrickRun>& runs) {
  if (begin == end) return;
  if (highBit <= lowBit) {
    runs.push_back({begin, end, inScratch});
    return;
  }
  const std::uint64_t* src = (inScratch ? scratch : keys) + begin;
  std::uint64_t* dst = (inScratch ? keys : scratch) + begin;
  const std::uint32_t bits = std::min(kDigitBits, highBit - lowBit);
  const std::uint32_t shift = highBit - bits;
  // Fast path: every key has the same digit.
  const std::uint64_t first = (src[0] >> shift) & ((1ull << bits) - 1);
  bool uniform = true;
  for (std::size_t i = 1; i < end - begin && uniform; ++i) uniform = ((src[i] >> shift) & ((1ull << bits) - 1)) == first;
  if (uniform) return splitByBrick(keys, scratch, begin, end, lowBit, shift, inScratch, runs);
  auto starts = countingSort(src, dst, end - begin, shift, bits);
  for (std::size_t d = 0; d + 1 < starts.size(); ++d)
    if (starts[d] != starts[d + 1])
      splitByBrick(keys, scratch, begin + starts[d], begin + starts[d + 1], lowBit, shift, !inScratch, runs);
}

/// Encodes one brick's keys (same brick code, any order) into `out` (reuses its vectors); with
/// `kinds`, a cell's kind is the smallest of its keys' (the key layout of binningKey).
void decodeRun(std::span<std::uint64_t> keys, const KeyGrid& grid, bool attribute, bool kinds, DecodedBrick& out,
               std::vector<std::uint32_t>& histogram, std::vector<ParticleKind>& cellKinds) {
  out.cells.clear();
  out.counts.clear();
  out.attributes.clear();
  out.kinds.clear();
  const std::uint32_t cellsPerBrick = grid.header.cellsPerBrick();
  const std::uint64_t cellMask = (1ull << grid.cellBits) - 1;
  auto cellOf = [&](std::uint64_t key) { return std::uint32_t((key >> 16) & cellMask); };
  auto kindOf = [](std::uint64_t key) { return ParticleKind(key & 3); };
  auto attributeOf = [kinds](std::uint64_t key) {
    if (!kinds) return std::uint16_t(key & 0xffff);
    const auto narrow = std::uint32_t((key >> 2) & 0x3fff);
    return std::uint16_t((narrow << 2) | (narrow >> 12));  // 14 bits widened: 0 -> 0, 16383 -> 65535
  };
  if (keys.size() * 16 < cellsPerBrick) {
    // Sparse: sort (cell, attribute) directly.
    std::sort(keys.begin(), keys.end());
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
  for (auto k : keys) ++histogram[cellOf(k)];
  if (kinds) {
    cellKinds.assign(cellsPerBrick, ParticleKind(kParticleKindCount - 1));
    for (auto k : keys) cellKinds[cellOf(k)] = std::min(cellKinds[cellOf(k)], kindOf(k));
  }
  std::uint32_t offset = 0;
  for (std::uint32_t c = 0; c < cellsPerBrick; ++c) {
    if (!histogram[c]) continue;
    out.cells.push_back(c);
    out.counts.push_back(histogram[c]);
    if (kinds) out.kinds.push_back(cellKinds[c]);
    const std::uint32_t count = histogram[c];
    histogram[c] = offset;  // becomes the cell's first attribute slot
    offset += count;
  }
  if (!attribute) return;
  out.attributes.resize(keys.size());
  for (auto k : keys) out.attributes[histogram[cellOf(k)]++] = attributeOf(k);
  std::size_t start = 0;
  for (auto count : out.counts) {
    std::sort(out.attributes.begin() + start, out.attributes.begin() + start + count);
    start += count;
  }
}

}  // namespace

void binKeys(KeyVector& keys, KeyVector& scratch, const KeyGrid& grid, bool attribute, bool kinds,
             int zstdLevel, const std::function<void(EncodedBrick&&)>& sink) {
  if (keys.empty()) return;
  scratch.resize(keys.size());
  std::vector<BrickRun> runs;
  const std::uint32_t lowBit = 16 + grid.cellBits;
  splitByBrick(keys.data(), scratch.data(), 0, keys.size(), lowBit, lowBit + grid.codeBits, false, runs);

  constexpr std::size_t kBatch = 64;
  std::vector<EncodedBrick> batch;
  for (std::size_t first = 0; first < runs.size(); first += kBatch) {
    const std::size_t count = std::min(kBatch, runs.size() - first);
    batch.assign(count, {});
    tbb::parallel_for(std::size_t(0), count, [&](std::size_t i) {
      const BrickRun& run = runs[first + i];
      std::span<std::uint64_t> span((run.inScratch ? scratch : keys).data() + run.begin, run.end - run.begin);
      thread_local DecodedBrick brick;
      thread_local std::vector<std::uint32_t> histogram;
      thread_local std::vector<ParticleKind> cellKinds;
      decodeRun(span, grid, attribute, kinds, brick, histogram, cellKinds);
      EncodedBrick& e = batch[i];
      for (ParticleKind kind : brick.kinds) ++e.kindCells[std::size_t(kind)];
      e.coord = glm::uvec3(mortonDecode3(std::uint32_t(span[0] >> lowBit)));
      e.particles = std::uint32_t(span.size());
      e.cells = std::uint32_t(brick.cells.size());
      e.payload = encodeBrick(brick, zstdLevel);
    });
    for (auto& e : batch) sink(std::move(e));
  }
}

}  // namespace flipscope::detail
