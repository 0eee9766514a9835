// Parameters of the deferred shading pass (smoothing/glsl/Shading.glsl), shared by C++
// (SurfaceShading.cpp checks the layout) and GLSL. std140: vec4s, then scalars in fours.
const uint kShadeLiquid = 0u;     // Fresnel reflection, refracted background, absorption (§3.6)
const uint kShadeSpheres = 1u;    // the ray-caster's sphere normals, Lambert and Blinn
const uint kShadeAttribute = 2u;  // the smoothed surface lit like the spheres (its albedo: see colorBy)
const uint kShadeNormals = 3u;    // the smoothed world normal as colour, n * 0.5 + 0.5

struct ShadingParams {
  vec4 lightDirection;   // xyz: unit world direction towards the sun; w: unused
  vec4 absorption;       // xyz: Beer-Lambert coefficient per cell of liquid (RGB); w: unused
  vec4 liquidColour;     // xyz: colour of light scattered in the liquid; w: unused
  vec4 albedo;           // xyz: the spheres' and the lit surface's colour without colorBy; w: unused
  vec4 foamColour;       // xyz: colour of the volumetric foam (§3.5); w: unused
  uint mode;             // kShadeLiquid, kShadeSpheres, kShadeAttribute or kShadeNormals
  uint environmentWidth;   // equirectangular map (input 3), 0: the procedural sky and ground
  uint environmentHeight;
  uint colorMap;         // kColorMapViridis .. (ColorMap.glsl)
  float fresnelF0;       // reflectance at normal incidence (water: 0.02)
  float refraction;      // background offset in pixels per unit of normal tilt (§3.6)
  float specular;        // sun highlight strength
  float shininess;       // Blinn exponent
  uint colorBy;          // 1: colour by the attribute through colorMap (liquid: dyed; else the albedo)
  uint compositeFoam;    // 1: foamColour composited over the image with the opacity of input 2's w
  float attributeScale;  // map position t = G-buffer attribute (0..1 of the frame's range) * scale
  float attributeOffset; //   + offset
};
