// Camera geometry of screen-space passes, shared by C++ and GLSL (core/GlslShared.h). Needs
// ScreenTypes.glsl before it and a ScreenFrame named F.

// Unit world direction of the ray through `pixel` (pixel centres at +0.5, row 0 at the top): the
// same ray the ray-caster traces (rcCameraRay in raycast/glsl/Raycast.glsl).
FS_FUNC vec3 ssPixelRay(vec2 pixel) {
  float sx = (pixel.x / float(F.width) * 2.0f - 1.0f) * F.tanHalfFovY * F.aspect;
  float sy = (1.0f - pixel.y / float(F.height) * 2.0f) * F.tanHalfFovY;
  vec3 f = vec3(F.forward.x, F.forward.y, F.forward.z);
  vec3 r = vec3(F.right.x, F.right.y, F.right.z);
  vec3 u = vec3(F.up.x, F.up.y, F.up.z);
  return normalize(f + sx * r + sy * u);
}

// World position relative to the eye of the surface point at `pixel` with linear depth `depth`.
FS_FUNC vec3 ssEyeOffset(ivec2 pixel, float depth) {
  vec3 ray = ssPixelRay(vec2(pixel) + vec2(0.5f));
  return ray * (depth / dot(ray, vec3(F.forward.x, F.forward.y, F.forward.z)));
}

FS_FUNC bool ssInside(ivec2 p) { return p.x >= 0 && p.y >= 0 && p.x < int(F.width) && p.y < int(F.height); }

// The pixels that `worldSize` world units span at linear depth z, at most maxPixels: a kernel of
// constant world-space size, as wide on screen as it is at that depth.
FS_FUNC float ssPixelsAtDepth(float worldSize, float z, float maxPixels) {
  return min(worldSize * F.focalPixels / max(z, 1e-6f), maxPixels);
}
