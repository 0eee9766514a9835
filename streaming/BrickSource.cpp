// Adapter from the brick store to BrickSource (Reichl et al. 2014 §3.1).
#include "streaming/BrickSource.h"

#include <algorithm>
#include <array>
#include <bit>
#include <limits>

#include <glm/common.hpp>
#include <glm/vector_relational.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "core/Error.h"

namespace flipscope {

bool BrickSource::hasFrame(int frame) const {
  const std::vector<int> all = frames();
  return std::binary_search(all.begin(), all.end(), frame);
}

std::shared_ptr<const DecodedBrick> StoreBrickSource::read(const BrickKey& key) {
  if (!mStore.hasFrame(key.frame)) return nullptr;
  std::shared_ptr<const FrameIndex> frame = mStore.frame(key.frame);
  const glm::uvec3 grid = mStore.header().brickGrid;
  if (key.coord.x >= grid.x || key.coord.y >= grid.y || key.coord.z >= grid.z) return nullptr;
  std::int64_t index = frame->octree.find(key.coord);
  if (index < 0) return nullptr;
  return std::make_shared<const DecodedBrick>(mStore.readBrick(*frame, std::uint32_t(index), mAttributes));
}

namespace {

using FrameIndices = std::vector<std::shared_ptr<const FrameIndex>>;

/// The indices of the frames of `source` in [first, last]: a flipbook's range may span frames
/// the store lacks.
FrameIndices frameIndices(BrickSource& source, int first, int last) {
  FrameIndices frames;
  for (const int f : source.frames())
    if (f >= first && f <= last) frames.push_back(source.frame(f));
  return frames;
}

bool within(glm::uvec3 c, glm::uvec3 lo, glm::uvec3 hi) {
  return glm::all(glm::greaterThanEqual(c, lo)) && glm::all(glm::lessThanEqual(c, hi));
}

/// occupiedBounds of the bricks of `frames` whose coordinates lie within [windowLo, windowHi].
Box occupiedBoundsWithin(BrickSource& source, const FrameIndices& frames, glm::uvec3 windowLo, glm::uvec3 windowHi) {
  const StoreHeader& h = source.header();
  glm::uvec3 lo(~0u), hi(0u);
  for (const auto& index : frames)
    for (const BrickRecord& record : index->bricks)
      if (within(record.coord, windowLo, windowHi)) {
        lo = glm::min(lo, record.coord);
        hi = glm::max(hi, record.coord);
      }
  if (lo.x > hi.x) return {};  // no bricks in any frame
  // Bricks on the outer layers of all frames decide the bounds: decode them (up to a limit over
  // the whole range) for cell-exact bounds, so a default camera frames the fluid, not its bricks.
  constexpr std::size_t kMaxDecoded = 2048;
  std::vector<std::pair<const FrameIndex*, std::uint32_t>> outer;
  for (const auto& index : frames) {
    for (std::uint32_t i = 0; i < index->bricks.size(); ++i) {
      const glm::uvec3 c = index->bricks[i].coord;
      if (within(c, lo, hi) && (glm::any(glm::equal(c, lo)) || glm::any(glm::equal(c, hi))))
        outer.emplace_back(index.get(), i);
    }
  }
  const glm::dvec3 lower(lo * h.brickSize), upper((hi + 1u) * h.brickSize);
  if (outer.size() > kMaxDecoded) return Box{h.origin + lower * h.cellSize, h.origin + upper * h.cellSize};
  // The bricks are decoded over every core (BrickSource is thread safe). Cell indices are
  // x + B (y + B z) with B a power of two: bounds in whole cells, as integers.
  using CellBounds = std::pair<glm::uvec3, glm::uvec3>;  // lowest cell, highest cell + 1
  const CellBounds none{glm::uvec3(~0u), glm::uvec3(0u)};
  const std::uint32_t shift = std::uint32_t(std::countr_zero(h.brickSize)), mask = h.brickSize - 1;
  const CellBounds cells = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, outer.size(), 4), none,
      [&](const tbb::blocked_range<std::size_t>& range, CellBounds bounds) {
        for (std::size_t o = range.begin(); o != range.end(); ++o) {
          const auto& [index, i] = outer[o];
          const auto brick = source.read(BrickKey{index->frame, index->bricks[i].coord});
          FLIPSCOPE_CHECK(brick, "brick " << i << " of frame " << index->frame << " listed but empty");
          glm::uvec3 low(~0u), high(0u);
          for (std::uint32_t cell : brick->cells) {
            const glm::uvec3 c(cell & mask, (cell >> shift) & mask, cell >> (2 * shift));
            low = glm::min(low, c);
            high = glm::max(high, c);
          }
          if (brick->cells.empty()) continue;
          const glm::uvec3 base = index->bricks[i].coord * h.brickSize;
          bounds.first = glm::min(bounds.first, base + low);
          bounds.second = glm::max(bounds.second, base + high + 1u);
        }
        return bounds;
      },
      [](const CellBounds& a, const CellBounds& b) {
        return CellBounds{glm::min(a.first, b.first), glm::max(a.second, b.second)};
      });
  if (cells.first.x > cells.second.x) return Box{h.origin + lower * h.cellSize, h.origin + upper * h.cellSize};
  return Box{h.origin + glm::dvec3(cells.first) * h.cellSize, h.origin + glm::dvec3(cells.second) * h.cellSize};
}

}  // namespace

Box occupiedBounds(BrickSource& source, int first, int last) {
  return occupiedBoundsWithin(source, frameIndices(source, first, last), glm::uvec3(0u), glm::uvec3(~0u));
}

FramedBounds framedBounds(BrickSource& source, int first, int last) {
  const FrameIndices frames = frameIndices(source, first, last);
  const glm::uvec3 grid = source.header().brickGrid;
  // Per axis, the particles of each brick coordinate.
  std::array<std::vector<std::uint64_t>, 3> histograms;
  for (int a = 0; a < 3; ++a) histograms[a].assign(grid[a], 0);
  FramedBounds out;
  for (const auto& index : frames)
    for (const BrickRecord& record : index->bricks) {
      if (!within(record.coord, glm::uvec3(0u), grid - 1u)) continue;  // an index holds none (BrickStore)
      for (int a = 0; a < 3; ++a) histograms[a][record.coord[a]] += record.particles;
      out.particles += record.particles;
    }
  // The bulk per axis: the coordinates past the tails of at most kFramingTail of the particles.
  const auto tail = std::uint64_t(double(out.particles) * kFramingTail);
  glm::uvec3 bulkLo(0u), bulkHi(0u);
  std::uint32_t extent = 0;
  for (int a = 0; a < 3 && out.particles > 0; ++a) {
    const std::vector<std::uint64_t>& h = histograms[a];
    std::uint64_t below = 0, above = 0;
    std::uint32_t lo = 0, hi = grid[a] - 1;
    while (below + h[lo] <= tail) below += h[lo++];
    while (above + h[hi] <= tail) above += h[hi--];
    bulkLo[a] = lo;
    bulkHi[a] = hi;
    extent = std::max(extent, hi - lo + 1);
  }
  glm::uvec3 windowLo(0u), windowHi(~0u);
  for (int a = 0; a < 3 && out.particles > 0; ++a) {
    windowLo[a] = bulkLo[a] - std::min(bulkLo[a], extent);
    windowHi[a] = bulkHi[a] + extent;
  }
  for (const auto& index : frames) {
    std::uint64_t leftOut = 0;
    for (const BrickRecord& record : index->bricks)
      if (!within(record.coord, windowLo, windowHi)) leftOut += record.particles;
    out.particlesLeftOut = std::max(out.particlesLeftOut, leftOut);
  }
  out.box = occupiedBoundsWithin(source, frames, windowLo, windowHi);
  return out;
}

}  // namespace flipscope
