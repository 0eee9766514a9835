// Screen-space curvature flow (van der Laan, Green, Sainz 2009, "Screen Space Fluid Rendering
// with Curvature Flow", Sec. 5.3.2): the depth moves by explicit Euler steps of dz/dt = H (eq.
// 5.1), H the mean curvature of eq. 5.6 with the paper's Cx, Cy and D (eq. 5.4-5.8, the terms
// in Wx, Wy neglected as the paper does). Shared by the compute shader (CurvatureFlow.comp) and
// the CPU reference (CurvatureFlowFilter.cpp); see smoothing/glsl/ScreenPass.glsl for the
// accessors and core/GlslShared.h for the rules.
//
// Images (vec4 per pixel):
//   depth  x: linear depth z (world units), y: foreground mask
//   links  x: bit mask (as a float) of the neighbours the pixel is joined to, see cfLinks
//
// Derivatives are central differences in pixels. Where a neighbour is off the screen, on the
// background or across a large depth jump, the derivatives in its direction are forced to 0
// (the paper's boundary condition), so no smoothing takes place across silhouettes.

// Whether neighbour q is joined to the foreground pixel `here` (input 0: depth): on the image, on
// the foreground, and no depth discontinuity between them: |dz| <= jumpBase + jumpPerDepth *
// min(z, z_q), a few particle radii plus a slope of a few pixel footprints.
FS_FUNC bool cfJoined(vec4 here, ivec2 q) {
  if (!ssInside(q)) return false;
  vec4 n = ssLoad(0u, q);
  if (n.y < 0.5f) return false;
  return abs(n.x - here.x) <= S.jumpBase + S.jumpPerDepth * min(here.x, n.x);
}

// cfLinks (input 0: the filter's input depth) -> links, once per apply: the discontinuities are
// those of the input, so every time step uses the same boundary. Bits: 1 (-1, 0), 2 (+1, 0),
// 4 (0, -1), 8 (0, +1), 16 (-1, -1), 32 (+1, -1), 64 (-1, +1), 128 (+1, +1).
FS_FUNC vec4 cfLinks(ivec2 p) {
  vec4 d = ssLoad(0u, p);
  if (d.y < 0.5f) return vec4(0.0f);
  uint links = 0u;
  if (cfJoined(d, p + ivec2(-1, 0))) links |= 1u;
  if (cfJoined(d, p + ivec2(1, 0))) links |= 2u;
  if (cfJoined(d, p + ivec2(0, -1))) links |= 4u;
  if (cfJoined(d, p + ivec2(0, 1))) links |= 8u;
  if (cfJoined(d, p + ivec2(-1, -1))) links |= 16u;
  if (cfJoined(d, p + ivec2(1, -1))) links |= 32u;
  if (cfJoined(d, p + ivec2(-1, 1))) links |= 64u;
  if (cfJoined(d, p + ivec2(1, 1))) links |= 128u;
  return vec4(float(links), 0.0f, 0.0f, 0.0f);
}

// cfStep (inputs: 0 depth z^n, 1 links) -> depth z^(n+1) = z^n + dt H on the foreground;
// background pixels keep their input.
//
// Sign: the normal of eq. 5.4, dP/dx x dP/dy, points away from the eye for positive depth, and
// with it eq. 5.6 gives H < 0 on a bump towards the eye, where dz/dt = H would raise the bump.
// The flow flattens bumps with H taken for the normal towards the eye, the negative of eq. 5.6:
// z^(n+1) = z^n - dt (Cy Ex + Cx Ey) / (2 D^(3/2)). For a nearly flat surface this is
// z += dt (z_xx / Cx + z_yy / Cy) / (2 z), a heat equation in pixels, stable for
// dt <= z Cx Cy / (Cx + Cy); dt = S.stepPerDepth * z is the fraction --smoothing-strength of it.
FS_FUNC vec4 cfStep(ivec2 p) {
  vec4 d = ssLoad(0u, p);
  if (d.y < 0.5f || d.x <= 0.0f) return d;
  uint links = uint(ssLoad(1u, p).x);
  float z = d.x;
  float zx = 0.0f;
  float zxx = 0.0f;
  float zy = 0.0f;
  float zyy = 0.0f;
  float zxy = 0.0f;
  if ((links & 3u) == 3u) {
    float l = ssLoad(0u, p + ivec2(-1, 0)).x;
    float r = ssLoad(0u, p + ivec2(1, 0)).x;
    zx = 0.5f * (r - l);
    zxx = (r - z) + (l - z);
  }
  if ((links & 12u) == 12u) {
    float u = ssLoad(0u, p + ivec2(0, -1)).x;
    float b = ssLoad(0u, p + ivec2(0, 1)).x;
    zy = 0.5f * (b - u);
    zyy = (b - z) + (u - z);
  }
  if (links == 255u) {
    float nn = ssLoad(0u, p + ivec2(-1, -1)).x;
    float pn = ssLoad(0u, p + ivec2(1, -1)).x;
    float np = ssLoad(0u, p + ivec2(-1, 1)).x;
    float pp = ssLoad(0u, p + ivec2(1, 1)).x;
    zxy = 0.25f * ((pp - pn) - (np - nn));
  }
  float cx = S.cx;
  float cy = S.cy;
  float cx2 = cx * cx;
  float cy2 = cy * cy;
  // eq. 5.5, and dD/dx / 2, dD/dy / 2 by the chain rule
  float D = cy2 * zx * zx + cx2 * zy * zy + cx2 * cy2 * z * z;
  float halfDx = cy2 * zx * zxx + cx2 * zy * zxy + cx2 * cy2 * z * zx;
  float halfDy = cy2 * zx * zxy + cx2 * zy * zyy + cx2 * cy2 * z * zy;
  // eq. 5.7, 5.8
  float ex = zx * halfDx - zxx * D;
  float ey = zy * halfDy - zyy * D;
  // eq. 5.6: 2H = (Cy Ex + Cx Ey) / D^(3/2)
  float twoH = (cy * ex + cx * ey) / (D * sqrt(D));
  float dt = S.stepPerDepth * z;
  return vec4(z - 0.5f * dt * twoH, d.y, 0.0f, 0.0f);
}
