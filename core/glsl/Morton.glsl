// Morton (Z-order) codes of 3D coordinates, 10 bits per axis, x in the lowest bit.
// Shared by C++ (core/Morton.h) and GLSL; see core/GlslShared.h for the rules.
// Used for brick order in the store and octree (preprocess), and for jitter seeds (streaming).

// Spreads the low 10 bits of v so that bit i moves to bit 3i.
FS_FUNC uint mortonSpread3(uint v) {
  v &= 0x3ffu;
  v = (v | (v << 16u)) & 0x030000ffu;
  v = (v | (v << 8u)) & 0x0300f00fu;
  v = (v | (v << 4u)) & 0x030c30c3u;
  v = (v | (v << 2u)) & 0x09249249u;
  return v;
}

// Inverse of mortonSpread3: gathers every third bit.
FS_FUNC uint mortonCompact3(uint v) {
  v &= 0x09249249u;
  v = (v | (v >> 2u)) & 0x030c30c3u;
  v = (v | (v >> 4u)) & 0x0300f00fu;
  v = (v | (v >> 8u)) & 0x030000ffu;
  v = (v | (v >> 16u)) & 0x3ffu;
  return v;
}

// 30-bit Morton code of (x, y, z), each < 1024.
FS_FUNC uint mortonEncode3(uint x, uint y, uint z) {
  return mortonSpread3(x) | (mortonSpread3(y) << 1u) | (mortonSpread3(z) << 2u);
}

FS_FUNC uvec3 mortonDecode3(uint code) {
  return uvec3(mortonCompact3(code), mortonCompact3(code >> 1u), mortonCompact3(code >> 2u));
}
