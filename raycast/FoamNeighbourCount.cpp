#include "raycast/FoamNeighbourCount.h"

#include <algorithm>
#include <cmath>

#include "core/Error.h"
#include "raycast/CpuRaycastKernel.h"

namespace flipscope {

void classifyBrickFoam(const glm::uvec4* subBricks, glm::uvec4* foam, const FoamClassifyParams& params,
                       FoamNeighbourScratch& scratch) {
  if (params.sphere.z < 0.5f) return;  // the uploaded bits as they are
  const std::uint32_t brickSize = params.brick.x, overlap = params.brick.y;
  const glm::uvec3 dims = glsl::bitBrickSubBrickDims(brickSize, overlap);
  FLIPSCOPE_CHECK(params.brick.z == dims.x * dims.y * dims.z, params.brick.z << " sub-bricks");
  const float radius = params.sphere.x;
  const int reach = int(std::floor(radius));
  const float needed = params.sphere.y * float(glsl::FoamKernel{params, nullptr}.fcNeighbourhoodSize(radius));
  // The stored cells, with `reach` empty cells around: beyond the stored cells they count as
  // empty (fcStoredCellSet). The grid spans the sub-bricks, whose last ones may reach past them.
  const int stored = int(brickSize + 2 * overlap);
  const glm::ivec3 span = glm::ivec3(dims * glm::uvec3(4, 4, 8)) + 2 * reach;
  const std::size_t row = std::size_t(span.x), plane = row * std::size_t(span.y);
  scratch.cells.assign(plane * std::size_t(span.z), 0);
  auto at = [&](int x, int y, int z) { return std::size_t(x + reach) + row * std::size_t(y + reach) + plane * std::size_t(z + reach); };
  // Calls f(sub-brick, word, bit, cell) for every set cell of the brick.
  auto forEachSetCell = [&](auto f) {
    for (std::uint32_t s = 0; s < params.brick.z; ++s) {
      const glm::uvec4 bits = subBricks[s];
      if ((bits.x | bits.y | bits.z | bits.w) == 0u) continue;
      const glm::ivec3 origin = glm::ivec3(glsl::bitBrickSubBrickCoord(s, dims) * glm::uvec3(4, 4, 8));
      for (int w = 0; w < 4; ++w) {
        for (std::uint32_t word = bits[w]; word != 0; word &= word - 1) {
          const std::uint32_t bit = std::uint32_t(w) * 32u + std::uint32_t(__builtin_ctz(word));
          f(s, w, bit, origin + glm::ivec3(int(bit & 3u), int((bit >> 2) & 3u), int(bit >> 4)));
        }
      }
    }
  };
  forEachSetCell([&](std::uint32_t, int, std::uint32_t, glm::ivec3 c) {
    if (c.x < stored && c.y < stored && c.z < stored) scratch.cells[at(c.x, c.y, c.z)] = 1;
  });
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
  forEachSetCell([&](std::uint32_t s, int w, std::uint32_t bit, glm::ivec3 c) {
    const std::uint8_t* cell = cells + at(c.x, c.y, c.z);
    // Counted 8 neighbours at a time: the decision is the same, the tests fewer.
    std::uint32_t count = 0;
    std::size_t i = 0;
    for (; i + 8 <= neighbours && count < enough; i += 8)
      for (std::size_t j = i; j < i + 8; ++j) count += cell[delta[j]];
    for (; i < neighbours && count < enough; ++i) count += cell[delta[i]];
    if (count < enough) foam[s][w] |= 1u << (bit & 31u);
  });
}

}  // namespace flipscope
