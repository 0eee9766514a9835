// Normal reconstruction from the smoothed depth image (Reichl et al. 2014 §3.3, Fig. 3: normals
// and positions reconstructed from smoothed depth for deferred shading; van der Laan et al. 2009
// §4: one-sided differences across depth edges). Shared by Normals.comp and SurfaceNormals.cpp.
// Needs ScreenTypes.glsl, the screen-pass accessors and a NormalParams named S.

// The derivative of the eye-relative position along `axis` at p: the central difference when both
// neighbours are foreground and the surface bends smoothly between them; else the one-sided
// difference to the neighbour whose depth is closer (so an edge between two surfaces is never
// differenced across); 0 when neither neighbour is foreground or both lie past an edge.
FS_FUNC vec3 nrDerivative(ivec2 p, ivec2 axis, vec3 here, float depth) {
  ivec2 fp = p + axis;
  ivec2 bp = p - axis;
  bool hasF = false;
  bool hasB = false;
  float df = 0.0f;
  float db = 0.0f;
  vec3 forwardPos = here;
  vec3 backwardPos = here;
  float edge = S.edgeDepth;
  if (ssInside(fp)) {
    vec4 f = ssLoad(0u, fp);
    if (f.y > 0.5f) {
      df = f.x - depth;
      hasF = abs(df) < edge;
      forwardPos = ssEyeOffset(fp, f.x);
    }
  }
  if (ssInside(bp)) {
    vec4 b = ssLoad(0u, bp);
    if (b.y > 0.5f) {
      db = depth - b.x;
      hasB = abs(db) < edge;
      backwardPos = ssEyeOffset(bp, b.x);
    }
  }
  if (hasF && hasB && abs(df - db) <= 0.5f * max(abs(df), abs(db)) + 1.0e-3f * edge)
    return (forwardPos - backwardPos) * 0.5f;
  if (hasF && (!hasB || abs(df) <= abs(db))) return forwardPos - here;
  if (hasB) return here - backwardPos;
  return vec3(0.0f);
}

// normalsFromDepth (input 0: depth x, mask y) -> xyz: unit world normal facing the camera, w:
// mask. A pixel with no usable neighbour on an axis faces the camera.
FS_FUNC vec4 normalsFromDepth(ivec2 p) {
  vec4 d = ssLoad(0u, p);
  if (d.y < 0.5f) return vec4(0.0f);
  vec3 ray = ssPixelRay(vec2(p) + vec2(0.5f));
  vec3 here = ssEyeOffset(p, d.x);
  // Image x grows to the right, image y downwards.
  vec3 dx = nrDerivative(p, ivec2(1, 0), here, d.x);
  vec3 dy = nrDerivative(p, ivec2(0, 1), here, d.x);
  vec3 n = cross(dy, dx);
  float len = sqrt(dot(n, n));
  if (len < 1.0e-20f) return vec4(-ray, 1.0f);
  n = n / len;
  if (dot(n, ray) > 0.0f) n = -n;
  return vec4(n, 1.0f);
}
