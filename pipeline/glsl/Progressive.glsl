// The viewer's progressive display (Reichl et al. 2014 §3.3: a ray that stopped at a brick not
// yet on the device is finished in a later frame). Shared by Progressive.comp and
// FramePipeline.cpp. Input 0 is the RayHit array (three vec4 per pixel, status in the second's
// y), input 1 the frame shaded from the rays so far (linear, premultiplied), input 2 the image
// shown before.

// The sRGB encoding of a linear value in 0..1 (what the PNG writer's linearToSrgb8 does before
// quantizing), so the window shows what `render -o a.png` writes.
FS_FUNC float progressiveSrgb(float linear) {
  float v = clamp(linear, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * pow(v, 1.0f / 2.4f) - 0.055f;
}

// progressiveDisplay -> the shaded pixel, sRGB-encoded with alpha 1, where its ray has finished
// (hit or miss), else the pixel shown before: a pending ray keeps the previous image until its
// bricks arrive.
FS_FUNC vec4 progressiveDisplay(ivec2 p) {
  uint i = uint(p.y) * F.width + uint(p.x);
  vec4 ray = ssLoadIndex(0u, 3u * i + 1u);
  if (floatBitsToUint(ray.y) == kRayPending) return ssLoad(2u, p);
  vec4 c = ssLoad(1u, p);
  float a = max(c.w, 1.0e-6f);
  return vec4(progressiveSrgb(c.x / a), progressiveSrgb(c.y / a), progressiveSrgb(c.z / a), 1.0f);
}
