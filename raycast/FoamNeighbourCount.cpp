#include "raycast/FoamNeighbourCount.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "core/Error.h"
#include "raycast/CpuRaycastKernel.h"

namespace flipscope {

namespace {

constexpr int kLanes = 8;  ///< cells counted at once, a byte each of a 64-bit word
constexpr std::uint64_t kEveryLane = 0x0101010101010101ull;

std::uint64_t load8(const std::uint8_t* p) {
  std::uint64_t v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

/// 4 bits of a sub-brick word (cells x to x + 3 of a row) as 4 bytes, 0 or 1.
constexpr std::array<std::uint32_t, 16> kRowBytes = [] {
  std::array<std::uint32_t, 16> bytes{};
  for (std::uint32_t bits = 0; bits < 16; ++bits)
    for (std::uint32_t x = 0; x < 4; ++x) bytes[bits] |= ((bits >> x) & 1u) << (8 * x);
  return bytes;
}();

/// The set cells of a brick's sub-bricks (BitBrick.glsl: 4x4x8 cells, bit x + 4 y + 16 z) as
/// bytes, 1 where set: cell (x, y, z) at x + row y + plane z.
void spreadSetCells(const glm::uvec4* subBricks, glm::uvec3 dims, std::size_t row, std::size_t plane,
                    std::vector<std::uint8_t>& grid) {
  for (std::uint32_t s = 0; s < dims.x * dims.y * dims.z; ++s) {
    const glm::uvec4 bits = subBricks[s];
    if ((bits.x | bits.y | bits.z | bits.w) == 0u) continue;
    const glm::uvec3 origin = glsl::bitBrickSubBrickCoord(s, dims) * glm::uvec3(4, 4, 8);
    for (std::uint32_t w = 0; w < 4; ++w)
      for (std::uint32_t half = 0; half < 2; ++half) {  // a word holds two layers of 4x4 cells
        const std::uint32_t layer = (bits[int(w)] >> (16 * half)) & 0xffffu;
        if (!layer) continue;
        const std::size_t z = origin.z + 2 * w + half;
        for (std::uint32_t y = 0; y < 4; ++y)
          std::memcpy(&grid[origin.x + row * (origin.y + y) + plane * z], &kRowBytes[(layer >> (4 * y)) & 15u], 4);
      }
  }
}

/// Sets the foam bit of brick cell (x, y, z) in its sub-brick.
void setFoamBit(glm::uvec4* foam, glm::uvec3 dims, std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  const std::uint32_t s = (x >> 2) + dims.x * ((y >> 2) + dims.y * (z >> 3));
  const std::uint32_t bit = (x & 3u) | (y & 3u) << 2 | (z & 7u) << 4;
  foam[s][int(bit >> 5)] |= 1u << (bit & 31u);
}

}  // namespace

void classifyBrickFoam(const glm::uvec4* subBricks, glm::uvec4* foam, const FoamClassifyParams& params,
                       FoamNeighbourScratch& scratch) {
  if (params.classify == 0u) return;  // the uploaded bits as they are
  const std::uint32_t brickSize = params.brickSize, overlap = params.overlap;
  const glm::uvec3 dims = glsl::bitBrickSubBrickDims(brickSize, overlap);
  FLIPSCOPE_CHECK(params.subBricksPerSlot == dims.x * dims.y * dims.z, params.subBricksPerSlot << " sub-bricks");
  const float radius = params.radius;
  const int reach = int(std::floor(radius));
  const float needed = params.threshold * float(glsl::FoamKernel{params, nullptr}.fcNeighbourhoodSize(radius));
  // Every set cell of the sub-bricks, which may reach past the stored cells: the cells to
  // classify. Rows of a multiple of kLanes, zero beyond the sub-bricks.
  const glm::ivec3 extent(dims * glm::uvec3(4, 4, 8));
  const std::size_t setRow = std::size_t((extent.x + kLanes - 1) / kLanes * kLanes);
  const std::size_t setPlane = setRow * std::size_t(extent.y);
  scratch.setCells.assign(setPlane * std::size_t(extent.z), 0);
  spreadSetCells(subBricks, dims, setRow, setPlane, scratch.setCells);
  // The cells they count: the stored ones, with `reach` empty cells around; beyond the stored
  // cells they count as empty (fcStoredCellSet).
  const int stored = int(brickSize + 2 * overlap);
  const glm::ivec3 span = extent + 2 * reach;
  const std::size_t row = std::size_t(span.x), plane = row * std::size_t(span.y);
  scratch.cells.assign(plane * std::size_t(span.z) + kLanes, 0);  // + kLanes: the 8-byte loads at the end
  auto at = [&](int x, int y, int z) { return std::size_t(x + reach) + row * std::size_t(y + reach) + plane * std::size_t(z + reach); };
  for (int z = 0; z < stored; ++z)
    for (int y = 0; y < stored; ++y)
      std::memcpy(&scratch.cells[at(0, y, z)], &scratch.setCells[setRow * std::size_t(y) + setPlane * std::size_t(z)],
                  std::size_t(stored));
  // fcClassify's neighbourhood, the nearest offsets first.
  struct Offset {
    int distance2;
    std::int32_t delta;
  };
  std::vector<Offset> offsets;
  for (int dz = -reach; dz <= reach; dz++)
    for (int dy = -reach; dy <= reach; dy++)
      for (int dx = -reach; dx <= reach; dx++) {
        if (float(dx * dx + dy * dy + dz * dz) > radius * radius || (dx == 0 && dy == 0 && dz == 0)) continue;
        offsets.push_back({dx * dx + dy * dy + dz * dz, std::int32_t(dx + std::int64_t(row) * dy + std::int64_t(plane) * dz)});
      }
  std::stable_sort(offsets.begin(), offsets.end(), [](const Offset& a, const Offset& b) { return a.distance2 < b.distance2; });
  scratch.offsets.clear();
  for (const Offset& o : offsets) scratch.offsets.push_back(o.delta);
  const std::size_t neighbours = scratch.offsets.size();
  const std::int32_t* delta = scratch.offsets.data();
  // count < needed, as fcClassify compares it (float(count) < needed), for counts this small.
  const std::uint32_t enough = std::uint32_t(std::ceil(needed));
  const std::uint8_t* cells = scratch.cells.data();
  // Each cell's count stops once it has enough (in a liquid body after a few), checked every 8
  // neighbours: the decision is the same, the tests fewer. 8 cells of a row are counted at once,
  // a byte of a 64-bit word each, when no count can reach 128 (no carry between the bytes).
  const bool lanes = neighbours < 128 && enough < 128;
  constexpr std::uint64_t kHigh = kEveryLane * 0x80;
  const std::uint64_t enoughInEveryLane = kEveryLane * enough;
  for (int z = 0; z < extent.z; ++z)
    for (int y = 0; y < extent.y; ++y)
      for (int x = 0; x < int(setRow); x += kLanes) {
        const std::uint64_t set =
            load8(&scratch.setCells[std::size_t(x) + setRow * std::size_t(y) + setPlane * std::size_t(z)]);
        if (set == 0) continue;
        const std::uint8_t* centre = cells + at(x, y, z);
        std::uint64_t short_ = 0;  // the lowest bit of each byte whose cell has fewer than enough: foam
        if (lanes) {
          std::uint64_t counts = 0, full = 0;  // full: 0x01 in the bytes with count >= enough
          for (std::size_t i = 0;; i += kLanes) {
            const std::size_t end = std::min(i + kLanes, neighbours);
            for (std::size_t j = i; j < end; ++j) counts += load8(centre + delta[j]);
            full = (((counts | kHigh) - enoughInEveryLane) & kHigh) >> 7;
            if (end == neighbours || (full & set) == set) break;
          }
          short_ = set & ~full;
        } else {
          for (int k = 0; k < kLanes; ++k) {
            if (!(set >> (8 * k) & 1)) continue;
            std::uint32_t count = 0;
            for (std::size_t i = 0; i < neighbours && count < enough; i += kLanes)
              for (std::size_t j = i; j < std::min(i + kLanes, neighbours); ++j) count += centre[k + delta[j]];
            if (count < enough) short_ |= std::uint64_t(1) << (8 * k);
          }
        }
        for (; short_ != 0; short_ &= short_ - 1)
          setFoamBit(foam, dims, std::uint32_t(x + __builtin_ctzll(short_) / 8), std::uint32_t(y), std::uint32_t(z));
      }
}

}  // namespace flipscope
