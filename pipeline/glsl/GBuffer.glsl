// The ray-caster's hits as the G-buffer of the screen-space stages (Reichl et al. 2014 §3.3,
// Fig. 3). Shared by GBuffer.comp and FramePipeline.cpp. Input 0 is the RayHit array
// (raycast/glsl/RaycastTypes.glsl) read as three vec4 per pixel: normal and attribute; t,
// status, depth, brick; thickness and three unused floats.

// gbufferSurface -> x: linear depth (world units; 0 on the background), y: mask, z: thickness
// (world units), w: attribute.
FS_FUNC vec4 gbufferSurface(ivec2 p) {
  uint i = uint(p.y) * F.size.x + uint(p.x);
  vec4 normal = ssLoadIndex(0u, 3u * i);
  vec4 ray = ssLoadIndex(0u, 3u * i + 1u);
  vec4 extra = ssLoadIndex(0u, 3u * i + 2u);
  if (floatBitsToUint(ray.y) != kRayHit) return vec4(0.0f);
  return vec4(ray.z, 1.0f, max(extra.x, 0.0f), normal.w);
}

// gbufferSphereNormal -> xyz: the sphere normal of the hit (world), w: mask.
FS_FUNC vec4 gbufferSphereNormal(ivec2 p) {
  uint i = uint(p.y) * F.size.x + uint(p.x);
  vec4 normal = ssLoadIndex(0u, 3u * i);
  vec4 ray = ssLoadIndex(0u, 3u * i + 1u);
  if (floatBitsToUint(ray.y) != kRayHit) return vec4(0.0f);
  return vec4(normal.x, normal.y, normal.z, 1.0f);
}
