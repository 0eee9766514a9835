// The narrow-range filter of Truong and Yuksel 2018 ("A Narrow-Range Filter for Screen-Space
// Fluid Rendering", [TY18] of Oliveira and Paiva 2022): a Gaussian of adaptive, world-space size
// that smooths each pixel only with the depths in a narrow range around its own, treating the
// samples outside it separately (in front: ignored; behind: clamped), so that the foreground and
// the background surfaces are smoothed separately and depth discontinuities survive. Shared by
// the compute shader (NarrowRange.comp) and the CPU reference (NarrowRangeFilter.cpp); see
// smoothing/glsl/ScreenPass.glsl for the accessors and core/GlslShared.h for the rules.
//
// Depth z grows away from the eye. For a foreground pixel of depth z:
//  - radius R = worldRadius * focalPixels / z pixels, at most maxRadius; Gaussian weights with
//    sigma = R / 3, lowered by their value at R so that they reach 0 there (the kernel changes
//    continuously with depth);
//  - the range starts as [z - delta, z + delta]; a sample nearer than it (another surface in
//    front) is ignored, a sample behind it (a surface behind, or the background) counts as
//    z + mu with its full weight, which rounds the foreground off at its silhouette instead of
//    pulling it towards the background;
//  - bias correction: when a sample is ignored its mirror image through the pixel is ignored
//    too, so the kernel stays symmetric and a sloped surface is not pulled towards one side;
//  - dynamic range: each sample inside the range widens it to cover [z_q - delta, z_q + delta],
//    so that a steep surface whose depth leaves the initial range stays in it;
//  - the 1D pass walks outwards along one axis and keeps one range per side; the 2D pass walks
//    outwards ring by ring with one range, pairing each sample with its mirror image.
// Samples outside the image are ignored (with their mirror image); background pixels keep their
// input.

// The sample at q for a pixel of depth z whose range is [range.x, range.y]: x the depth it
// contributes, y its kind: 0 ignored (outside the image, or in front of the range), 1 clamped
// (behind the range, or background: contributes z + mu), 2 inside the range.
FS_FUNC vec2 nrSample(ivec2 q, float z, vec2 range) {
  if (!ssInside(q)) return vec2(0.0f, 0.0f);
  vec4 s = ssLoad(0u, q);
  if (s.y < 0.5f) return vec2(z + S.clampOffset, 1.0f);
  if (s.x < range.x) return vec2(0.0f, 0.0f);
  if (s.x > range.y) return vec2(z + S.clampOffset, 1.0f);
  return vec2(s.x, 2.0f);
}

// The range [range.x, range.y] after sample `s` (of nrSample): widened to cover
// [s.x - delta, s.x + delta] when the sample is inside it (dynamic range), as it was otherwise.
FS_FUNC vec2 nrWiden(vec2 range, vec2 s) {
  if (s.y < 1.5f) return range;
  return vec2(min(range.x, s.x - S.threshold), max(range.y, s.x + S.threshold));
}

// The sums (x: weighted depths, y: weights) after the pair of mirror samples a, b (of nrSample)
// of weight w: both count, or neither when one is ignored (bias correction).
FS_FUNC vec2 nrAddPair(vec2 sums, float w, vec2 a, vec2 b) {
  if (a.y < 0.5f || b.y < 0.5f) return sums;
  return vec2(sums.x + w * (a.x + b.x), sums.y + 2.0f * w);
}

// narrowRange1D (input 0: depth) -> depth: one separable pass along (axisX, axisY).
FS_FUNC vec4 narrowRange1D(ivec2 p) {
  vec4 d = ssLoad(0u, p);
  if (d.y < 0.5f) return d;
  float z = d.x;
  float radius = ssPixelsAtDepth(S.worldRadius, z, S.maxRadius);
  // Below one pixel every neighbour lies on or outside the support: the kernel is the identity.
  if (!(radius > 1.0f)) return vec4(z, d.y, 0.0f, 0.0f);
  int n = int(radius);
  ivec2 axis = ivec2(S.axisX, S.axisY);
  float invR2 = 1.0f / (radius * radius);
  float edge = exp(-4.5f);                           // the Gaussian (sigma = R / 3) at distance R
  vec2 sums = vec2((1.0f - edge) * z, 1.0f - edge);  // x: weighted depths, y: weights
  vec2 rangeA = vec2(z - S.threshold, z + S.threshold);  // near and far end, the + axis side
  vec2 rangeB = rangeA;                                  // the - axis side
  for (int k = 1; k <= n; k++) {
    float w = max(exp(-4.5f * float(k * k) * invR2) - edge, 0.0f);
    vec2 a = nrSample(p + k * axis, z, rangeA);
    vec2 b = nrSample(p - k * axis, z, rangeB);
    rangeA = nrWiden(rangeA, a);
    rangeB = nrWiden(rangeB, b);
    sums = nrAddPair(sums, w, a, b);
  }
  return vec4(sums.x / sums.y, d.y, 0.0f, 0.0f);
}

// narrowRange2D (input 0: depth) -> depth: the full 2D filter, rings of growing Chebyshev
// distance k; each ring is visited as 4k pairs of mirror images (its upper row and right column,
// and their reflections through p).
FS_FUNC vec4 narrowRange2D(ivec2 p) {
  vec4 d = ssLoad(0u, p);
  if (d.y < 0.5f) return d;
  float z = d.x;
  float radius = ssPixelsAtDepth(S.worldRadius, z, S.maxRadius);
  if (!(radius > 1.0f)) return vec4(z, d.y, 0.0f, 0.0f);
  int n = int(radius);
  float invR2 = 1.0f / (radius * radius);
  float edge = exp(-4.5f);
  vec2 sums = vec2((1.0f - edge) * z, 1.0f - edge);
  vec2 range = vec2(z - S.threshold, z + S.threshold);
  for (int k = 1; k <= n; k++) {
    for (int j = 0; j < 4 * k; j++) {
      ivec2 o = j < 2 * k + 1 ? ivec2(j - k, k) : ivec2(k, j - 3 * k);
      float r2 = float(o.x * o.x + o.y * o.y) * invR2;
      if (r2 >= 1.0f) continue;  // a corner outside the support
      float w = exp(-4.5f * r2) - edge;
      vec2 a = nrSample(p + o, z, range);
      vec2 b = nrSample(p - o, z, range);
      range = nrWiden(nrWiden(range, a), b);
      sums = nrAddPair(sums, w, a, b);
    }
  }
  return vec4(sums.x / sums.y, d.y, 0.0f, 0.0f);
}
