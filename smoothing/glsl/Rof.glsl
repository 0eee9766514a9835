// Adaptive ROF smoothing of the depth image (Reichl et al. 2014 §3.4), solved by Chambolle's
// fixed point (Chambolle 2004; eq. 2 and 3 of the paper), with the depth-dependent lambda of
// eq. 7. Shared by the compute shader (Rof.comp) and the CPU reference (RofFilter.cpp); see
// smoothing/glsl/ScreenPass.glsl for the accessors and core/GlslShared.h for the rules.
//
// Images (vec4 per pixel):
//   depth    x: linear depth v (world units), y: foreground mask
//   domain   x: v extruded by one pixel, y: 1 on the filter domain (foreground and its one-pixel
//            extrusion), z: lambda^(0)
//   dual     xy: the dual variable p
//   div      x: div p, y: the current lambda
// The domain is the foreground extruded by one pixel; Neumann boundary on its edge: a forward
// difference towards a pixel outside it is 0, and so p's component across it (eq. 2 discretised
// with forward differences, div with backward differences, its adjoint).

// rofExtrude (input 0: depth) -> domain. Background pixels next to the foreground take the mean
// depth of the foreground pixels of their 3x3 neighbourhood; the mask is not changed.
FS_FUNC vec4 rofExtrude(ivec2 p) {
  vec4 d = ssLoad(0u, p);
  float v = d.x;
  float inside = 0.0f;
  if (d.y > 0.5f) {
    inside = 1.0f;
  } else {
    float sum = 0.0f;
    float count = 0.0f;
    for (int dy = -1; dy <= 1; dy++) {
      for (int dx = -1; dx <= 1; dx++) {
        ivec2 q = p + ivec2(dx, dy);
        if (!ssInside(q)) continue;
        vec4 n = ssLoad(0u, q);
        if (n.y > 0.5f) {
          sum += n.x;
          count += 1.0f;
        }
      }
    }
    if (count > 0.0f) {
      v = sum / count;
      inside = 1.0f;
    } else {
      v = 0.0f;
    }
  }
  float lambda = inside > 0.5f ? S.lambda0 / (v + S.epsilon) : 0.0f;
  return vec4(v, inside, lambda, 0.0f);
}

// rofStart (input 0: domain) -> div: div p^(0) = 0 and lambda^(0).
FS_FUNC vec4 rofStart(ivec2 p) { return vec4(0.0f, ssLoad(0u, p).z, 0.0f, 0.0f); }

// div p - v / lambda at p: the quantity whose gradient drives eq. 2 (for constant lambda,
// grad(div p) - grad(v) / lambda). With a lambda per pixel, eq. 2 takes grad(v) / lambda_ij:
// rofDual divides the depth difference by the lambda of the pixel itself.
FS_FUNC vec4 rofDual(ivec2 p) {
  // inputs: 0 domain, 1 dual (p^n), 2 div (div p^n, lambda^n)
  vec4 here = ssLoad(0u, p);
  if (here.y < 0.5f) return vec4(0.0f);
  vec4 divHere = ssLoad(2u, p);
  float lambda = divHere.y;
  vec2 g = vec2(0.0f);
  ivec2 px = p + ivec2(1, 0);
  ivec2 py = p + ivec2(0, 1);
  if (ssInside(px)) {
    vec4 n = ssLoad(0u, px);
    if (n.y > 0.5f) g.x = (ssLoad(2u, px).x - divHere.x) - (n.x - here.x) / lambda;
  }
  if (ssInside(py)) {
    vec4 n = ssLoad(0u, py);
    if (n.y > 0.5f) g.y = (ssLoad(2u, py).x - divHere.x) - (n.x - here.x) / lambda;
  }
  vec4 dual = ssLoad(1u, p);
  vec2 step = S.tau * g;
  vec2 next = (vec2(dual.x, dual.y) + step) / (1.0f + sqrt(dot(step, step)));
  return vec4(next.x, next.y, 0.0f, 0.0f);
}

// rofDivergence (inputs: 0 domain, 1 dual p^(n+1), 2 div (div p^n, lambda^n)) -> div: backward
// differences of p (0 outside the domain and the image), and lambda by eq. 7 from the depth the
// iteration has reached, v - lambda^n div p.
FS_FUNC vec4 rofDivergence(ivec2 p) {
  vec4 here = ssLoad(0u, p);
  if (here.y < 0.5f) return vec4(0.0f);
  vec4 dual = ssLoad(1u, p);
  float div = dual.x + dual.y;
  ivec2 qx = p - ivec2(1, 0);
  ivec2 qy = p - ivec2(0, 1);
  if (ssInside(qx)) div -= ssLoad(1u, qx).x;
  if (ssInside(qy)) div -= ssLoad(1u, qy).y;
  float lambda = ssLoad(2u, p).y;
  if (S.adaptive != 0u) lambda = S.lambda0 / max(here.x - lambda * div + S.epsilon, S.epsilon);
  return vec4(div, lambda, 0.0f, 0.0f);
}

// rofResult (inputs: 0 depth, 1 div) -> output: u = v - lambda div p on the foreground (eq. 3);
// background pixels keep their input.
FS_FUNC vec4 rofResult(ivec2 p) {
  vec4 d = ssLoad(0u, p);
  if (d.y < 0.5f) return d;
  vec4 div = ssLoad(1u, p);
  return vec4(d.x - div.y * div.x, d.y, 0.0f, 0.0f);
}
