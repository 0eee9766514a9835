#include "raycast/NearSphereMask.h"

#include <algorithm>
#include <array>
#include <vector>

#include "core/Error.h"
#include "streaming/BitBrickLayout.h"

namespace flipscope {
namespace {

/// A row of stored cells along x (at most 4 * ceil((128 + 2 * 8) / 4) = 144), x in the lowest
/// bit, with a word to spare so that reads past the end see zeros.
using StoredRow = std::array<std::uint64_t, 4>;

/// The row with bit i moved to bit i + d (d may be negative); bits leaving the row are dropped.
StoredRow shifted(const StoredRow& row, int d) {
  StoredRow out{};
  const int words = int(row.size());
  const int wordShift = (d >= 0 ? d : -d) / 64, bitShift = (d >= 0 ? d : -d) % 64;
  for (int w = 0; w < words; ++w) {
    std::uint64_t v = 0;
    if (d >= 0) {
      const int from = w - wordShift;
      if (from >= 0) v = row[from] << bitShift;
      if (bitShift && from - 1 >= 0) v |= row[from - 1] >> (64 - bitShift);
    } else {
      const int from = w + wordShift;
      if (from < words) v = row[from] >> bitShift;
      if (bitShift && from + 1 < words) v |= row[from + 1] << (64 - bitShift);
    }
    out[w] = v;
  }
  return out;
}

/// Bits [first, first + 64) of the row.
std::uint64_t bitsFrom(const StoredRow& row, std::uint32_t first) {
  const std::uint32_t w = first / 64, b = first % 64;
  std::uint64_t v = row[w] >> b;
  if (b && w + 1 < row.size()) v |= row[w + 1] << (64 - b);
  return v;
}

}  // namespace

std::size_t nearSphereMaskWords(std::uint32_t brickSize) {
  return std::size_t(brickSize) * brickSize * ((brickSize + 63) / 64);
}

void buildNearSphereMask(const glm::uvec4* bits, const glm::uvec4* foam, std::uint32_t brickSize,
                         std::uint32_t overlap, std::uint32_t reach, std::uint64_t* mask) {
  FLIPSCOPE_CHECK(reach <= overlap && overlap <= kMaxOverlap && brickSize <= 128,
                  "reach " << reach << " overlap " << overlap << " brick " << brickSize);
  const glm::uvec3 dims = bitBrickSubBrickDims(brickSize, overlap);
  const std::uint32_t storedY = dims.y * kSubBrickCells.y, storedZ = dims.z * kSubBrickCells.z;
  const std::uint32_t B = brickSize, W = (B + 63) / 64, k = reach;
  const std::uint64_t lastWordMask = B % 64 ? (std::uint64_t(1) << (B % 64)) - 1 : ~std::uint64_t(0);

  // 1. Per stored (y, z): the sphere cells of the row, dilated by k along x, cut to x in [0, B).
  std::vector<std::uint64_t> alongX(std::size_t(storedY) * storedZ * W);
  for (std::uint32_t sz = 0; sz < storedZ; ++sz)
    for (std::uint32_t sy = 0; sy < storedY; ++sy) {
      StoredRow row{};
      const std::uint32_t bit = ((sy & 3u) << 2u) | ((sz & 7u) << 4u);  // of x = 0 in its sub-brick
      for (std::uint32_t sx = 0; sx < dims.x; ++sx) {
        const std::uint32_t sub = sx + dims.x * ((sy >> 2u) + dims.y * (sz >> 3u));
        std::uint32_t four = ((&bits[sub].x)[bit >> 5u] >> (bit & 31u)) & 0xfu;
        if (foam) four &= ~((&foam[sub].x)[bit >> 5u] >> (bit & 31u));
        row[sx / 16] |= std::uint64_t(four & 0xfu) << ((sx % 16) * 4);
      }
      StoredRow dilated{};
      for (int d = -int(k); d <= int(k); ++d) {
        const StoredRow s = shifted(row, d);
        for (std::size_t w = 0; w < dilated.size(); ++w) dilated[w] |= s[w];
      }
      std::uint64_t* out = &alongX[(std::size_t(sz) * storedY + sy) * W];
      for (std::uint32_t w = 0; w < W; ++w) out[w] = bitsFrom(dilated, overlap + 64 * w);
      out[W - 1] &= lastWordMask;
    }

  // 2. Along y, for the stored z within k of the brick: rows y in [0, B).
  const std::uint32_t z0 = overlap - k, zCount = B + 2 * k;
  std::vector<std::uint64_t> alongY(std::size_t(zCount) * B * W, 0);
  for (std::uint32_t z = 0; z < zCount; ++z)
    for (std::uint32_t y = 0; y < B; ++y)
      for (std::uint32_t sy = y + overlap - k; sy <= y + overlap + k; ++sy)
        for (std::uint32_t w = 0; w < W; ++w)
          alongY[(std::size_t(z) * B + y) * W + w] |= alongX[(std::size_t(z0 + z) * storedY + sy) * W + w];

  // 3. Along z: the mask of z in [0, B).
  for (std::uint32_t z = 0; z < B; ++z)
    for (std::uint32_t y = 0; y < B; ++y)
      for (std::uint32_t w = 0; w < W; ++w) {
        std::uint64_t v = 0;
        for (std::uint32_t dz = 0; dz <= 2 * k; ++dz) v |= alongY[(std::size_t(z + dz) * B + y) * W + w];
        mask[(std::size_t(z) * B + y) * W + w] = v;
      }
}

std::size_t nearSphereGroupCount(std::uint32_t brickSize) {
  const std::size_t g = brickSize / kNearGroupCells;
  return g * g * g;
}

void nearSphereGroups(const std::uint64_t* mask, std::uint32_t brickSize, std::uint32_t* groups) {
  FLIPSCOPE_CHECK(brickSize % kNearGroupCells == 0 && brickSize <= 128, "brick " << brickSize);
  const std::uint32_t B = brickSize, W = (B + 63) / 64, G = B / kNearGroupCells;
  std::fill(groups, groups + (nearSphereGroupCount(B) + 31) / 32, 0u);
  for (std::uint32_t gz = 0; gz < G; ++gz)
    for (std::uint32_t gy = 0; gy < G; ++gy) {
      std::array<std::uint64_t, 2> rows{};  // the group row's 4 x 4 mask rows, or-ed
      for (std::uint32_t z = gz * 4; z < gz * 4 + 4; ++z)
        for (std::uint32_t y = gy * 4; y < gy * 4 + 4; ++y)
          for (std::uint32_t w = 0; w < W; ++w) rows[w] |= mask[(std::size_t(z) * B + y) * W + w];
      for (std::uint32_t gx = 0; gx < G; ++gx) {
        if (((rows[gx / 16] >> ((gx % 16) * 4)) & 0xfu) == 0u) continue;
        const std::size_t i = gx + std::size_t(G) * (gy + std::size_t(G) * gz);
        groups[i / 32] |= 1u << (i % 32);
      }
    }
}

}  // namespace flipscope
