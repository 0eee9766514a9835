// Deferred shading of the smoothed surface (Reichl et al. 2014 §3.3 Fig. 3, §3.6): Fresnel
// reflection of an environment, the refracted background, Beer-Lambert absorption over the
// liquid's thickness and a sun highlight (kernels: smoothing/glsl/Shading.glsl). Any mode but
// normals can colour the liquid by the stored attribute through a colour map (ColorMap.glsl).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "smoothing/ScreenDevice.h"

namespace flipscope {

enum class ShadingMode { Liquid, Spheres, Attribute, Normals };
/// "liquid", "spheres", "attribute" or "normals". Throws InputError naming --shading and the
/// valid values.
ShadingMode parseShadingMode(const std::string& text);

/// The colour maps of `render --color-map` (smoothing/glsl/ColorMap.glsl defines them).
enum class ColorMap : std::uint32_t { Viridis = 0, Magma = 1, Coolwarm = 2, Blues = 3 };
/// "viridis", "magma", "coolwarm" or "blues". Throws InputError naming --color-map and the valid
/// values.
ColorMap parseColorMap(const std::string& text);
/// "viridis, magma, coolwarm, blues".
std::string colorMapNames();
/// "viridis", ...
const char* colorMapName(ColorMap map);
/// The linear RGB colour of `map` at t (clamped to [0, 1]): the C++ build of the GLSL function
/// the shading pass runs.
glm::vec3 colorMapColour(ColorMap map, float t);

/// An equirectangular environment map, linear RGB, row 0 at the top (the up direction).
struct EnvironmentMap {
  std::uint32_t width = 0, height = 0;
  std::vector<glm::vec4> texels;
};

struct ShadingOptions {
  ShadingMode mode = ShadingMode::Liquid;
  /// Colour by the stored attribute through `colorMap` (--color-by attribute): the albedo of the
  /// spheres and of the lit surface (attribute mode), the dye of the liquid; normals ignore it.
  bool colorByAttribute = false;
  ColorMap colorMap = ColorMap::Viridis;
  /// Attribute values at the two ends of the map (--color-range A,B, A < B); unset: the range of
  /// each frame (FramePipeline: a store's range when the render command gives none).
  std::optional<glm::vec2> colorRange;
  glm::vec3 lightFromCamera{-0.45f, 0.75f, 0.50f};  ///< towards the sun: camera right, up, backwards
  glm::vec3 absorption{0.30f, 0.11f, 0.06f};         ///< Beer-Lambert per cell of liquid (RGB)
  glm::vec3 liquidColour{0.03f, 0.17f, 0.28f};       ///< light scattered in deep liquid
  glm::vec3 albedo{0.05f, 0.26f, 0.55f};             ///< spheres and lit surface without colour by attribute
  bool foam = false;                                 ///< composite the volumetric foam (sphere normals' w)
  glm::vec3 foamColour{0.90f, 0.93f, 0.95f};         ///< §3.5
  float fresnelF0 = 0.02f;                            ///< water
  float refraction = 12.0f;                           ///< pixels of background offset per unit tilt
  float specular = 0.45f;
  float shininess = 120.0f;
};

/// Shades into `output` (linear RGB, alpha 1) from the G-buffer `gbuffer` (x: unsmoothed depth,
/// y: mask, z: thickness in world units, w: attribute), the smoothed `normals` and the hits'
/// `sphereNormals` (w: the volumetric foam's opacity, composited last with options.foam). `environment` is a fixed image holding `map` (unused when map is empty).
/// The light follows the camera: `right`, `up`, `forward` are the frame's axes.
class SurfaceShading {
 public:
  SurfaceShading(ScreenDevice& device, const ShadingOptions& options, const EnvironmentMap& map);
  /// The attribute values the G-buffer's 0 and 1 stand for (the frame's quantization range,
  /// FrameStats): with options.colorRange they place the frame's values on the map. Default 0, 1.
  void setFrameAttributeRange(float min, float max);
  void shade(ScreenDevice& device, ScreenImage gbuffer, ScreenImage normals, ScreenImage sphereNormals,
             ScreenImage output);

 private:
  ShadingOptions mOptions;
  float mFrameMin = 0, mFrameMax = 1;
  std::uint32_t mMapWidth = 0, mMapHeight = 0;
  ScreenImage mEnvironment = 0;
};

}  // namespace flipscope
