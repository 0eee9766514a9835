// Brick mipmaps (Reichl et al. 2014 §4.2): level 1 tests each sub-brick's dilated box against the
// bits of the sub-bricks it reaches with one masked AND per word; coarser levels OR their 2x2x2
// children.
#include "streaming/BrickMipmap.h"

#include "core/Error.h"

namespace flipscope {
namespace {

// Bits of a sub-brick at sub-brick offset `offset` from a target sub-brick whose cells lie
// within `dilation` of the target's box.
glm::uvec4 dilationMask(glm::ivec3 offset, int dilation) {
  auto axisBits = [dilation](int offsetInBlocks, int blockCells) {
    std::uint32_t bits = 0;
    for (int c = 0; c < blockCells; ++c) {
      int relative = offsetInBlocks * blockCells + c;  // cell position relative to the target's low corner
      if (relative >= -dilation && relative < blockCells + dilation) bits |= 1u << c;
    }
    return bits;
  };
  std::uint32_t xBits = axisBits(offset.x, 4), yBits = axisBits(offset.y, 4), zBits = axisBits(offset.z, 8);
  glm::uvec4 mask(0);
  for (int z = 0; z < 8; ++z)
    for (int y = 0; y < 4; ++y)
      if ((zBits >> z & 1u) && (yBits >> y & 1u)) {
        int shift = 4 * y + 16 * z;
        mask[shift >> 5] |= xBits << (shift & 31);
      }
  return mask;
}

}  // namespace

std::vector<std::uint32_t> buildBrickMipmap(const BitBrick& brick, std::uint32_t dilation) {
  FLIPSCOPE_CHECK(dilation <= kMaxMipDilation, "dilation=" << dilation);
  const std::uint32_t size = brick.brickSize, overlap = brick.overlap;
  const std::uint32_t levels = bitBrickMipLevelCount(size, overlap);
  std::vector<std::uint32_t> mip(bitBrickMipWordOffset(levels + 1, size, overlap), 0);
  auto setBit = [&mip](std::uint32_t wordOffset, std::uint32_t bit) {
    mip[wordOffset + (bit >> 5)] |= 1u << (bit & 31);
  };
  auto isBitSet = [&mip](std::uint32_t wordOffset, std::uint32_t bit) {
    return (mip[wordOffset + (bit >> 5)] >> (bit & 31) & 1u) != 0;
  };

  // Level 1: one bit per sub-brick.
  const glm::ivec3 dims(brick.subBrickDims());
  const int d = int(dilation);
  const glm::ivec3 reach((d + 3) / 4, (d + 3) / 4, (d + 7) / 8);
  std::vector<glm::uvec4> masks;
  for (int k = -reach.z; k <= reach.z; ++k)
    for (int j = -reach.y; j <= reach.y; ++j)
      for (int i = -reach.x; i <= reach.x; ++i) masks.push_back(dilationMask({i, j, k}, d));
  const glm::ivec3 span = 2 * reach + 1;
  for (int c = 0; c < dims.z; ++c)
    for (int b = 0; b < dims.y; ++b)
      for (int a = 0; a < dims.x; ++a) {
        bool occupied = false;
        for (int k = -reach.z; k <= reach.z && !occupied; ++k)
          for (int j = -reach.y; j <= reach.y && !occupied; ++j)
            for (int i = -reach.x; i <= reach.x && !occupied; ++i) {
              glm::ivec3 source(a + i, b + j, c + k);
              if (glm::any(glm::lessThan(source, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(source, dims)))
                continue;
              glm::uvec4 bits = brick.subBricks[source.x + dims.x * (source.y + dims.y * source.z)];
              glm::uvec4 mask = masks[(i + reach.x) + span.x * ((j + reach.y) + span.y * (k + reach.z))];
              occupied = ((bits.x & mask.x) | (bits.y & mask.y) | (bits.z & mask.z) | (bits.w & mask.w)) != 0;
            }
        if (occupied) setBit(0, std::uint32_t(a + dims.x * (b + dims.y * c)));
      }

  // Levels 2..: OR of the 2x2x2 children.
  for (std::uint32_t level = 2; level <= levels; ++level) {
    const glm::uvec3 fine = bitBrickMipDims(level - 1, size, overlap), coarse = bitBrickMipDims(level, size, overlap);
    const std::uint32_t fineOffset = bitBrickMipWordOffset(level - 1, size, overlap);
    const std::uint32_t coarseOffset = bitBrickMipWordOffset(level, size, overlap);
    for (std::uint32_t z = 0; z < coarse.z; ++z)
      for (std::uint32_t y = 0; y < coarse.y; ++y)
        for (std::uint32_t x = 0; x < coarse.x; ++x) {
          bool occupied = false;
          for (std::uint32_t child = 0; child < 8 && !occupied; ++child) {
            glm::uvec3 f(2 * x + (child & 1), 2 * y + (child >> 1 & 1), 2 * z + (child >> 2));
            if (f.x < fine.x && f.y < fine.y && f.z < fine.z)
              occupied = isBitSet(fineOffset, bitBrickMipBitIndex(f, level - 1, size, overlap));
          }
          if (occupied) setBit(coarseOffset, bitBrickMipBitIndex({x, y, z}, level, size, overlap));
        }
  }
  return mip;
}

}  // namespace flipscope
