// The ray-caster's hits as the G-buffer of the screen-space stages (Reichl et al. 2014 §3.3,
// Fig. 3). Shared by GBufferHits.comp, GBuffer.comp and GBufferPasses.cpp. Input 0 is the RayHit array
// (raycast/glsl/RaycastTypes.glsl) read as three vec4 per pixel: normal and attribute; t,
// status, depth, brick; thickness, foam opacity and two unused floats.

// gbufferHits (GBufferHits.comp, two outputs) -> first, the surface: x: linear depth (world
// units; 0 on the background), y: mask, z: thickness (world units), w: attribute; second, the
// sphere: xyz: the sphere normal of the hit (world; 0 on the background), w: the opacity of the
// volumetric foam in front of it, or along the ray on the background (§3.5). One pass reads the
// hits (48 bytes a pixel) once for both.
FS_FUNC ScreenPair gbufferHits(ivec2 p) {
  uint i = uint(p.y) * F.width + uint(p.x);
  vec4 normal = ssLoadIndex(0u, 3u * i);
  vec4 ray = ssLoadIndex(0u, 3u * i + 1u);
  vec4 extra = ssLoadIndex(0u, 3u * i + 2u);
  float foam = clamp(extra.y, 0.0f, 1.0f);
  ScreenPair texels;
  if (floatBitsToUint(ray.y) != kRayHit) {
    texels.first = vec4(0.0f);
    texels.second = vec4(0.0f, 0.0f, 0.0f, foam);
  } else {
    texels.first = vec4(ray.z, 1.0f, max(extra.x, 0.0f), normal.w);
    texels.second = vec4(normal.x, normal.y, normal.z, foam);
  }
  return texels;
}

// gbufferBlurThickness (input 0: the gbufferSurface image) -> the same with its thickness
// averaged over the foreground pixels within one particle's screen radius (at most 8 pixels) that
// lie on the same surface (depth within 4 particle radii): the thickness of one ray counts the
// set cells it meets, which varies from pixel to pixel more than the liquid does.
FS_FUNC vec4 gbufferBlurThickness(ivec2 p) {
  vec4 here = ssLoad(0u, p);
  if (here.y < 0.5f) return here;
  int radius = int(clamp(F.focalPixels * F.particleRadius / max(here.x, 1.0e-6f), 1.0f, 8.0f));
  float sum = 0.0f;
  float count = 0.0f;
  for (int dy = -radius; dy <= radius; dy++) {
    for (int dx = -radius; dx <= radius; dx++) {
      ivec2 q = p + ivec2(dx, dy);
      if (!ssInside(q)) continue;
      vec4 n = ssLoad(0u, q);
      if (n.y < 0.5f || abs(n.x - here.x) > 4.0f * F.particleRadius) continue;
      sum += n.z;
      count += 1.0f;
    }
  }
  return vec4(here.x, here.y, sum / count, here.w);
}
