// Colour maps for colouring the liquid by a per-particle attribute (`render --color-map`), in the
// common subset of GLSL and C++ (core/GlslShared.h): Shading.comp runs them on the GPU, and
// SurfaceShading.cpp includes this file in namespace flipscope::glsl for the C++ reference and
// colorMapColour(). Each map is nine sRGB control points at t = 0, 1/8, .., 1, interpolated
// linearly in sRGB (as the maps were designed) and decoded to linear RGB (what shading works in):
//   viridis, magma  perceptually uniform sequential maps (van der Walt and Smith, matplotlib 2.0)
//   coolwarm        Moreland's diverging blue-white-red map ("Diverging Color Maps for Scientific
//                   Visualization", 2009)
//   blues           ColorBrewer's sequential Blues (Brewer), light for low values, dark for high
const uint kColorMapViridis = 0u;
const uint kColorMapMagma = 1u;
const uint kColorMapCoolwarm = 2u;
const uint kColorMapBlues = 3u;
const uint kColorMapCount = 4u;

// Control point i (0..8) of `map`, sRGB in 0..255.
FS_FUNC vec3 cmPoint(uint map, uint i) {
  if (map == kColorMapMagma) {
    if (i == 0u) return vec3(0.0f, 0.0f, 4.0f);
    if (i == 1u) return vec3(28.0f, 16.0f, 68.0f);
    if (i == 2u) return vec3(79.0f, 18.0f, 123.0f);
    if (i == 3u) return vec3(129.0f, 37.0f, 129.0f);
    if (i == 4u) return vec3(181.0f, 54.0f, 122.0f);
    if (i == 5u) return vec3(229.0f, 80.0f, 100.0f);
    if (i == 6u) return vec3(251.0f, 135.0f, 97.0f);
    if (i == 7u) return vec3(254.0f, 194.0f, 135.0f);
    return vec3(252.0f, 253.0f, 191.0f);
  }
  if (map == kColorMapCoolwarm) {
    if (i == 0u) return vec3(59.0f, 76.0f, 192.0f);
    if (i == 1u) return vec3(98.0f, 130.0f, 234.0f);
    if (i == 2u) return vec3(141.0f, 176.0f, 254.0f);
    if (i == 3u) return vec3(184.0f, 208.0f, 249.0f);
    if (i == 4u) return vec3(221.0f, 221.0f, 221.0f);
    if (i == 5u) return vec3(245.0f, 196.0f, 173.0f);
    if (i == 6u) return vec3(244.0f, 154.0f, 123.0f);
    if (i == 7u) return vec3(222.0f, 96.0f, 77.0f);
    return vec3(180.0f, 4.0f, 38.0f);
  }
  if (map == kColorMapBlues) {
    if (i == 0u) return vec3(247.0f, 251.0f, 255.0f);
    if (i == 1u) return vec3(222.0f, 235.0f, 247.0f);
    if (i == 2u) return vec3(198.0f, 219.0f, 239.0f);
    if (i == 3u) return vec3(158.0f, 202.0f, 225.0f);
    if (i == 4u) return vec3(107.0f, 174.0f, 214.0f);
    if (i == 5u) return vec3(66.0f, 146.0f, 198.0f);
    if (i == 6u) return vec3(33.0f, 113.0f, 181.0f);
    if (i == 7u) return vec3(8.0f, 81.0f, 156.0f);
    return vec3(8.0f, 48.0f, 107.0f);
  }
  // viridis (also for an unknown map)
  if (i == 0u) return vec3(68.0f, 1.0f, 84.0f);
  if (i == 1u) return vec3(71.0f, 44.0f, 122.0f);
  if (i == 2u) return vec3(59.0f, 81.0f, 139.0f);
  if (i == 3u) return vec3(44.0f, 113.0f, 142.0f);
  if (i == 4u) return vec3(33.0f, 144.0f, 141.0f);
  if (i == 5u) return vec3(39.0f, 173.0f, 129.0f);
  if (i == 6u) return vec3(92.0f, 200.0f, 99.0f);
  if (i == 7u) return vec3(170.0f, 220.0f, 50.0f);
  return vec3(253.0f, 231.0f, 37.0f);
}

// The sRGB decoding (IEC 61966-2-1) of one component in 0..1.
FS_FUNC float cmLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : pow((c + 0.055f) / 1.055f, 2.4f);
}

// The linear RGB colour of `map` at t (clamped to 0..1; NaN reads as 0).
FS_FUNC vec3 colorMap(uint map, float t) {
  float x = t >= 0.0f ? min(t, 1.0f) * 8.0f : 0.0f;
  uint i = min(uint(x), 7u);
  vec3 c = mix(cmPoint(map, i), cmPoint(map, i + 1u), x - float(i)) / 255.0f;
  return vec3(cmLinear(c.x), cmLinear(c.y), cmLinear(c.z));
}
