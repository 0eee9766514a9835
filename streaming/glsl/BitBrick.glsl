// Bit-brick layout (Reichl et al. 2014 §3.1, §3.2, §4.2), shared by C++ (streaming/BitBrickLayout.h)
// and GLSL; see core/GlslShared.h for the rules. The CPU writes bricks in this layout
// (streaming/BitBrick.h), the GPU reads them with these functions.
//
// Cells. A brick has B^3 cells (B = brickSize in {32, 64, 128}) plus an overlap border of
// n = overlap cells (0..8) on every side: brick-local cell coordinates c in [-n, B+n) per axis
// are stored, at stored coordinate s = c + n.
// Sub-bricks. Stored cells are grouped into sub-bricks of 4x4x8 cells, one uvec4 each.
// Sub-brick (s.x>>2, s.y>>2, s.z>>3) has index a + sx*(b + sy*c) with dims
// (sx, sy, sz) = (ceil((B+2n)/4), ceil((B+2n)/4), ceil((B+2n)/8)); padding cells past B+n stay 0.
// Inside a sub-brick, bit i = (s.x&3) + 4*(s.y&3) + 16*(s.z&7) lives in word i>>5, bit i&31:
// words 0,1 hold the lower 4x4x4 half, words 2,3 the upper (foam density = popcount of two
// words, §3.5, Fig. 7).
// Attributes (§3.2). The attribute of set cell i of a sub-brick sits at
// base + (set bits below i across the four words), where base is the sub-brick's attribute
// offset (streaming/BitBrick.h: 32-bit row offset + 16-bit sub-brick offset).
// Mipmaps (§4.2). Level k >= 1 holds one bit per block of (4<<(k-1)) x (4<<(k-1)) x (8<<(k-1))
// stored cells, aligned to stored coordinate 0 (level 1: one bit per sub-brick, level k+1 halves
// level k's dims, rounding up, until 1x1x1). Block (x,y,z) of level k is bit
// x + dx*(y + dy*z) of that level, packed in 32-bit words (word bit>>5, bit bit&31); levels are
// concatenated from level 1 at word offset bitBrickMipWordOffset(k, ...). A block's bit is set
// when a set stored cell lies within `dilation` cells (per axis) of the block, so that a ray in
// a block whose bit is clear meets no sphere of radius + jitter <= dilation.

// Sub-bricks per axis for a brick of brickSize^3 cells with an `overlap`-cell border.
FS_FUNC uvec3 bitBrickSubBrickDims(uint brickSize, uint overlap) {
  uint stored = brickSize + 2u * overlap;
  return uvec3((stored + 3u) / 4u, (stored + 3u) / 4u, (stored + 7u) / 8u);
}

// Index of the sub-brick at sub-brick coordinates `c` (each below `dims`), and back.
FS_FUNC uint bitBrickSubBrickLinear(uvec3 c, uvec3 dims) { return c.x + dims.x * (c.y + dims.y * c.z); }
FS_FUNC uvec3 bitBrickSubBrickCoord(uint index, uvec3 dims) {
  return uvec3(index % dims.x, (index / dims.x) % dims.y, index / (dims.x * dims.y));
}

// Index into the brick's uvec4 array of the sub-brick holding brick-local `cell` in [-n, B+n).
FS_FUNC uint bitBrickSubBrickIndex(ivec3 cell, uint brickSize, uint overlap) {
  uvec3 s = uvec3(cell + ivec3(int(overlap)));
  return bitBrickSubBrickLinear(uvec3(s.x >> 2u, s.y >> 2u, s.z >> 3u), bitBrickSubBrickDims(brickSize, overlap));
}

// Bit index (0..127) of brick-local `cell` inside its sub-brick.
FS_FUNC uint bitBrickBitIndex(ivec3 cell, uint overlap) {
  uvec3 s = uvec3(cell + ivec3(int(overlap)));
  return (s.x & 3u) + 4u * (s.y & 3u) + 16u * (s.z & 7u);
}

FS_FUNC bool bitBrickBitSet(uvec4 subBrick, uint bitIndex) {
  return ((subBrick[int(bitIndex >> 5u)] >> (bitIndex & 31u)) & 1u) != 0u;
}

// Set cells of the lower (upper = 0) or upper (upper = 1) 4x4x4 half of a sub-brick: the density
// of that block times 64 (§3.5, Fig. 7: the popcount of two words).
FS_FUNC uint bitBrickHalfCount(uvec4 subBrick, uint upper) {
  if (upper == 0u) return uint(bitCount(subBrick.x) + bitCount(subBrick.y));
  return uint(bitCount(subBrick.z) + bitCount(subBrick.w));
}

// §3.2: base + countbits(v & ((1 << i) - 1)), extended over the four words of a sub-brick.
FS_FUNC uint bitBrickAttributeOffset(uint base, uvec4 subBrick, uint bitIndex) {
  uint word = bitIndex >> 5u;
  uint below = 0u;
  if (word > 0u) below += uint(bitCount(subBrick.x));
  if (word > 1u) below += uint(bitCount(subBrick.y));
  if (word > 2u) below += uint(bitCount(subBrick.z));
  uint mask = (1u << (bitIndex & 31u)) - 1u;
  return base + below + uint(bitCount(subBrick[int(word)] & mask));
}

// Blocks per axis of mip level `level` (>= 1).
FS_FUNC uvec3 bitBrickMipDims(uint level, uint brickSize, uint overlap) {
  uvec3 dims = bitBrickSubBrickDims(brickSize, overlap);
  for (uint k = 1u; k < level; k++) dims = (dims + uvec3(1u)) / 2u;
  return dims;
}

// Number of mip levels: levels 1..count, the last one 1x1x1.
FS_FUNC uint bitBrickMipLevelCount(uint brickSize, uint overlap) {
  uvec3 dims = bitBrickSubBrickDims(brickSize, overlap);
  uint count = 1u;
  while (dims.x > 1u || dims.y > 1u || dims.z > 1u) {
    dims = (dims + uvec3(1u)) / 2u;
    count++;
  }
  return count;
}

// 32-bit words one level occupies.
FS_FUNC uint bitBrickMipLevelWords(uint level, uint brickSize, uint overlap) {
  uvec3 dims = bitBrickMipDims(level, brickSize, overlap);
  return (dims.x * dims.y * dims.z + 31u) / 32u;
}

// Word offset of level `level` in the brick's mip array; level count + 1 gives the total size.
FS_FUNC uint bitBrickMipWordOffset(uint level, uint brickSize, uint overlap) {
  uint offset = 0u;
  for (uint k = 1u; k < level; k++) offset += bitBrickMipLevelWords(k, brickSize, overlap);
  return offset;
}

// Bit index of block `block` within level `level`.
FS_FUNC uint bitBrickMipBitIndex(uvec3 block, uint level, uint brickSize, uint overlap) {
  uvec3 dims = bitBrickMipDims(level, brickSize, overlap);
  return block.x + dims.x * (block.y + dims.y * block.z);
}
