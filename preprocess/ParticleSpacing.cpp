// ParticleSpacing: the metadata and neighbour estimates of the particle spacing (see the header).
#include "preprocess/ParticleSpacing.h"

#include "preprocess/particles/PointSpanSource.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <glm/common.hpp>
#include <glm/vector_relational.hpp>
#include <glm/vec3.hpp>

#include "core/Error.h"
#include "core/FastFloor.h"
#include "preprocess/FiniteBounds.h"

namespace flipscope {
namespace {

constexpr std::size_t kChunkParticles = 1 << 16;
constexpr std::size_t kNeighbours = kSpacingNeighbour;
/// Query grids of at most this many cells are indexed directly (16 MiB), larger ones hashed.
constexpr std::size_t kDenseCells = std::size_t(1) << 22;
/// Query grids of at most this many cells (with a border of one) get a byte per cell of block
/// mask (4 MiB, cache-sized); up to kNearCells, a bit per cell (64 MiB) saying whether a query
/// lies in the 27 cells around: those of frames of a few billion particles.
constexpr std::size_t kMaskCells = std::size_t(1) << 22;
constexpr std::size_t kNearCells = std::size_t(1) << 29;
/// The near-query bits (KthNeighbours::buildNearQueryBits): cells of half the radius, at most
/// this many (4 MiB of bits; coarser cells beyond).
constexpr double kNearQueryCells = double(std::size_t(1) << 25);

/// Spacing per k-th neighbour distance r: at spacing r * ballFactor(), a ball of radius r holds k particles.
double ballFactor() { return std::cbrt(4 * std::numbers::pi / (3 * double(kSpacingNeighbour))); }

bool isFinite(const glm::vec3& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

std::string text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// The query particles: a uniform random sample of the source's finite particles.
struct Sample {
  std::vector<glm::vec3> positions;
  std::vector<std::uint64_t> ids;  ///< index of each sampled particle in the source's order
  std::uint64_t finite = 0;        ///< finite particles in the whole source
  Box bounds;                      ///< of the finite particles of the whole source
  bool complete() const { return finite == positions.size(); }
};

/// Reservoir sampling of the finite particles (Li's algorithm L: a random skip to the next
/// particle that enters the sample, so random numbers are drawn only for those, about
/// size * ln(finite / size) of them), one read of the source, then a rewind. The count and the
/// bounds of the finite particles are gathered on the way, in parallel over each chunk.
Sample reservoirSample(ParticleSource& source, std::size_t size, Progress* progress) {
  Sample s;
  std::mt19937_64 rng(0x5041434eull);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const auto open = [&] { return 1.0 - uniform(rng); };  // in (0, 1]: its log is finite
  const double k = double(size);
  double w = std::exp(std::log(open()) / k);
  // The finite particle (counted from 0) that enters the sample next, once it is full.
  const auto skip = [&] {
    const double gap = std::floor(std::log(open()) / std::log1p(-w));
    return gap < 0x1p62 ? std::uint64_t(gap) + 1 : std::uint64_t(1) << 62;  // (w so small: never)
  };
  std::uint64_t next = 0;
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
      if (s.positions.size() < size) {
        s.positions.push_back(p[i]);
        s.ids.push_back(id + i);
        if (s.positions.size() == size) next = counted + skip();
      } else if (counted == next) {
        const auto slot = std::uniform_int_distribution<std::size_t>(0, size - 1)(rng);
        s.positions[slot] = p[i];
        s.ids[slot] = id + i;
        w *= std::exp(std::log(open()) / k);
        next = counted + skip();
      } else if (p.size() - i == end - counted) {  // all finite from here: jump to the next one in
        if (next >= end) break;                     // (none of them enters the sample)
        i += std::size_t(next - counted) - 1;
        counted = next - 1;
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

/// The k-th neighbour distance of every query among the candidates given to add(), searched as
/// far as `radius`: a query whose k-th neighbour is farther keeps +inf. Queries are binned into
/// cells of 2 * radius (indexed directly, or hashed when the grid is large), so a candidate only
/// visits the 8 cells on its side of its own cell; a candidate with the id of a query is that
/// query itself and skipped.
class KthNeighbours {
 public:
  KthNeighbours(const Sample& queries, double radius)
      : mQueries(queries),
        mRadius(radius),
        mCell(2 * radius),
        mInverseCell(1 / mCell),
        mHeaps(queries.positions.size() * kNeighbours, std::numeric_limits<float>::infinity()) {
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
    for (const glm::vec3& q : queries.positions) {
      lo = glm::min(lo, glm::dvec3(q));
      hi = glm::max(hi, glm::dvec3(q));
    }
    mOrigin = lo;
    mLo = lo - radius;
    mHi = hi + radius;
    const glm::dvec3 extent = (hi - lo) / mCell;
    mUsable = queries.positions.size() > 0 && mCell > 0 && std::isfinite(mCell) &&
              std::max({extent.x, extent.y, extent.z}) < double(1 << 30);
    if (mUsable) {
      buildTable();
      buildNearQueryBits();
    }
  }

  /// Candidates with consecutive ids from `firstId` (the source's order).
  void add(std::span<const glm::vec3> candidates, std::uint64_t firstId) {
    addAll(candidates.size(), [&](std::size_t i) { return std::pair(candidates[i], firstId + i); });
  }
  /// Candidates with the given ids.
  void add(std::span<const glm::vec3> candidates, std::span<const std::uint64_t> ids) {
    addAll(candidates.size(), [&](std::size_t i) { return std::pair(candidates[i], ids[i]); });
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
  struct Slot {
    glm::ivec3 cell{0};
    std::uint32_t begin = 0, end = 0;  ///< queries mOrder[begin, end); empty slot when begin == end
  };

  /// In cells of the grid, from its origin; queries and candidates alike.
  glm::dvec3 gridPoint(const glm::dvec3& p) const { return (p - mOrigin) * mInverseCell; }
  glm::ivec3 cellOf(const glm::dvec3& p) const { return glm::ivec3(fastFloor(gridPoint(p))); }

  static std::uint64_t hash(const glm::ivec3& c) {
    std::uint64_t h = std::uint64_t(std::uint32_t(c.x)) | (std::uint64_t(std::uint32_t(c.y)) << 32);
    h ^= std::uint64_t(std::uint32_t(c.z)) * 0x9e3779b97f4a7c15ull;
    h ^= h >> 31;
    h *= 0xbf58476d1ce4e5b9ull;
    h ^= h >> 29;
    return h;
  }

  void buildTable() {
    const std::size_t n = mQueries.positions.size();
    std::vector<glm::ivec3> cells(n);
    for (std::size_t j = 0; j < n; ++j) cells[j] = cellOf(glm::dvec3(mQueries.positions[j]));
    mOrder.resize(n);
    for (std::size_t j = 0; j < n; ++j) mOrder[j] = std::uint32_t(j);
    auto less = [](const glm::ivec3& a, const glm::ivec3& b) {
      return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
    };
    std::sort(mOrder.begin(), mOrder.end(), [&](std::uint32_t a, std::uint32_t b) { return less(cells[a], cells[b]); });
    glm::i64vec3 dims(1);
    for (const glm::ivec3& c : cells) dims = glm::max(dims, glm::i64vec3(c) + std::int64_t(1));
    mDims = glm::ivec3(dims);
    const auto cellsOf = [](glm::i64vec3 d) { return double(d.x) * double(d.y) * double(d.z); };
    // Bit o of a cell's byte of mask: a query lies in the 2x2x2 cells a candidate of the cell
    // visits when it is in octant o (visit()); over the grid and one cell around it. Most
    // candidates lie far from every query, and this one byte turns them away.
    // Larger grids get a bit per cell: a query lies in the 3x3x3 cells around, a coarser test
    // that fits in the caches where a byte a cell would not (every candidate looks it up).
    const double maskCells = cellsOf(dims + std::int64_t(2));
    if (maskCells <= double(kMaskCells)) mBlockMask.assign(std::size_t(maskCells), 0);
    else if (maskCells <= double(kNearCells)) mNearBits.assign((std::size_t(maskCells) + 63) / 64, 0);
    for (std::size_t i = 0; i < n && (!mBlockMask.empty() || !mNearBits.empty()); ++i) {
      if (i > 0 && cells[mOrder[i]] == cells[mOrder[i - 1]]) continue;
      const glm::ivec3 q = cells[mOrder[i]];
      if (!mBlockMask.empty()) {
        for (int octant = 0; octant < 8; ++octant)
          for (int corner = 0; corner < 8; ++corner) {
            const glm::ivec3 step(corner & 1 ? octantSide(octant, 0) : 0, corner & 2 ? octantSide(octant, 1) : 0,
                                  corner & 4 ? octantSide(octant, 2) : 0);
            mBlockMask[maskIndex(q - step)] |= std::uint8_t(1u << octant);
          }
      } else {
        for (int z = -1; z <= 1; ++z)
          for (int y = -1; y <= 1; ++y)
            for (int x = -1; x <= 1; ++x) {
              const std::size_t bit = maskIndex(q + glm::ivec3(x, y, z));
              mNearBits[bit / 64] |= std::uint64_t(1) << (bit % 64);
            }
      }
    }
    // Small grids (the usual case) index their cells directly: mOrder is sorted in the order of
    // the dense index (x, then y, then z), so each cell's queries are one range of it.
    if (cellsOf(dims) <= double(kDenseCells)) {
      mDenseStart.assign(std::size_t(cellsOf(dims)) + 1, 0);
      for (const glm::ivec3& c : cells) ++mDenseStart[denseIndex(c) + 1];
      for (std::size_t i = 1; i < mDenseStart.size(); ++i) mDenseStart[i] += mDenseStart[i - 1];
      return;
    }
    std::size_t groups = 0;
    for (std::size_t i = 0; i < n; ++i) groups += i == 0 || cells[mOrder[i]] != cells[mOrder[i - 1]];
    mTable.assign(std::bit_ceil(std::max<std::size_t>(16, 2 * groups)), Slot{});
    mMask = mTable.size() - 1;
    for (std::size_t i = 0; i < n;) {
      std::size_t end = i + 1;
      while (end < n && cells[mOrder[end]] == cells[mOrder[i]]) ++end;
      std::size_t s = hash(cells[mOrder[i]]) & mMask;
      while (mTable[s].begin != mTable[s].end) s = (s + 1) & mMask;
      mTable[s] = Slot{cells[mOrder[i]], std::uint32_t(i), std::uint32_t(end)};
      i = end;
    }
  }

  /// A bit per cell of a grid finer than the query cells (half the radius) over [mLo, mHi]: set
  /// where a query lies within the radius of some point of the cell. A candidate whose cell's
  /// bit is clear has no query within the radius and is turned away with one lookup. Cells are
  /// set with a margin (kSlack) so that rounding in the candidate's cell index never turns away
  /// one that has; the search itself (visit) stays exact. Without these bits half the
  /// candidates of a frame passed the coarser block mask below; with them about a tenth do.
  void buildNearQueryBits() {
    const glm::dvec3 extent = mHi - mLo;
    double cell = mRadius / 2;
    const auto cellsFor = [&](double c) { return glm::floor(extent / c) + 1.0; };
    glm::dvec3 dims = cellsFor(cell);
    if (const double count = dims.x * dims.y * dims.z; !(count <= kNearQueryCells)) {
      cell *= std::cbrt(count / kNearQueryCells) * 1.01;
      dims = cellsFor(cell);
    }
    if (!(dims.x * dims.y * dims.z <= kNearQueryCells)) return;  // (extents beyond doubles' reach: no bits)
    mNearQueryInverse = 1 / cell;
    mNearQueryDims = glm::ivec3(dims);
    mNearQueryBits.assign((std::size_t(dims.x * dims.y * dims.z) + 63) / 64, 0);
    constexpr double kSlack = 1e-6;
    const double reach = mRadius * (1 + kSlack) + cell * kSlack;
    std::vector<double> distance[3];  // per axis, from the query to each cell of its range
    for (const glm::vec3& query : mQueries.positions) {
      const glm::dvec3 q(query);
      glm::ivec3 first, last;
      for (int a = 0; a < 3; ++a) {
        first[a] = std::max(0, int(std::floor((q[a] - reach - mLo[a]) * mNearQueryInverse)));
        last[a] = std::min(mNearQueryDims[a] - 1, int(std::floor((q[a] + reach - mLo[a]) * mNearQueryInverse)));
        distance[a].clear();
        for (int i = first[a]; i <= last[a]; ++i) {
          const double lo = mLo[a] + i * cell, hi = lo + cell;
          const double d = std::max({lo - q[a], 0.0, q[a] - hi});
          distance[a].push_back(d * d);
        }
      }
      const double reach2 = reach * reach;
      for (int z = first.z; z <= last.z; ++z)
        for (int y = first.y; y <= last.y; ++y) {
          const double yz = distance[2][std::size_t(z - first.z)] + distance[1][std::size_t(y - first.y)];
          if (yz > reach2) continue;
          const std::size_t row =
              (std::size_t(z) * std::size_t(mNearQueryDims.y) + std::size_t(y)) * std::size_t(mNearQueryDims.x);
          for (int x = first.x; x <= last.x; ++x) {
            if (yz + distance[0][std::size_t(x - first.x)] > reach2) continue;
            const std::size_t bit = row + std::size_t(x);
            mNearQueryBits[bit / 64] |= std::uint64_t(1) << (bit % 64);
          }
        }
    }
  }

  /// Whether the near-query bits let candidate p (inside [mLo, mHi]) through.
  bool mayHaveQueryNear(const glm::dvec3& p) const {
    if (mNearQueryBits.empty()) return true;
    const glm::dvec3 g = (p - mLo) * mNearQueryInverse;  // >= 0: p is inside
    const glm::ivec3 c = glm::min(glm::ivec3(g), mNearQueryDims - 1);
    const std::size_t bit =
        (std::size_t(c.z) * std::size_t(mNearQueryDims.y) + std::size_t(c.y)) * std::size_t(mNearQueryDims.x) +
        std::size_t(c.x);
    return mNearQueryBits[bit / 64] >> (bit % 64) & 1;
  }

  /// The side (-1 or 1) of `axis` of octant o: bit `axis` of o set is the upper half.
  static int octantSide(int octant, int axis) { return octant >> axis & 1 ? 1 : -1; }
  /// Index into mBlockMask (or bit of mNearBits) of a cell in [-1, mDims] on every axis.
  std::size_t maskIndex(const glm::ivec3& c) const {
    return (std::size_t(c.x + 1) * std::size_t(mDims.y + 2) + std::size_t(c.y + 1)) * std::size_t(mDims.z + 2) +
           std::size_t(c.z + 1);
  }

  std::size_t denseIndex(const glm::ivec3& c) const {
    return (std::size_t(c.x) * std::size_t(mDims.y) + std::size_t(c.y)) * std::size_t(mDims.z) + std::size_t(c.z);
  }

  /// The queries of `cell`: mOrder[begin, end), empty when it has none.
  std::pair<std::uint32_t, std::uint32_t> find(const glm::ivec3& cell) const {
    if (!mDenseStart.empty()) {
      if (cell.x < 0 || cell.y < 0 || cell.z < 0 || cell.x >= mDims.x || cell.y >= mDims.y || cell.z >= mDims.z)
        return {0, 0};
      const std::size_t i = denseIndex(cell);
      return {mDenseStart[i], mDenseStart[i + 1]};
    }
    for (std::size_t s = hash(cell) & mMask;; s = (s + 1) & mMask) {
      const Slot& slot = mTable[s];
      if (slot.begin == slot.end) return {0, 0};
      if (slot.cell == cell) return {slot.begin, slot.end};
    }
  }

  /// A query's candidate within the radius.
  struct Hit {
    std::uint32_t query;
    float distance2;
  };

  /// Finds the hits of candidates [0, n) in parallel, then merges them into the heaps.
  template <class Candidate>
  void addAll(std::size_t n, Candidate candidate) {
    if (!mUsable) return;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const auto& range) {
      std::vector<Hit>& hits = mHits.local();
      for (std::size_t i = range.begin(); i != range.end(); ++i) {
        const auto [position, id] = candidate(i);
        visit(position, id, hits);
      }
    });
    for (std::vector<Hit>& hits : mHits) {
      for (const Hit& hit : hits) {
        float* heap = &mHeaps[std::size_t(hit.query) * kNeighbours];
        if (!(hit.distance2 < heap[0])) continue;
        std::pop_heap(heap, heap + kNeighbours);
        heap[kNeighbours - 1] = hit.distance2;
        std::push_heap(heap, heap + kNeighbours);
      }
      hits.clear();
    }
  }

  void visit(const glm::vec3& candidate, std::uint64_t id, std::vector<Hit>& hits) const {
    if (!isFinite(candidate)) return;
    const glm::dvec3 p(candidate);
    if (p.x < mLo.x || p.y < mLo.y || p.z < mLo.z || p.x > mHi.x || p.y > mHi.y || p.z > mHi.z) return;
    if (!mayHaveQueryNear(p)) return;
    const glm::dvec3 f = gridPoint(p);
    const glm::dvec3 base = fastFloor(f);
    const glm::ivec3 cell(base);
    // A query within radius = half a cell lies in this cell or the neighbour on the side of
    // the half the candidate is in, on every axis: the octant's (no branches: the halves are
    // a coin toss).
    const int octant = int(f.x - base.x >= 0.5) | int(f.y - base.y >= 0.5) << 1 | int(f.z - base.z >= 0.5) << 2;
    if (!mBlockMask.empty() || !mNearBits.empty()) {  // most candidates have no query near
      if (glm::any(glm::lessThan(cell, glm::ivec3(-1))) || glm::any(glm::greaterThan(cell, mDims))) return;
      const std::size_t m = maskIndex(cell);
      if (mNearBits.empty() ? !(mBlockMask[m] >> octant & 1) : !(mNearBits[m / 64] >> (m % 64) & 1)) return;
    }
    const glm::ivec3 side(octantSide(octant, 0), octantSide(octant, 1), octantSide(octant, 2));
    const float radius2 = float(mRadius * mRadius);
    for (int corner = 0; corner < 8; ++corner) {
      const glm::ivec3 c = cell + glm::ivec3(corner & 1 ? side.x : 0, corner & 2 ? side.y : 0, corner & 4 ? side.z : 0);
      const auto [begin, end] = find(c);
      for (std::uint32_t i = begin; i < end; ++i) {
        const std::uint32_t j = mOrder[i];
        if (mQueries.ids[j] == id) continue;
        const glm::vec3 d = mQueries.positions[j] - candidate;
        const float d2 = d.x * d.x + d.y * d.y + d.z * d.z;
        if (d2 <= radius2) hits.push_back({j, d2});
      }
    }
  }

  const Sample& mQueries;
  double mRadius, mCell, mInverseCell;
  glm::dvec3 mOrigin{0}, mLo{0}, mHi{0};
  bool mUsable = false;
  std::vector<std::uint32_t> mOrder;
  glm::ivec3 mDims{0};                     ///< of the query cells (the dense index and the mask)
  std::vector<std::uint32_t> mDenseStart;  ///< per dense cell, its first query in mOrder; then n
  std::vector<std::uint8_t> mBlockMask;    ///< small grids: see buildTable()
  std::vector<std::uint64_t> mNearBits;    ///< larger grids: see buildTable()
  std::vector<Slot> mTable;                ///< else: the cells with queries, hashed
  double mNearQueryInverse = 0;            ///< see buildNearQueryBits()
  glm::ivec3 mNearQueryDims{0};
  std::vector<std::uint64_t> mNearQueryBits;
  std::size_t mMask = 0;
  std::vector<float> mHeaps;  ///< k squared distances per query, a max-heap each
  tbb::enumerable_thread_specific<std::vector<Hit>> mHits;
};

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
  // Start from the spacing of the central 98 % of the particles spread over their box / 16:
  // each failed try is cheap, a radius far too large is not.
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
  double radius = std::cbrt(volume / double(n)) / 16;
  // Beyond 2 * longest every query has every other particle (n > k) within the radius.
  for (int attempt = 0; attempt < 64; ++attempt, radius *= 2) {
    KthNeighbours search(s, std::min(radius, 2 * longest));
    search.add(s.positions, s.ids);
    const double median = search.median();
    if (std::isfinite(median)) return median;
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
  const Sample sample = reservoirSample(source, sampleSize, progress);
  SpacingEstimate e;
  e.bounds = sample.bounds;
  if (sample.finite < kNeighbours + 1) {
    e.origin = "too few particles to measure (" + std::to_string(sample.finite) + " finite)";
    return e;
  }
  double median = medianWithinSample(sample);
  std::string of = "all " + std::to_string(sample.finite) + " particles";
  if (!sample.complete() && std::isfinite(median) && median > 0) {
    // The sample is a random thinning to density n / N: distances shrink by cbrt(n / N).
    of = std::to_string(sample.positions.size()) + " sampled of " + std::to_string(sample.finite) + " particles";
    double radius = 1.5 * median * std::cbrt(double(sample.positions.size()) / double(sample.finite));
    median = std::numeric_limits<double>::infinity();
    for (int pass = 1; pass < kSpacingMaxPasses && !std::isfinite(median); ++pass, radius *= 2) {
      KthNeighbours search(sample, radius);
      ParticleChunk chunk;
      std::uint64_t id = 0;
      while (source.read(chunk, kChunkParticles)) {
        search.add(chunk.positions, id);
        id += chunk.size();
        if (progress) progress->advance(chunk.size());
      }
      source.rewind();
      median = search.median();
    }
  }
  if (!std::isfinite(median)) {
    e.origin = "neighbour distances of " + of + " not found within " + std::to_string(kSpacingMaxPasses) + " reads";
    return e;
  }
  if (!(median > 0)) {
    e.origin = "most of " + of + " coincide with " + std::to_string(kSpacingNeighbour) + " others";
    return e;
  }
  e.spacing = median * ballFactor();
  e.origin = "median " + std::to_string(kSpacingNeighbour) + "th-neighbour distance " + text(median) + " of " + of;
  return e;
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
