// Adapter from the brick store to BrickSource (Reichl et al. 2014 §3.1).
#include "streaming/BrickSource.h"

#include <algorithm>
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

Box occupiedBounds(BrickSource& source, int first, int last) {
  const StoreHeader& h = source.header();
  std::vector<std::shared_ptr<const FrameIndex>> frames;
  glm::uvec3 lo(~0u), hi(0u);
  for (int f = first; f <= last; ++f) {
    frames.push_back(source.frame(f));
    for (const BrickRecord& record : frames.back()->bricks) {
      lo = glm::min(lo, record.coord);
      hi = glm::max(hi, record.coord);
    }
  }
  if (lo.x > hi.x) return {};  // no bricks in any frame
  // Bricks on the outer layers of all frames decide the bounds: decode them (up to a limit over
  // the whole range) for cell-exact bounds, so a default camera frames the fluid, not its bricks.
  constexpr std::size_t kMaxDecoded = 2048;
  std::vector<std::pair<const FrameIndex*, std::uint32_t>> outer;
  for (const auto& index : frames) {
    for (std::uint32_t i = 0; i < index->bricks.size(); ++i) {
      const glm::uvec3 c = index->bricks[i].coord;
      if (glm::any(glm::equal(c, lo)) || glm::any(glm::equal(c, hi))) outer.emplace_back(index.get(), i);
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

}  // namespace flipscope
