// Iterative local plane fitting by moving least squares (Imai, Kanamori, Mitani 2016, screen-space
// liquids with up to four refractions, Sec. 4.3). Shared by the compute shader (PlaneFit.comp)
// and the CPU reference (PlaneFitFilter.cpp); see smoothing/glsl/ScreenPass.glsl for the
// accessors and core/GlslShared.h for the rules.
//
// Per pixel i, the plane n_i . x = d_i minimising E = sum_j w_ij (n_i . p_j - d_i)^2 (eq. 1) over
// the eye-space positions p_j of the foreground neighbours j in a window, with the
// view-dependent weights w_ij = exp(-(z_i - z_j)^2 / sigma^2) (eq. 2); as in the paper, n_i is
// the w-weighted mean of the unsmoothed normals n~_j (eq. 3) and d_i = sum_j w_ij n_i . p_j /
// sum_j w_ij from dE/dd_i = 0 (eq. 4). The pixel moves along its view ray onto the plane (eq. 5).
//
// Images (vec4 per pixel):
//   depth    x: linear depth z (world units), y: foreground mask
//   normals  xyz: n~, the unit normal of the input depth towards the eye (eye space = world
//            directions about the eye); 0 on the background
//
// The window is a disk of radius R = worldRadius * focalPixels / z_i pixels (at most
// maxRadius), which covers a neighbour at distance rho by clamp(R + 0.5 - rho, 0, 1): the
// paper's uniform window with an edge one pixel wide, so the fit changes continuously with the
// depth that sets R.

// The eye-space difference of the surface across pixel p along `axis` (input 0: depth): to the
// neighbour in +axis or -axis whose depth is closer to z (van der Laan et al. 2009 Sec. 5.3.5,
// so silhouettes get one-sided differences), from the lower to the higher pixel; 0 when neither
// neighbour is on the foreground.
FS_FUNC vec3 pfDifference(ivec2 p, float z, vec3 here, ivec2 axis) {
  ivec2 a = p + axis;
  ivec2 b = p - axis;
  bool useA = ssInside(a) && ssLoad(0u, a).y > 0.5f;
  bool useB = ssInside(b) && ssLoad(0u, b).y > 0.5f;
  float za = ssLoad(0u, a).x;
  float zb = ssLoad(0u, b).x;
  if (useA && useB) {
    if (abs(za - z) <= abs(zb - z)) {
      useB = false;
    } else {
      useA = false;
    }
  }
  if (useA) return ssEyeOffset(a, za) - here;
  if (useB) return here - ssEyeOffset(b, zb);
  return vec3(0.0f);
}

// pfNormals (input 0: the filter's input depth) -> normals: n~ from the cross product of the
// differences along x and y, turned towards the eye; facing the eye where a pixel has no
// neighbour along x or y.
FS_FUNC vec4 pfNormals(ivec2 p) {
  vec4 d = ssLoad(0u, p);
  if (d.y < 0.5f) return vec4(0.0f);
  vec3 here = ssEyeOffset(p, d.x);
  vec3 n = cross(pfDifference(p, d.x, here, ivec2(1, 0)), pfDifference(p, d.x, here, ivec2(0, 1)));
  float length2 = dot(n, n);
  if (length2 > 0.0f) {
    n = n / sqrt(length2);
  } else {
    n = -normalize(here);
  }
  if (dot(n, here) > 0.0f) n = -n;
  return vec4(n.x, n.y, n.z, 0.0f);
}

// pfFit (inputs: 0 depth z^n, 1 normals) -> depth z^(n+1): the depth where pixel i's view ray
// meets the plane fitted to its window, at most moveLimit world radii of the window (R z /
// focalPixels) from z^n; background pixels keep their input. With p_i = ray * t, the ray meets the plane at z_i d_i / (n_i . p_i), so the change is
// z_i n_i . (c - p_i) / (n_i . p_i), c = sum_j w_ij p_j / sum_j w_ij (differences to p_i keep
// the sums small).
FS_FUNC vec4 pfFit(ivec2 p) {
  vec4 d = ssLoad(0u, p);
  if (d.y < 0.5f || d.x <= 0.0f) return d;
  float z = d.x;
  vec3 here = ssEyeOffset(p, z);
  float radius = ssPixelsAtDepth(S.worldRadius, z, S.maxRadius);
  int reach = int(radius + 0.5f);
  vec3 normalSum = vec3(0.0f);
  vec3 offsetSum = vec3(0.0f);
  float weightSum = 0.0f;
  for (int dy = -reach; dy <= reach; dy++) {
    for (int dx = -reach; dx <= reach; dx++) {
      ivec2 q = p + ivec2(dx, dy);
      if (!ssInside(q)) continue;
      vec4 n = ssLoad(0u, q);
      if (n.y < 0.5f) continue;
      float cover = clamp(radius + 0.5f - sqrt(float(dx * dx + dy * dy)), 0.0f, 1.0f);
      if (cover <= 0.0f) continue;
      float dz = n.x - z;
      float w = cover * exp(-dz * dz * S.invSigma2);
      vec4 normal = ssLoad(1u, q);
      normalSum += w * vec3(normal.x, normal.y, normal.z);
      offsetSum += w * (ssEyeOffset(q, n.x) - here);
      weightSum += w;
    }
  }
  float length2 = dot(normalSum, normalSum);
  if (weightSum <= 0.0f || length2 <= 0.0f) return vec4(z, d.y, 0.0f, 0.0f);
  vec3 normal = normalSum / sqrt(length2);
  // n . p_i < 0 for a plane facing the eye; a plane seen edge-on (or from behind) saturates the
  // clamp instead of dividing by zero.
  float facing = min(dot(normal, here), -1e-6f * z);
  float move = z * dot(normal, offsetSum / weightSum) / facing;
  float limit = S.moveLimit * radius * z / F.focalPixels;
  return vec4(z + clamp(move, -limit, limit), d.y, 0.0f, 0.0f);
}
