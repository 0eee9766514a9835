// Deferred liquid shading (Reichl et al. 2014 §3.3 Fig. 3, §3.6): the environment is the
// background buffer, looked up along the pixel's ray offset by the smoothed normal
// (refraction), attenuated by Beer-Lambert absorption over the liquid's thickness, and blended
// with the Fresnel (Schlick) reflection of the environment and a sun highlight. Shared by
// Shading.comp and SurfaceShading.cpp.
//
// Inputs: 0 G-buffer (x: unsmoothed depth, y: mask, z: thickness in world units, w: attribute),
// 1 smoothed normals (xyz, w: mask), 2 sphere normals of the hits (xyz) and the foam's opacity
// (w), 3 the equirectangular environment (S.environmentWidth x S.environmentHeight, row 0 at the
// top) when it has one. The volumetric foam in front of the surface (§3.5, Fig. 3) is composited
// last, over the surface and the background alike: colour = foam A + shaded (1 - A).
//
// Colour by attribute (S.colorBy, render --color-by): one path for every mode but normals. The
// G-buffer attribute (0..1 over the frame's range) becomes t = w * S.attributeScale +
// S.attributeOffset (the --color-range) and the colour colorMap(S.colorMap, t) (ColorMap.glsl,
// included before this file): the albedo of the spheres and of the lit surface, and for the
// liquid a dye, which tints both the light scattered in it and the background seen through it.

// The procedural environment: a sky that brightens towards the horizon and the sun, over a
// darker ground, around the scene's up axis.
FS_FUNC vec3 shProceduralSky(vec3 dir) {
  vec3 up = vec3(F.worldUp.x, F.worldUp.y, F.worldUp.z);
  float h = dot(dir, up);
  vec3 sun = vec3(S.lightDirection.x, S.lightDirection.y, S.lightDirection.z);
  if (h >= 0.0f) {
    vec3 horizon = vec3(0.78f, 0.85f, 0.92f);
    vec3 zenith = vec3(0.22f, 0.42f, 0.75f);
    vec3 sky = mix(horizon, zenith, pow(h, 0.6f));
    float glow = max(dot(dir, sun), 0.0f);
    for (int i = 0; i < 6; i++) glow *= glow;  // glow^64, without a pow per background pixel
    return sky + vec3(1.0f, 0.9f, 0.7f) * (glow * 0.6f);
  }
  vec3 near = vec3(0.34f, 0.32f, 0.29f);
  vec3 far = vec3(0.55f, 0.55f, 0.53f);
  return mix(far, near, sqrt(min(-h * 4.0f, 1.0f)));
}

// The environment in world direction `dir`: the map when there is one, else the procedural sky.
FS_FUNC vec3 shEnvironment(vec3 dir) {
  if (S.environmentWidth == 0u) return shProceduralSky(dir);
  vec3 up = vec3(F.worldUp.x, F.worldUp.y, F.worldUp.z);
  // A frame around the up axis: longitude 0 looks along `east`.
  vec3 east = abs(up.x) < 0.9f ? normalize(cross(up, vec3(1.0f, 0.0f, 0.0f))) : vec3(0.0f, 0.0f, 1.0f);
  vec3 north = cross(up, east);
  float longitude = atan(dot(dir, north), dot(dir, east));  // -pi..pi
  float latitude = acos(clamp(dot(dir, up), -1.0f, 1.0f));  // 0 (up)..pi
  float u = longitude / 6.28318531f + 0.5f;
  float v = latitude / 3.14159265f;
  uint x = min(uint(u * float(S.environmentWidth)), S.environmentWidth - 1u);
  uint y = min(uint(v * float(S.environmentHeight)), S.environmentHeight - 1u);
  vec4 texel = ssLoadIndex(3u, y * S.environmentWidth + x);
  return vec3(texel.x, texel.y, texel.z);
}

// The colour of the attribute value `a` (the G-buffer's, 0..1 over the frame's range) through the
// colour map, when colouring by attribute; else the plain albedo.
FS_FUNC vec3 shAlbedo(float a) {
  if (S.colorBy == 0u) return vec3(S.albedo.x, S.albedo.y, S.albedo.z);
  return colorMap(S.colorMap, a * S.attributeScale + S.attributeOffset);
}

// Lambert and Blinn from the sun for a surface of colour `albedo`.
FS_FUNC vec3 shLit(vec3 albedo, vec3 n, vec3 view) {
  vec3 sun = vec3(S.lightDirection.x, S.lightDirection.y, S.lightDirection.z);
  float diffuse = max(dot(n, sun), 0.0f);
  vec3 halfway = normalize(sun + view);
  float highlight = diffuse > 0.0f ? pow(max(dot(n, halfway), 0.0f), S.shininess) : 0.0f;
  return albedo * (0.22f + 0.78f * diffuse) + vec3(S.specular * highlight);
}

// The surface (or the background) of pixel p, before the foam.
FS_FUNC vec3 shadeUnderFoam(ivec2 p) {
  vec3 ray = ssPixelRay(vec2(p) + vec2(0.5f));
  vec4 g = ssLoad(0u, p);
  if (g.y < 0.5f) return shEnvironment(ray);
  vec3 view = -ray;
  vec3 colour;
  if (S.mode == kShadeSpheres) {
    vec4 h = ssLoad(2u, p);
    colour = shLit(shAlbedo(g.w), normalize(vec3(h.x, h.y, h.z)), view);
  } else {
    vec4 nn = ssLoad(1u, p);
    vec3 n = vec3(nn.x, nn.y, nn.z);
    if (S.mode == kShadeAttribute) {
      colour = shLit(shAlbedo(g.w), n, view);
    } else if (S.mode == kShadeNormals) {
      colour = n * 0.5f + vec3(0.5f);
    } else {
      // §3.6: the background behind the liquid, offset along the normal's screen-space tilt.
      vec3 right = vec3(F.right.x, F.right.y, F.right.z);
      vec3 up = vec3(F.up.x, F.up.y, F.up.z);
      vec2 offset = vec2(dot(n, right), -dot(n, up)) * S.refraction;
      vec3 behind = shEnvironment(ssPixelRay(vec2(p) + vec2(0.5f) + offset));
      float cells = g.z / F.cellSize;
      vec3 transmitted = exp(-vec3(S.absorption.x, S.absorption.y, S.absorption.z) * cells);
      vec3 sun = vec3(S.lightDirection.x, S.lightDirection.y, S.lightDirection.z);
      float lit = 0.45f + 0.55f * max(dot(n, sun), 0.0f);
      vec3 scattered = vec3(S.liquidColour.x, S.liquidColour.y, S.liquidColour.z) * lit;
      vec3 body = behind * transmitted + scattered * (vec3(1.0f) - transmitted);
      if (S.colorBy != 0u) {
        // A dyed liquid: the dye's colour filters what passes through and is what it scatters.
        vec3 dye = shAlbedo(g.w);
        body = behind * transmitted * dye + dye * lit * (vec3(1.0f) - transmitted);
      }
      float cosine = clamp(dot(n, view), 0.0f, 1.0f);
      float fresnel = S.fresnelF0 + (1.0f - S.fresnelF0) * pow(1.0f - cosine, 5.0f);
      vec3 reflected = shEnvironment(reflect(ray, n));
      vec3 halfway = normalize(sun + view);
      float highlight = pow(max(dot(n, halfway), 0.0f), S.shininess) * S.specular;
      colour = mix(body, reflected, fresnel) + vec3(highlight);
    }
  }
  return colour;
}

// shadeSurface -> linear RGB, alpha 1 (the environment behind the background).
FS_FUNC vec4 shadeSurface(ivec2 p) {
  vec3 colour = shadeUnderFoam(p);
  if (S.compositeFoam != 0u) {
    float foam = ssLoad(2u, p).w;
    colour = vec3(S.foamColour.x, S.foamColour.y, S.foamColour.z) * foam + colour * (1.0f - foam);
  }
  return vec4(colour.x, colour.y, colour.z, 1.0f);
}
