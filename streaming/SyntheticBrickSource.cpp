// Synthetic wave-tank bricks for the Streamer's, the renderer's and the pipeline's tests and
// benchmarks.
#include "streaming/SyntheticBrickSource.h"

#include <algorithm>
#include <cmath>

#include "core/Error.h"
#include "core/Morton.h"
#include "streaming/Jitter.h"

namespace flipscope {

SyntheticBrickSource::SyntheticBrickSource(std::uint32_t brickSize, glm::uvec3 grid, int frames, double fill)
    : mBrickSize(brickSize), mGrid(grid), mFrames(frames), mFill(fill) {
  FLIPSCOPE_CHECK(grid.x < kMortonAxisLimit && grid.y < kMortonAxisLimit && grid.z < kMortonAxisLimit,
                  "synthetic brick grid " << grid.x << "x" << grid.y << "x" << grid.z);
  mHeader.brickSize = brickSize;
  mHeader.cellSize = kCellSize;
  mHeader.brickGrid = grid;
  mHeader.origin = glm::dvec3(-0.5 * grid.x * brickSize * kCellSize, -0.5 * grid.y * brickSize * kCellSize, 0.0);
  mHeader.attribute = AttributeKind::Speed;
  mHeader.attributeName = "speed";
  mHeader.particleSpacing = 0;
}

std::vector<int> SyntheticBrickSource::frames() const {
  std::vector<int> out;
  for (int f = 0; f < mFrames; ++f) out.push_back(f);
  return out;
}

std::string SyntheticBrickSource::name() const {
  return "synthetic wave tank (" + std::to_string(mGrid.x) + "x" + std::to_string(mGrid.y) + "x" +
         std::to_string(mGrid.z) + " bricks of " + std::to_string(mBrickSize) + ")";
}

double SyntheticBrickSource::surfaceHeight(int frame, double x, double y) const {
  double size = double(mBrickSize);
  double extent = double(mGrid.z) * size;
  double phase = 0.15 * frame;
  return extent * (0.45 + 0.2 * std::sin(x / (2.3 * size) + phase) * std::cos(y / (1.7 * size) - 0.5 * phase));
}

std::shared_ptr<const DecodedBrick> SyntheticBrickSource::decode(const BrickKey& key) const {
  if (key.frame < 0 || key.frame >= mFrames) return nullptr;
  if (key.coord.x >= mGrid.x || key.coord.y >= mGrid.y || key.coord.z >= mGrid.z) return nullptr;
  const std::uint32_t b = mBrickSize;
  const glm::uvec3 origin = key.coord * b;
  const std::uint32_t threshold = std::uint32_t(mFill * 4294967295.0);
  auto brick = std::make_shared<DecodedBrick>();
  std::vector<double> heights(std::size_t(b) * b);
  for (std::uint32_t y = 0; y < b; ++y)
    for (std::uint32_t x = 0; x < b; ++x) heights[x + b * y] = surfaceHeight(key.frame, origin.x + x, origin.y + y);
  for (std::uint32_t z = 0; z < b; ++z)
    for (std::uint32_t y = 0; y < b; ++y)
      for (std::uint32_t x = 0; x < b; ++x) {
        if (double(origin.z + z) >= heights[x + b * y]) continue;
        glm::uvec2 hash =
            tea(glm::uvec2(mortonEncode3(origin.x + x, origin.y + y, origin.z + z), std::uint32_t(key.frame)), 4);
        if (hash.x > threshold) continue;
        std::uint32_t count = 1 + (hash.y & 1);
        brick->cells.push_back(x + b * (y + b * z));
        brick->counts.push_back(count);
        for (std::uint32_t p = 0; p < count; ++p) brick->attributes.push_back(std::uint16_t(hash.y >> (16 * p)));
      }
  if (brick->cells.empty()) return nullptr;
  return brick;
}

std::vector<glm::uvec3> SyntheticBrickSource::bricks(int frame) const {
  std::vector<glm::uvec3> out;
  if (frame < 0 || frame >= mFrames) return out;
  const double b = double(mBrickSize);
  for (std::uint32_t z = 0; z < mGrid.z; ++z)
    for (std::uint32_t y = 0; y < mGrid.y; ++y)
      for (std::uint32_t x = 0; x < mGrid.x; ++x) {
        // A brick is non-empty when the surface rises above its floor somewhere (sampled on its columns).
        bool below = false;
        for (double sy = 0; sy < b && !below; sy += 1)
          for (double sx = 0; sx < b && !below; sx += 1) below = surfaceHeight(frame, x * b + sx, y * b + sy) > z * b;
        if (below) out.push_back({x, y, z});
      }
  return out;
}

std::shared_ptr<const FrameIndex> SyntheticBrickSource::frame(int frame) const {
  if (!hasFrame(frame)) throw InputError(name() + ": no frame " + std::to_string(frame));
  {
    std::lock_guard lock(mMutex);
    if (auto it = mIndices.find(frame); it != mIndices.end()) return it->second;
  }
  // The candidates from the analytic surface, decoded: only bricks that draw particles are
  // listed, in Morton order, as a store's frame file would list them.
  std::vector<std::pair<std::uint32_t, glm::uvec3>> candidates;
  for (glm::uvec3 c : bricks(frame)) candidates.emplace_back(mortonEncode3(c.x, c.y, c.z), c);
  std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  auto index = std::make_shared<FrameIndex>();
  index->frame = frame;
  std::vector<std::uint32_t> codes;
  for (const auto& [code, coord] : candidates) {
    const auto brick = decode({frame, coord});
    if (!brick) continue;
    BrickRecord record;
    record.coord = coord;
    record.particles = std::uint32_t(brick->particleCount());
    record.cells = std::uint32_t(brick->cells.size());
    index->bricks.push_back(record);
    index->stats.particles += record.particles;
    codes.push_back(code);
  }
  index->stats.attributeMax = 1.0f;  // speeds are synthetic: quantized 65535 reads as 1
  index->octree = PresenceOctree::build(codes, std::max({mGrid.x, mGrid.y, mGrid.z}));
  std::lock_guard lock(mMutex);
  return mIndices.emplace(frame, std::move(index)).first->second;
}

}  // namespace flipscope
