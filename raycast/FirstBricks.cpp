#include "raycast/FirstBricks.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

namespace flipscope {

std::uint32_t firstBrickStride(std::uint32_t width, std::uint32_t height) {
  const double pixels = double(width) * double(height);
  return std::max(1u, std::uint32_t(std::ceil(std::sqrt(pixels / double(kFirstBrickRays)))));
}

namespace {

/// The brick of `octree`'s table that the ray from `o` along `d` (in bricks) enters first, or -1.
std::int64_t firstBrickAlong(glm::dvec3 o, glm::dvec3 d, glm::uvec3 grid, const PresenceOctree& octree) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double enter = 0, leave = kInf;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0) {
      if (o[a] < 0 || o[a] > double(grid[a])) return -1;
      continue;
    }
    const double t0 = -o[a] / d[a], t1 = (double(grid[a]) - o[a]) / d[a];
    enter = std::max(enter, std::min(t0, t1));
    leave = std::min(leave, std::max(t0, t1));
  }
  if (enter > leave) return -1;
  const glm::dvec3 p = o + enter * d;
  int cell[3], step[3];
  double next[3], delta[3];
  for (int a = 0; a < 3; ++a) {
    cell[a] = std::clamp(int(std::floor(p[a])), 0, int(grid[a]) - 1);
    step[a] = d[a] < 0 ? -1 : 1;
    delta[a] = d[a] == 0 ? kInf : 1 / std::abs(d[a]);
    const double boundary = double(cell[a] + (step[a] > 0 ? 1 : 0));
    next[a] = d[a] == 0 ? kInf : (boundary - o[a]) / d[a];
  }
  for (;;) {
    const std::int64_t brick = octree.find(glm::uvec3(cell[0], cell[1], cell[2]));
    if (brick >= 0) return brick;
    const int a = next[0] <= next[1] ? (next[0] <= next[2] ? 0 : 2) : (next[1] <= next[2] ? 1 : 2);
    if (next[a] > leave) return -1;
    cell[a] += step[a];
    if (cell[a] < 0 || cell[a] >= int(grid[a])) return -1;
    next[a] += delta[a];
  }
}

}  // namespace

std::vector<std::uint32_t> firstBricksAlongRays(const Camera& camera, std::uint32_t width, std::uint32_t height,
                                             std::uint32_t stride, const StoreHeader& header,
                                             const PresenceOctree& octree) {
  if (octree.nodes.empty() || stride == 0) return {};
  const double brickWorld = header.cellSize * double(header.brickSize);
  const glm::dvec3 o = (camera.eye - header.origin) / brickWorld;
  const std::uint32_t columns = (width + stride - 1) / stride, rows = (height + stride - 1) / stride;
  tbb::enumerable_thread_specific<std::vector<std::uint32_t>> found;
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, rows), [&](const tbb::blocked_range<std::uint32_t>& r) {
    std::vector<std::uint32_t>& bricks = found.local();
    for (std::uint32_t row = r.begin(); row != r.end(); ++row) {
      const std::uint32_t y = std::min(height - 1, row * stride + stride / 2);
      for (std::uint32_t column = 0; column < columns; ++column) {
        const std::uint32_t x = std::min(width - 1, column * stride + stride / 2);
        const std::int64_t brick = firstBrickAlong(o, camera.pixelRay(x, y, width, height), header.brickGrid, octree);
        if (brick >= 0 && (bricks.empty() || bricks.back() != std::uint32_t(brick))) bricks.push_back(std::uint32_t(brick));
      }
    }
  });
  std::vector<std::uint32_t> all;
  for (const auto& bricks : found) all.insert(all.end(), bricks.begin(), bricks.end());
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  return all;
}

}  // namespace flipscope
