// Per-cell jitter of quantized particle positions (Reichl et al. 2014 §3.2.2), shared by C++
// (streaming/Jitter.h) and GLSL; see core/GlslShared.h for the rules. Requires
// core/glsl/Morton.glsl before it. TEA hash after Zafar, Olano, Curtis, "GPU Random Numbers via
// the Tiny Encryption Algorithm", HPG 2010 (key constants of their GPU snippet).
//
// Seeding. Global cell coordinates reach 2^17 while mortonEncode3 takes 10 bits per axis, so
// the cell is split into low = c & 1023 and high = c >> 10 (each < 1024, coordinates < 2^20).
// The three hashes are tea((morton(low), key_k), kJitterTeaRounds).x for axes k = 0, 1, 2 with
// key_k = morton(high) * 0x27d4eb2d ^ (3 * timeStep + k). Domains below 1024 cells per axis
// have high = 0 and key_k = 3 * timeStep + k.

const uint kJitterTeaRounds = 6u;  // 4 rounds leave neighbouring cells' offsets correlated (0.28)

// TEA with `rounds` rounds on the pair v (Zafar et al. 2010).
FS_FUNC uvec2 tea(uvec2 v, uint rounds) {
  uint v0 = v.x;
  uint v1 = v.y;
  uint sum = 0u;
  for (uint n = 0u; n < rounds; n++) {
    sum += 0x9e3779b9u;
    v0 += ((v1 << 4u) + 0xa341316cu) ^ (v1 + sum) ^ ((v1 >> 5u) + 0xc8013ea4u);
    v1 += ((v0 << 4u) + 0xad90777du) ^ (v0 + sum) ^ ((v0 >> 5u) + 0x7e95761eu);
  }
  return uvec2(v0, v1);
}

// Maps a hash to [-maxJitter, maxJitter) exactly the same on both sides: the top 24 bits times
// 2^-23 minus 1 are exact in float, only the final product rounds.
FS_FUNC float jitterFromHash(uint hash, float maxJitter) {
  return (float(hash >> 8u) * 1.1920928955078125e-7f - 1.0f) * maxJitter;
}

// Offset in cells, each component in [-maxJitter, maxJitter), of the particle in global cell
// `globalCell` (< 2^20 per axis) at time step `timeStep`.
FS_FUNC vec3 cellJitter(uvec3 globalCell, uint timeStep, float maxJitter) {
  uint low = mortonEncode3(globalCell.x & 1023u, globalCell.y & 1023u, globalCell.z & 1023u);
  uint high = mortonEncode3(globalCell.x >> 10u, globalCell.y >> 10u, globalCell.z >> 10u);
  uint key = high * 0x27d4eb2du;
  uint step3 = 3u * timeStep;
  return vec3(jitterFromHash(tea(uvec2(low, key ^ step3), kJitterTeaRounds).x, maxJitter),
              jitterFromHash(tea(uvec2(low, key ^ (step3 + 1u)), kJitterTeaRounds).x, maxJitter),
              jitterFromHash(tea(uvec2(low, key ^ (step3 + 2u)), kJitterTeaRounds).x, maxJitter));
}
