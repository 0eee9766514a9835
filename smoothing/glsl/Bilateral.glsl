// Depth-adaptive bilateral filter of the depth image (the bilateral Gaussian of screen-space
// fluid rendering, Green 2010, as the narrow-band paper of Oliveira and Paiva 2022 compares
// it), with a kernel of constant world-space size. Shared by the compute shader (Bilateral.comp)
// and the CPU reference (BilateralFilter.cpp); see smoothing/glsl/ScreenPass.glsl for the
// accessors and core/GlslShared.h for the rules.
//
// At a foreground pixel of depth z the kernel radius is R = worldRadius * focalPixels / z pixels
// (a world-space size seen at depth z), at most maxRadius. The spatial weight is a Gaussian of
// sigma = R / 2, lowered by its value at R so that it reaches 0 there: the kernel then changes
// continuously with depth (no pixel enters or leaves the support with a jump in weight). The
// range weight is a Gaussian of the depth difference with sigma sigmaDepth (the host sets it to
// the spatial sigma in world units). Only foreground pixels inside the image contribute;
// background pixels keep their input.

// bilateral (input 0: depth) -> depth: x the filtered depth, y the mask.
FS_FUNC vec4 bilateral(ivec2 p) {
  vec4 d = ssLoad(0u, p);
  if (d.y < 0.5f) return d;
  float z = d.x;
  float radius = ssPixelsAtDepth(S.worldRadius, z, S.maxRadius);
  // Below one pixel every neighbour lies on or outside the support: the kernel is the identity.
  if (!(radius > 1.0f)) return vec4(z, d.y, 0.0f, 0.0f);
  int n = int(radius);
  float invR2 = 1.0f / (radius * radius);
  float edge = exp(-2.0f);  // the spatial Gaussian (sigma = R / 2) at distance R
  float invTwoSigmaZ2 = 1.0f / (2.0f * S.sigmaDepth * S.sigmaDepth);
  float sum = 0.0f;
  float weights = 0.0f;
  for (int dy = -n; dy <= n; dy++) {
    for (int dx = -n; dx <= n; dx++) {
      ivec2 q = p + ivec2(dx, dy);
      if (!ssInside(q)) continue;
      float r2 = float(dx * dx + dy * dy) * invR2;
      if (r2 >= 1.0f) continue;
      vec4 s = ssLoad(0u, q);
      if (s.y < 0.5f) continue;
      float dz = s.x - z;
      float w = (exp(-2.0f * r2) - edge) * exp(-dz * dz * invTwoSigmaZ2);
      sum += w * s.x;
      weights += w;
    }
  }
  return vec4(sum / weights, d.y, 0.0f, 0.0f);
}
