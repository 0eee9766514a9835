// ParticleSpacing: the metadata and neighbour estimates of the particle spacing (see the header).
#include "preprocess/ParticleSpacing.h"

#include "preprocess/particles/PointSpanSource.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <mutex>
#include <numbers>
#include <optional>
#include <random>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include "core/NumberText.h"
#include "preprocess/FiniteBounds.h"
#include "preprocess/PositionRanges.h"

namespace flipscope {
namespace {

constexpr std::size_t kChunkParticles = 1 << 16;
constexpr std::size_t kNeighbours = kSpacingNeighbour;
/// The cells of KthNeighbours: the radius, at most this many (4 MiB of bits; coarser cells
/// beyond).
constexpr double kMaxSearchCells = double(std::size_t(1) << 25);
/// ... and at most this many along an axis (a bound on the rounding of cellsOf).
constexpr double kMaxAxisCells = 4096;

/// How far beyond `radius` a candidate may lie whose float squared distance is rounded down to
/// float(radius^2) where the squares are subnormal (coordinates below about 1e-19): a few of
/// their quantum, denorm_min, over twice the radius. The searches' cells reach this much further.
double subnormalMargin(double radius) { return 4 * double(std::numeric_limits<float>::denorm_min()) / radius; }

/// Spacing per k-th neighbour distance r: at spacing r * ballFactor(), a ball of radius r holds k particles.
double ballFactor() { return std::cbrt(4 * std::numbers::pi / (3 * double(kSpacingNeighbour))); }

bool isFinite(const glm::vec3& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

/// The query particles: a uniform random sample of the source's finite particles.
struct Sample {
  std::vector<glm::vec3> positions;
  std::vector<std::uint64_t> ids;  ///< index of each sampled particle in the source's order
  std::uint64_t finite = 0;        ///< finite particles in the whole source (once `counted`)
  Box bounds;                      ///< of the finite particles of the whole source (once `counted`)
  bool counted = false;            ///< the sample was drawn reading the whole source: finite and bounds are known
  bool complete() const { return counted && finite == positions.size(); }
};

/// Li's algorithm L: which items of a stream numbered 0, 1, 2, ... enter a uniform random
/// sample of `size` items, and the slot each takes. After the first `size`, a random skip leads
/// to the next item that enters, so random numbers are drawn only for those, about
/// size * ln(items / size) of them. A fixed seed: the same items for the same stream length.
class ReservoirSkips {
 public:
  explicit ReservoirSkips(std::size_t size) : mSize(size), mW(std::exp(std::log(open()) / double(size))) {}
  /// The item that enters the sample next.
  std::uint64_t next() const { return mNext; }
  /// Item next() enters the sample: the slot it takes (0, 1, ... while the sample fills).
  std::size_t enter() {
    if (mNext < mSize) {
      const std::size_t slot = std::size_t(mNext);
      mNext += mNext + 1 == mSize ? skip() : 1;
      return slot;
    }
    const std::size_t slot = std::uniform_int_distribution<std::size_t>(0, mSize - 1)(mRng);
    mW *= std::exp(std::log(open()) / double(mSize));
    mNext += skip();
    return slot;
  }

 private:
  double open() { return 1.0 - mUniform(mRng); }  // in (0, 1]: its log is finite
  std::uint64_t skip() {
    const double gap = std::floor(std::log(open()) / std::log1p(-mW));
    return gap < 0x1p62 ? std::uint64_t(gap) + 1 : std::uint64_t(1) << 62;  // (w so small: never)
  }

  std::mt19937_64 mRng{0x5041434eull};
  std::uniform_real_distribution<double> mUniform{0.0, 1.0};
  std::size_t mSize;
  double mW;
  std::uint64_t mNext = 0;
};

/// Reservoir sampling of the finite particles, one read of the source, then a rewind. The
/// count and the bounds of the finite particles are gathered on the way, in parallel over each
/// chunk.
Sample reservoirSample(ParticleSource& source, std::size_t size, Progress* progress) {
  Sample s;
  s.counted = true;
  ReservoirSkips reservoir(size);
  ParticleChunk chunk;
  std::uint64_t id = 0;
  while (source.read(chunk, kChunkParticles)) {
    const std::vector<glm::vec3>& p = chunk.positions;
    const FiniteBounds tally = finiteBounds(p);
    // The chunk's finite particles are s.finite .. end - 1; visit those that enter the sample.
    const std::uint64_t end = s.finite + tally.finite;
    std::uint64_t counted = s.finite;  // finite particles before p[i]
    for (std::size_t i = 0; i < p.size() && counted < end; ++i) {
      if (!isFinite(p[i])) continue;
      if (counted == reservoir.next()) {
        const std::size_t slot = reservoir.enter();
        if (slot == s.positions.size()) {
          s.positions.push_back(p[i]);
          s.ids.push_back(id + i);
        } else {
          s.positions[slot] = p[i];
          s.ids[slot] = id + i;
        }
      } else if (p.size() - i == end - counted) {  // all finite from here: jump to the next one in
        if (reservoir.next() >= end) break;        // (none of them enters the sample)
        i += std::size_t(reservoir.next() - counted) - 1;
        counted = reservoir.next() - 1;
      }
      ++counted;
    }
    s.finite = end;
    s.bounds.extend(tally.bounds);
    id += p.size();
    if (progress) progress->advance(chunk.size());
  }
  source.rewind();
  return s;
}

/// The same sampling without reading the source whole, where it has more than `size` particles
/// and seeks to one cheaply (ParticleSource::readPositionsAt): a sample of `size` of all its
/// particles, by number, less the non-finite ones among them; not `counted`. Else nullopt.
std::optional<Sample> sampleByNumber(ParticleSource& source, std::size_t size) {
  const std::optional<std::uint64_t> count = source.countHint();
  if (!count || *count <= size) return std::nullopt;
  std::vector<std::uint64_t> ids;
  ids.reserve(size);
  for (ReservoirSkips reservoir(size); reservoir.next() < *count;) {
    const std::uint64_t item = reservoir.next();
    const std::size_t slot = reservoir.enter();
    if (slot == ids.size())
      ids.push_back(item);
    else
      ids[slot] = item;
  }
  std::sort(ids.begin(), ids.end());
  Sample s;
  if (!source.readPositionsAt(ids, s.positions)) return std::nullopt;
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (isFinite(s.positions[i])) {
      s.positions[s.ids.size()] = s.positions[i];
      s.ids.push_back(ids[i]);
    }
  s.positions.resize(s.ids.size());
  return s;
}

/// The key of cell (x, y, z) of a sparse grid, 21 bits an axis (x fastest).
std::uint64_t cellKey(std::uint64_t x, std::uint64_t y, std::uint64_t z) { return (z << 42) | (y << 21) | x; }

/// (cell, item) pairs sorted by cell, as runs: each occupied cell's key and first pair; with
/// `hashed`, an open-addressing table (at most half full) from a cell to its run, for grids of
/// more cells than a table of every one could hold. The searches' sparse cells
/// (KthNeighbours::buildFineLists, kthAmongPoints).
class CellRuns {
 public:
  CellRuns() = default;
  CellRuns(std::span<const std::pair<std::uint64_t, std::uint32_t>> sorted, bool hashed) {
    for (std::size_t i = 0; i < sorted.size(); ++i)
      if (i == 0 || sorted[i].first != sorted[i - 1].first) {
        mCells.push_back(sorted[i].first);
        mStarts.push_back(std::uint32_t(i));
      }
    mStarts.push_back(std::uint32_t(sorted.size()));
    if (!hashed) return;
    const std::size_t slots = std::bit_ceil(std::max<std::size_t>(2, 2 * mCells.size()));
    mShift = 64 - std::countr_zero(slots);
    mTable.assign(slots, 0);
    for (std::size_t run = 0; run < mCells.size(); ++run) {
      std::size_t s = slotOf(mCells[run]);
      while (mTable[s]) s = (s + 1) & (slots - 1);
      mTable[s] = std::uint32_t(run + 1);
    }
  }

  std::size_t size() const { return mCells.size(); }
  std::uint64_t cell(std::size_t run) const { return mCells[run]; }
  /// The pairs [first, end) of a run.
  std::uint32_t first(std::size_t run) const { return mStarts[run]; }
  std::uint32_t end(std::size_t run) const { return mStarts[run + 1]; }
  /// The run of `cell`, or -1 where it holds none (a hashed CellRuns only).
  std::int64_t find(std::uint64_t cell) const {
    for (std::size_t s = slotOf(cell); mTable[s]; s = (s + 1) & (mTable.size() - 1))
      if (mCells[mTable[s] - 1] == cell) return std::int64_t(mTable[s] - 1);
    return -1;
  }

 private:
  std::size_t slotOf(std::uint64_t cell) const { return std::size_t((cell * 0x9e3779b97f4a7c15ull) >> mShift); }

  std::vector<std::uint64_t> mCells;
  std::vector<std::uint32_t> mStarts;  ///< each run's first pair, then the number of pairs
  std::vector<std::uint32_t> mTable;   ///< a run + 1, or 0
  int mShift = 64;
};

/// The k-th neighbour distance of every query among the candidates given to add(), searched as
/// far as `radius`: a query whose k-th neighbour is farther keeps +inf. A grid of cells of the
/// radius (coarser where that would exceed kMaxSearchCells, or kMaxAxisCells along an axis)
/// covers the queries' bounds grown by the radius, and each cell lists the queries within reach
/// of some point of it. A candidate looks up its own cell only (found in floats, four at a
/// time): a bit turns it away when the list is empty (most candidates lie far from every query),
/// else it measures its distance to each listed query. The reach is the radius plus a margin for
/// the rounding of a candidate's cell, so the lists are a superset and the search is exact. Where
/// the bits' cells came out coarser than kFineCellRatio radii (queries far apart), their lists
/// would hold many queries out of reach of most candidates; the lists are then of cells of the
/// radius, of those near a query only, found through a hash table (buildFineLists), and the bits
/// only turn candidates away. A candidate with the id of a query is that query itself and skipped.
class KthNeighbours {
 public:
  /// Cells of the radius, not of half of it, for the frame's pass too: there, fewer candidates
  /// would pass the bits of finer cells, but the lists, eight times as many cells, took longer
  /// to build than that saved (20 M particle frames, and 100 M, 2026-12-05).
  KthNeighbours(const Sample& queries, double radius)
      : mQueries(queries), mRadius(radius), mCell(radius), mHeaps(queries.positions.size() * kNeighbours, kInf) {
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
    for (const glm::vec3& q : queries.positions) {
      lo = glm::min(lo, glm::dvec3(q));
      hi = glm::max(hi, glm::dvec3(q));
    }
    for (int a = 0; a < 3; ++a) {
      mLo[a] = roundedToFloat(lo[a] - radius, -1);
      mHi[a] = roundedToFloat(hi[a] + radius, +1);
    }
    const glm::dvec3 extent = mHi - mLo;
    mUsable = !queries.positions.empty() && radius > 0 && std::isfinite(extent.x + extent.y + extent.z);
    if (mUsable) buildCellLists();
  }

  /// Candidates with consecutive ids from `firstId` (the source's order).
  void add(std::span<const glm::vec3> candidates, std::uint64_t firstId) {
    addAll(candidates, [&](std::size_t i) { return firstId + i; });
  }

  /// add(), for candidates read on several threads at once: a thread's hits are merged into the
  /// heaps, under a lock, once they are many; flush() merges the rest after the last add.
  void addConcurrently(std::span<const glm::vec3> candidates, std::uint64_t firstId) {
    if (!mUsable) return;
    std::vector<Hit>& hits = mHits.local();
    collect(
        candidates, [&](std::size_t i) { return firstId + i; }, hits);
    if (hits.size() >= kMergeHits) {
      const std::lock_guard lock(mMerging);
      merge(hits);
    }
  }
  void flush() {
    for (std::vector<Hit>& hits : mHits) merge(hits);
  }

  /// Each query's k-th neighbour distance, +inf where it lies beyond the radius.
  std::vector<double> distances() const {
    const std::size_t n = mQueries.positions.size();
    std::vector<double> kth(n, std::numeric_limits<double>::infinity());
    if (!mUsable) return kth;
    const double radius2 = mRadius * mRadius;
    for (std::size_t j = 0; j < n; ++j) {
      const double d2 = mHeaps[j * kNeighbours];  // the heap's maximum: the k-th smallest
      if (d2 <= radius2) kth[j] = std::sqrt(d2);
    }
    return kth;
  }

  /// The median k-th neighbour distance: exact when more than half the queries found theirs
  /// within the radius (the others' lie farther), else +inf.
  double median() const {
    const std::size_t n = mQueries.positions.size();
    if (!mUsable || n == 0) return std::numeric_limits<double>::infinity();
    std::vector<double> kth = distances();
    auto mid = kth.begin() + std::ptrdiff_t(n / 2);
    std::nth_element(kth.begin(), mid, kth.end());
    return *mid;
  }

 private:
  static constexpr float kInf = std::numeric_limits<float>::infinity();
  /// Candidates whose cells are found at a time (cellsOf).
  static constexpr std::size_t kBlock = 256;
  /// The margins of the reach (buildCellLists).
  static constexpr double kSlack = 1e-6, kCellSlack = 0x1p-9;
  /// Cells of the bits coarser than this many radii get lists of cells of the radius (buildFineLists).
  static constexpr double kFineCellRatio = 2;

  /// v as a float (exactly), rounded down (`direction` -1) or up (+1).
  static double roundedToFloat(double v, int direction) {
    float f = float(v);
    if (direction < 0 ? double(f) > v : double(f) < v) f = std::nextafter(f, direction < 0 ? -kInf : kInf);
    return f;
  }

  /// Cells of the radius (or coarser) over [lo, lo + cell * dims).
  struct CellGrid {
    glm::dvec3 lo{0};
    double cell = 0, inverse = 0;
    glm::ivec3 dims{0};
  };

  /// Calls visit(x, y, z) for each cell of `grid` within reach of `query`: whose box holds a point
  /// at most `reach` from it.
  template <class Visit>
  void forEachCellNear(const CellGrid& grid, const glm::vec3& query, double reach, Visit visit) {
    const glm::dvec3 q(query);
    glm::ivec3 first, last;
    for (int a = 0; a < 3; ++a) {
      first[a] = std::max(0, int(std::floor((q[a] - reach - grid.lo[a]) * grid.inverse)));
      last[a] = std::min(grid.dims[a] - 1, int(std::floor((q[a] + reach - grid.lo[a]) * grid.inverse)));
      mAxisDistance2[a].clear();
      for (int i = first[a]; i <= last[a]; ++i) {
        const double lo = grid.lo[a] + i * grid.cell, hi = lo + grid.cell;
        const double d = std::max({lo - q[a], 0.0, q[a] - hi});
        mAxisDistance2[a].push_back(d * d);
      }
    }
    const double reach2 = reach * reach;
    for (int z = first.z; z <= last.z; ++z)
      for (int y = first.y; y <= last.y; ++y) {
        const double yz = mAxisDistance2[2][std::size_t(z - first.z)] + mAxisDistance2[1][std::size_t(y - first.y)];
        if (yz > reach2) continue;
        for (int x = first.x; x <= last.x; ++x)
          if (yz + mAxisDistance2[0][std::size_t(x - first.x)] <= reach2) visit(x, y, z);
      }
  }

  /// The list of queries of a cell with its bit set: its rank among the set bits.
  std::size_t listOf(std::size_t bit, std::uint64_t word) const {
    return mWordRank[bit / 64] + std::size_t(std::popcount(word & ((std::uint64_t(1) << (bit % 64)) - 1)));
  }

  void buildCellLists() {
    const glm::dvec3 extent = mHi - mLo;
    const auto cellsFor = [&](double c) { return glm::floor(extent / c) + 1.0; };
    glm::dvec3 dims = cellsFor(mCell);
    while (!(dims.x * dims.y * dims.z <= kMaxSearchCells)) {
      mCell *= std::max(1.01, std::cbrt(dims.x * dims.y * dims.z / kMaxSearchCells) * 1.01);
      dims = cellsFor(mCell);
    }
    const double longest = std::max({dims.x, dims.y, dims.z});
    if (longest > kMaxAxisCells) {
      mCell *= longest / kMaxAxisCells * 1.01;
      dims = cellsFor(mCell);
    }
    mInverseCell = 1 / mCell;
    mDims = glm::ivec3(dims);
    const std::size_t words = (std::size_t(dims.x * dims.y * dims.z) + 63) / 64;
    // The margins of the reach: kCellSlack, as a candidate's cell, found in floats (cellsOf), may
    // be one whose box it misses by three float roundings of its coordinate in cells (at most
    // kMaxAxisCells): 3 * 2^-24 * 4096 = 0.0007 cells; kSlack, the double rounding of the
    // distances from a query to the cells' boxes (forEachCellNear).
    const double reach = mRadius * (1 + kSlack) + mCell * kCellSlack + subnormalMargin(mRadius);
    // Queries in the order of their cells, so that the cells each visits next lie in memory near
    // those of the one before: each pass below walks the bits and lists about in order.
    const std::size_t n = mQueries.positions.size();
    std::vector<std::pair<std::size_t, std::uint32_t>> order(n);
    for (std::size_t j = 0; j < n; ++j) order[j] = {cellIndex(glm::dvec3(mQueries.positions[j])), std::uint32_t(j)};
    std::sort(order.begin(), order.end());
    // Three walks over the (cell, query) pairs, each visited afresh (cheaper than keeping them,
    // millions of pairs of fresh memory): the bits; each list's length; the lists, filled from
    // their ends (the order within a list is of no account). In between, the rank of each word's
    // first bit and the lists' ends.
    const CellGrid grid{mLo, mCell, mInverseCell, mDims};
    const auto forEachPair = [&](auto visit) {
      for (const auto& entry : order) {
        const std::uint32_t j = entry.second;
        forEachCellNear(grid, mQueries.positions[j], reach, [&](int x, int y, int z) {
          visit((std::size_t(z) * std::size_t(mDims.y) + std::size_t(y)) * std::size_t(mDims.x) + std::size_t(x), j);
        });
      }
    };
    mBits.assign(words, 0);
    forEachPair([&](std::size_t bit, std::uint32_t) { mBits[bit / 64] |= std::uint64_t(1) << (bit % 64); });
    if (mCell > kFineCellRatio * mRadius) {
      buildFineLists(order);
      return;
    }
    mWordRank.resize(words + 1);
    mWordRank[0] = 0;
    for (std::size_t w = 0; w < words; ++w) mWordRank[w + 1] = mWordRank[w] + std::uint32_t(std::popcount(mBits[w]));
    const std::size_t lists = mWordRank[words];
    mListStart.assign(lists + 1, 0);
    forEachPair([&](std::size_t bit, std::uint32_t) { ++mListStart[listOf(bit, mBits[bit / 64])]; });
    for (std::size_t i = 1; i < lists; ++i) mListStart[i] += mListStart[i - 1];  // each list's end
    mListStart[lists] = lists ? mListStart[lists - 1] : 0;
    mListed.resize(mListStart[lists]);
    forEachPair([&](std::size_t bit, std::uint32_t j) { mListed[--mListStart[listOf(bit, mBits[bit / 64])]] = j; });
  }

  /// The lists where the cells of the bits are coarser than kFineCellRatio radii (queries far
  /// apart: two tanks, a particle flung far away, or a box too large for kMaxSearchCells cells of
  /// the radius), whose lists would hold many queries beyond the reach of most of their
  /// candidates: lists of cells of the radius again, of the occupied cells only, found by a hash
  /// table of their keys (fineListOf). The bits still turn away the candidates far from every
  /// query.
  void buildFineLists(std::span<const std::pair<std::size_t, std::uint32_t>> order) {
    const glm::dvec3 extent = mHi - mLo;
    constexpr double kAxisCells = double((1 << 21) - 2);  // a key holds 21 bits an axis
    mFine.lo = mLo;
    mFine.cell = std::max(mRadius, std::max({extent.x, extent.y, extent.z}) / kAxisCells);
    mFine.inverse = 1 / mFine.cell;
    mFine.dims = glm::ivec3(glm::floor(extent * mFine.inverse) + 1.0);
    // The reach's margins as in buildCellLists; the candidates' fine cells are found in doubles.
    const double reach = mRadius * (1 + kSlack) + mFine.cell * kCellSlack + subnormalMargin(mRadius);
    std::vector<std::pair<std::uint64_t, std::uint32_t>> pairs;  // (fine cell, query)
    for (const auto& entry : order)
      forEachCellNear(mFine, mQueries.positions[entry.second], reach, [&](int x, int y, int z) {
        pairs.push_back({cellKey(std::uint64_t(x), std::uint64_t(y), std::uint64_t(z)), entry.second});
      });
    std::sort(pairs.begin(), pairs.end());
    mFineLists = CellRuns(pairs, true);
    mListed.resize(pairs.size());
    for (std::size_t i = 0; i < pairs.size(); ++i) mListed[i] = pairs[i].second;
  }

  /// The fine list of candidate p (inside [mLo, mHi]), or -1 where no query is near its cell.
  std::int64_t fineListOf(const glm::vec3& p) const {
    const glm::u64vec3 c(
        glm::clamp(glm::ivec3(glm::floor((glm::dvec3(p) - mFine.lo) * mFine.inverse)), glm::ivec3(0), mFine.dims - 1));
    return mFineLists.find(cellKey(c.x, c.y, c.z));
  }

  /// The bit of the cell of p, a point inside [mLo, mHi].
  std::size_t cellIndex(const glm::dvec3& p) const {
    const glm::ivec3 c = glm::min(glm::ivec3((p - mLo) * mInverseCell), mDims - 1);  // >= 0: p is inside
    return (std::size_t(c.z) * std::size_t(mDims.y) + std::size_t(c.y)) * std::size_t(mDims.x) + std::size_t(c.x);
  }

  /// A query's candidate within the radius.
  struct Hit {
    std::uint32_t query;
    float distance2;
  };

  /// Finds the hits of the candidates in parallel, then merges them into the heaps. `idOf(i)`:
  /// candidate i's id.
  template <class IdOf>
  void addAll(std::span<const glm::vec3> candidates, IdOf idOf) {
    if (!mUsable) return;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, candidates.size(), 4096), [&](const auto& range) {
      collect(
          candidates.subspan(range.begin(), range.size()), [&](std::size_t i) { return idOf(range.begin() + i); },
          mHits.local());
    });
    for (std::vector<Hit>& hits : mHits) merge(hits);
  }

  /// A thread's hits that addConcurrently merges at once (512 KiB).
  static constexpr std::size_t kMergeHits = std::size_t(1) << 16;

  /// Appends the candidates' hits to `hits`. Thread safe.
  template <class IdOf>
  void collect(std::span<const glm::vec3> candidates, IdOf idOf, std::vector<Hit>& hits) const {
    std::array<std::int32_t, kBlock> cells;
    for (std::size_t first = 0; first < candidates.size(); first += kBlock) {
      const std::size_t count = std::min(kBlock, candidates.size() - first);
      cellsOf(&candidates[first], count, cells.data());
      for (std::size_t k = 0; k < count; ++k) {
        if (cells[k] < 0) continue;
        const std::size_t bit = std::size_t(cells[k]);
        const std::uint64_t word = mBits[bit / 64];
        if (!(word >> (bit % 64) & 1)) continue;
        if (mFineLists.size() == 0) {
          const std::size_t list = listOf(bit, word);
          measure(candidates[first + k], idOf(first + k), mListStart[list], mListStart[list + 1], hits);
        } else if (const std::int64_t list = fineListOf(candidates[first + k]); list >= 0) {
          measure(candidates[first + k], idOf(first + k), mFineLists.first(std::size_t(list)),
                  mFineLists.end(std::size_t(list)), hits);
        }
      }
    }
  }

  /// Keeps each query's k nearest among `hits` (in any order: the k smallest distances are the
  /// same), and empties it.
  void merge(std::vector<Hit>& hits) {
    for (const Hit& hit : hits) {
      float* heap = &mHeaps[std::size_t(hit.query) * kNeighbours];
      if (!(hit.distance2 < heap[0])) continue;
      std::pop_heap(heap, heap + kNeighbours);
      heap[kNeighbours - 1] = hit.distance2;
      std::push_heap(heap, heap + kNeighbours);
    }
    hits.clear();
  }

  /// The cell (its bit) of each of `n` <= kBlock candidates, -1 for one outside [mLo, mHi] (NaN
  /// and Inf among them). In floats, four candidates at a time: mLo and mHi are floats, and the
  /// reach's margin covers the rounding (buildCellLists). `cells` has room for n rounded up to 4.
  void cellsOf(const glm::vec3* p, std::size_t n, std::int32_t* cells) const {
    using Lanes = float __attribute__((vector_size(16)));
    using Ints = std::int32_t __attribute__((vector_size(16)));
    alignas(16) float x[kBlock], y[kBlock], z[kBlock];
    for (std::size_t k = 0; k < n; ++k) x[k] = p[k].x, y[k] = p[k].y, z[k] = p[k].z;
    for (std::size_t k = n; k % 4; ++k) x[k] = y[k] = z[k] = std::numeric_limits<float>::quiet_NaN();  // outside
    const glm::vec3 lo(mLo), hi(mHi);
    const float inverse = float(mInverseCell);
    const glm::ivec3 last = mDims - 1;
    // The cell along an axis: 0 outside (NaN and the out of range do not convert to int).
    const auto axisCell = [&](const Lanes& v, float low, std::int32_t lastCell, const Ints& inside) {
      const Ints c = __builtin_convertvector((Lanes)((Ints)((v - low) * inverse) & inside), Ints);
      const Ints beyond = c > lastCell;
      return (c & ~beyond) | (lastCell & beyond);
    };
    for (std::size_t k = 0; k < n; k += 4) {
      Lanes vx, vy, vz;
      std::memcpy(&vx, x + k, sizeof vx);
      std::memcpy(&vy, y + k, sizeof vy);
      std::memcpy(&vz, z + k, sizeof vz);
      const Ints inside = (vx >= lo.x) & (vx <= hi.x) & (vy >= lo.y) & (vy <= hi.y) & (vz >= lo.z) & (vz <= hi.z);
      const Ints cell = (axisCell(vz, lo.z, last.z, inside) * mDims.y + axisCell(vy, lo.y, last.y, inside)) * mDims.x +
                        axisCell(vx, lo.x, last.x, inside);
      const Ints result = cell | ~inside;  // -1 outside
      std::memcpy(cells + k, &result, sizeof result);
    }
  }

  /// Measures a candidate whose cell has a list against the list's queries.
  void measure(const glm::vec3& candidate, std::uint64_t id, std::uint32_t first, std::uint32_t end,
               std::vector<Hit>& hits) const {
    const float radius2 = float(mRadius * mRadius);
    for (std::uint32_t i = first; i < end; ++i) {
      const std::uint32_t j = mListed[i];
      if (mQueries.ids[j] == id) continue;
      const glm::vec3 d = mQueries.positions[j] - candidate;
      const float d2 = d.x * d.x + d.y * d.y + d.z * d.z;
      if (d2 <= radius2) hits.push_back({j, d2});
    }
  }

  const Sample& mQueries;
  double mRadius;
  glm::dvec3 mLo{0}, mHi{0};  ///< the queries' bounds grown by the radius, rounded out to floats
  bool mUsable = false;
  double mCell = 0, mInverseCell = 0;
  glm::ivec3 mDims{0};                    ///< of the cells over [mLo, mHi]
  std::vector<std::uint64_t> mBits;       ///< a bit per cell (x fastest): its list is not empty
  std::vector<std::uint32_t> mWordRank;   ///< per word of mBits, the set bits before it
  std::vector<std::uint32_t> mListStart;  ///< per set bit, its list's first entry in mListed; then the end
  CellGrid mFine;                         ///< buildFineLists' cells, where it ran
  CellRuns mFineLists;                    ///< the fine lists' entries in mListed; empty: the bits' lists
  std::vector<std::uint32_t> mListed;     ///< the queries of each list
  std::vector<double> mAxisDistance2[3];  ///< forEachCellNear's scratch
  std::vector<float> mHeaps;  ///< k squared distances per query, a max-heap each
  tbb::enumerable_thread_specific<std::vector<Hit>> mHits;
  std::mutex mMerging;  ///< addConcurrently's merges
};

/// The count and the bounds of finite particles.
struct FiniteTally {
  std::uint64_t finite = 0;
  Box bounds;
  void add(std::span<const glm::vec3> positions) {
    const FiniteBounds t = finiteBounds(positions);
    finite += t.finite;
    bounds.extend(t.bounds);
  }
  void add(const FiniteTally& other) {
    finite += other.finite;
    bounds.extend(other.bounds);
  }
};

/// One read of every particle of `source` as candidates of `search`, ranges of it on every core
/// at once, where the source reads a range of particles cheaply (readPositionRangesInParallel:
/// the reading no longer holds up the search), and their tally; else false, having read nothing.
bool addInParallel(ParticleSource& source, KthNeighbours& search, FiniteTally& tally, Progress* progress) {
  tbb::enumerable_thread_specific<FiniteTally> tallies;
  const bool read = readPositionRangesInParallel(
      source,
      [&](std::span<const glm::vec3> positions, std::uint64_t first) {
        search.addConcurrently(positions, first);
        tallies.local().add(positions);
      },
      progress);
  if (!read) return false;
  search.flush();
  for (const FiniteTally& t : tallies) tally.add(t);
  return true;
}

/// Each point's k-th neighbour distance among the other points (detail::kthNeighbourDistancesAmong).
/// Points, not lists of queries within reach, go into cells a little wider than the radius:
/// queries and candidates are the same points, so no cell turns a candidate away, and each point
/// lies in one cell only. The points are sorted by cell (z, y, x), and the points of a cell
/// measure the runs of the 27 cells around it, found once for them all: by a dense table of
/// every cell's first point, where the points' box holds at most kDenseCellsPerPoint cells a
/// point (9 runs of 3 cells each), else by a hash table of the occupied cells, so that the cells
/// stay of the radius however far apart the points lie (two tanks, a particle flung far away).
std::vector<double> kthAmongPoints(std::span<const glm::vec3> points, double radius) {
  const std::size_t n = points.size();
  std::vector<double> kth(n, std::numeric_limits<double>::infinity());
  if (n <= kNeighbours || !(radius > 0) || !std::isfinite(radius)) return kth;
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
  for (const glm::vec3& p : points) {
    lo = glm::min(lo, glm::dvec3(p));
    hi = glm::max(hi, glm::dvec3(p));
  }
  const glm::dvec3 extent = hi - lo;
  if (!std::isfinite(extent.x + extent.y + extent.z)) return kth;
  // A candidate is counted when its float squared distance d2 is at most float(radius^2): its
  // true distance exceeds the radius by at most 3e-7 of it, plus subnormalMargin. Cells wider
  // than that put it in a cell next to the query's; a coordinate in cells (below 2^20, found in
  // doubles) is exact to far below the margin. Coarser cells where the spread is over 2^20 radii.
  constexpr double kAxisCells = double((1 << 20) - 3);
  const double cell =
      std::max(radius * (1 + 1e-5) + subnormalMargin(radius), std::max({extent.x, extent.y, extent.z}) / kAxisCells);
  // Cell coordinates from 1 with a cell of margin each side: the cells around one are in range.
  const glm::dvec3 axisCells = glm::floor(extent / cell) + 3.0;
  constexpr double kDenseCellsPerPoint = 8;
  const bool dense = axisCells.x * axisCells.y * axisCells.z <= std::max(4096.0, kDenseCellsPerPoint * double(n));
  const std::uint64_t rowCells = dense ? std::uint64_t(axisCells.x) : cellKey(0, 1, 0);
  const std::uint64_t sliceCells = dense ? rowCells * std::uint64_t(axisCells.y) : cellKey(0, 0, 1);
  const auto cellOf = [&](const glm::vec3& p) {
    const glm::u64vec3 c(glm::floor((glm::dvec3(p) - lo) / cell) + 1.0);
    return c.z * sliceCells + c.y * rowCells + c.x;
  };
  // The points by cell: a counting sort where dense, whose counts become each cell's first point.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> order(n);  // (cell, point)
  std::vector<std::uint32_t> firstPoint;                          // dense: at or after each cell, then n
  if (dense) {
    firstPoint.assign(std::size_t(sliceCells * std::uint64_t(axisCells.z)) + 1, 0);
    std::vector<std::uint64_t> cells(n);
    for (std::size_t i = 0; i < n; ++i) ++firstPoint[(cells[i] = cellOf(points[i])) + 1];
    for (std::size_t c = 1; c < firstPoint.size(); ++c) firstPoint[c] += firstPoint[c - 1];
    std::vector<std::uint32_t> next(firstPoint.begin(), firstPoint.end() - 1);
    for (std::size_t i = 0; i < n; ++i) order[next[cells[i]]++] = {cells[i], std::uint32_t(i)};
  } else {
    for (std::size_t i = 0; i < n; ++i) order[i] = {cellOf(points[i]), std::uint32_t(i)};
    std::sort(order.begin(), order.end());
  }
  std::vector<glm::vec3> sorted(n);  // the points in the order of their cells
  for (std::size_t k = 0; k < n; ++k) sorted[k] = points[order[k].second];
  const CellRuns runs(order, !dense);
  const float radius2 = float(radius * radius);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, runs.size(), 256), [&](const auto& range) {
    std::vector<float> near;
    std::array<std::pair<std::uint32_t, std::uint32_t>, 27> around;  // runs of points to measure
    for (std::size_t r = range.begin(); r != range.end(); ++r) {
      std::size_t arounds = 0;
      for (const std::uint64_t slice : {runs.cell(r) - sliceCells, runs.cell(r), runs.cell(r) + sliceCells})
        for (const std::uint64_t row : {slice - rowCells, slice, slice + rowCells}) {
          if (dense) {
            around[arounds++] = {firstPoint[row - 1], firstPoint[row + 2]};
            continue;
          }
          for (std::uint64_t c = row - 1; c <= row + 1; ++c)
            if (const std::int64_t run = runs.find(c); run >= 0)
              around[arounds++] = {runs.first(std::size_t(run)), runs.end(std::size_t(run))};
        }
      for (std::size_t k = runs.first(r); k < runs.end(r); ++k) {
        near.clear();
        const glm::vec3 q = sorted[k];
        for (std::size_t a = 0; a < arounds; ++a)
          for (std::size_t j = around[a].first; j < around[a].second; ++j) {
            const glm::vec3 d = q - sorted[j];
            const float d2 = d.x * d.x + d.y * d.y + d.z * d.z;
            if (d2 <= radius2 && j != k) near.push_back(d2);
          }
        if (near.size() < kNeighbours) continue;
        std::nth_element(near.begin(), near.begin() + (kNeighbours - 1), near.end());
        const double d2 = near[kNeighbours - 1];
        if (d2 <= radius * radius) kth[order[k].second] = std::sqrt(d2);
      }
    }
  });
  return kth;
}

/// Samples at least this large start medianWithinSample's search from a thinned part of them.
constexpr std::size_t kThinnedStart = 4000;

/// The median k-th neighbour distance among the sample itself (exact: the radius doubles from
/// a small start until more than half the queries have their k-th neighbour within it).
double medianWithinSample(const Sample& s) {
  const std::size_t n = s.positions.size();
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
  for (const glm::vec3& p : s.positions) {
    lo = glm::min(lo, glm::dvec3(p));
    hi = glm::max(hi, glm::dvec3(p));
  }
  const glm::dvec3 extent = hi - lo;
  const double longest = std::max({extent.x, extent.y, extent.z});
  if (!(longest > 0)) return 0;  // every particle at one point
  // Start from the spacing of the central 98 % of the particles spread over their box / 4 (the
  // 12th-neighbour distance is 1.4 spacings in a filled box): each failed try is cheap, a radius
  // far too large is not.
  double volume = 1;
  std::vector<float> axis(n);
  for (int a = 0; a < 3; ++a) {
    for (std::size_t i = 0; i < n; ++i) axis[i] = s.positions[i][a];
    auto low = axis.begin() + std::ptrdiff_t(n / 100), high = axis.begin() + std::ptrdiff_t(n - 1 - n / 100);
    std::nth_element(axis.begin(), low, axis.end());
    const float q0 = *low;
    std::nth_element(axis.begin(), high, axis.end());
    volume *= std::max(double(*high) - double(q0), 1e-3 * longest);
  }
  double radius = std::cbrt(volume / double(n)) / 4;
  // A large sample starts instead from the median within every 8th of its queries (a random
  // sample too, found the same way): distances there are cbrt(8) = 2 times longer. With a margin
  // of a fifth, one try usually does, where the box's spacing takes four on a tank of liquid.
  if (n >= kThinnedStart) {
    Sample part;
    for (std::size_t j = 0; j < n; j += 8) {
      part.positions.push_back(s.positions[j]);
    }
    const double partMedian = medianWithinSample(part);
    if (std::isfinite(partMedian) && partMedian > 0)
      radius = 1.2 * partMedian * std::cbrt(double(part.positions.size()) / double(n));
  }
  // Beyond 2 * longest every query has every other particle (n > k) within the radius.
  for (int attempt = 0; attempt < 64; ++attempt, radius *= 2) {
    std::vector<double> kth = kthAmongPoints(s.positions, std::min(radius, 2 * longest));
    const auto mid = kth.begin() + std::ptrdiff_t(n / 2);
    std::nth_element(kth.begin(), mid, kth.end());
    if (std::isfinite(*mid)) return *mid;
    if (radius >= 2 * longest) break;
  }
  return std::numeric_limits<double>::infinity();
}


}  // namespace

SpacingEstimate hintSpacing(const SpacingHint& hint) {
  SpacingEstimate e;
  if (hint.points == 0) return e;
  const double spacing = std::cbrt(hint.volume / double(hint.points));
  if (!(std::isfinite(spacing) && spacing > 0)) return e;
  e.spacing = spacing;
  e.origin = hint.origin;
  return e;
}

SpacingEstimate neighbourSpacing(ParticleSource& source, std::size_t sampleSize, Progress* progress) {
  sampleSize = std::max(sampleSize, kNeighbours + 1);
  // By number where the source allows it (one read fewer), unless too few of those sampled are
  // finite, or their distances say nothing: then the sample of a whole read, and its messages.
  double median = 0;
  std::optional<Sample> drawn = sampleByNumber(source, sampleSize);
  if (drawn && drawn->positions.size() > kNeighbours) median = medianWithinSample(*drawn);
  if (!(std::isfinite(median) && median > 0)) drawn.reset();
  const Sample sample = drawn ? std::move(*drawn) : reservoirSample(source, sampleSize, progress);
  SpacingEstimate e;
  if (!sample.complete() && !sample.positions.empty()) e.sampledBounds = finiteBounds(sample.positions).bounds;
  if (sample.counted && sample.finite < kNeighbours + 1) {
    e.bounds = sample.bounds;
    e.origin = "too few particles to measure (" + std::to_string(sample.finite) + " finite)";
    return e;
  }
  if (!drawn) median = medianWithinSample(sample);
  std::uint64_t finite = sample.finite;
  Box bounds = sample.bounds;
  if (!sample.complete() && std::isfinite(median) && median > 0) {
    // The sample is a random thinning to density n / N: distances shrink by cbrt(n / N). A
    // sample by number knows N only as the finite share of it.
    const double particles = sample.counted
                                 ? double(sample.finite)
                                 : double(*source.countHint()) * double(sample.positions.size()) / double(sampleSize);
    double radius = 1.5 * median * std::cbrt(double(sample.positions.size()) / particles);
    median = std::numeric_limits<double>::infinity();
    for (int pass = 1; pass < kSpacingMaxPasses && !std::isfinite(median); ++pass, radius *= 2) {
      FiniteTally tally;
      KthNeighbours search(sample, radius);
      if (!addInParallel(source, search, tally, progress)) {
        ParticleChunk chunk;
        std::uint64_t id = 0;
        while (source.read(chunk, kChunkParticles)) {
          search.add(chunk.positions, id);
          tally.add(chunk.positions);
          id += chunk.size();
          if (progress) progress->advance(chunk.size());
        }
        source.rewind();
      }
      if (pass == 1 && !sample.counted) finite = tally.finite, bounds = tally.bounds;
      median = search.median();
    }
  }
  e.bounds = bounds;
  const std::string of = sample.complete() ? "all " + std::to_string(finite) + " particles"
                                           : std::to_string(sample.positions.size()) + " sampled of " +
                                                 std::to_string(finite) + " particles";
  if (!std::isfinite(median)) {
    e.origin = "neighbour distances of " + of + " not found within " + std::to_string(kSpacingMaxPasses) + " reads";
    return e;
  }
  if (!(median > 0)) {
    e.origin = "most of " + of + " coincide with " + std::to_string(kSpacingNeighbour) + " others";
    return e;
  }
  e.spacing = median * ballFactor();
  e.origin =
      "median " + std::to_string(kSpacingNeighbour) + "th-neighbour distance " + numberText(median) + " of " + of;
  return e;
}

std::vector<double> detail::kthNeighbourDistancesAmong(std::span<const glm::vec3> points, double radius) {
  return kthAmongPoints(points, radius);
}

std::vector<double> detail::kthNeighbourDistances(std::span<const glm::vec3> queries,
                                                  std::span<const std::uint64_t> queryIds,
                                                  std::span<const glm::vec3> candidates, double radius) {
  Sample sample;
  sample.positions.assign(queries.begin(), queries.end());
  sample.ids.assign(queryIds.begin(), queryIds.end());
  KthNeighbours search(sample, radius);
  search.add(candidates, 0);
  return search.distances();
}

SpacingEstimate neighbourSpacing(std::span<const glm::vec3> points, std::size_t sampleSize) {
  PointSpanSource source(points);
  return neighbourSpacing(source, sampleSize);
}

SpacingEstimate estimateParticleSpacing(ParticleSource& source, Progress* progress) {
  if (auto hint = source.spacingHint()) {
    SpacingEstimate e = hintSpacing(*hint);
    if (e.known()) return e;
  }
  return neighbourSpacing(source, kSpacingSample, progress);
}

}  // namespace flipscope
