// Parameters of the deferred shading pass (smoothing/glsl/Shading.glsl), shared by C++
// (SurfaceShading.cpp checks the layout) and GLSL. std140: vec4s, then scalars in fours.
const uint kShadeLiquid = 0u;     // Fresnel reflection, refracted background, absorption (§3.6)
const uint kShadeSpheres = 1u;    // the ray-caster's sphere normals, Lambert and Blinn
const uint kShadeAttribute = 2u;  // colour by the stored attribute on the smoothed surface
const uint kShadeNormals = 3u;    // the smoothed world normal as colour, n * 0.5 + 0.5

struct ShadingParams {
  vec4 lightDirection;   // xyz: unit world direction towards the sun; w: sun intensity
  vec4 absorption;       // xyz: Beer-Lambert coefficient per cell of liquid (RGB); w: unused
  vec4 liquidColour;     // xyz: colour of light scattered in the liquid; w: unused
  vec4 slowColour;       // xyz: attribute 0 (spheres, attribute modes); w: unused
  vec4 fastColour;       // xyz: attribute 1; w: unused
  uint mode;             // kShadeLiquid, kShadeSpheres, kShadeAttribute or kShadeNormals
  uint environmentWidth;   // equirectangular map (input 3), 0: the procedural sky and ground
  uint environmentHeight;
  uint unused0;
  float fresnelF0;       // reflectance at normal incidence (water: 0.02)
  float refraction;      // background offset in pixels per unit of normal tilt (§3.6)
  float specular;        // sun highlight strength
  float shininess;       // Blinn exponent
};
