// Deferred shading of the smoothed surface (Reichl et al. 2014 §3.3 Fig. 3, §3.6): Fresnel
// reflection of an environment, the refracted background, Beer-Lambert absorption over the
// liquid's thickness and a sun highlight (kernels: smoothing/glsl/Shading.glsl).
#pragma once

#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "smoothing/ScreenDevice.h"

namespace flipscope {

enum class ShadingMode { Liquid, Spheres, Attribute, Normals };
/// "liquid", "spheres", "attribute" or "normals". Throws InputError naming --shading and the
/// valid values.
ShadingMode parseShadingMode(const std::string& text);

/// An equirectangular environment map, linear RGB, row 0 at the top (the up direction).
struct EnvironmentMap {
  std::uint32_t width = 0, height = 0;
  std::vector<glm::vec4> texels;
};

struct ShadingOptions {
  ShadingMode mode = ShadingMode::Liquid;
  glm::vec3 lightFromCamera{-0.45f, 0.75f, 0.50f};  ///< towards the sun: camera right, up, backwards
  glm::vec3 absorption{0.30f, 0.11f, 0.06f};         ///< Beer-Lambert per cell of liquid (RGB)
  glm::vec3 liquidColour{0.03f, 0.17f, 0.28f};       ///< light scattered in deep liquid
  glm::vec3 slowColour{0.05f, 0.26f, 0.55f};         ///< attribute 0
  glm::vec3 fastColour{0.80f, 0.92f, 1.00f};         ///< attribute 1 (fastest of the frame)
  float fresnelF0 = 0.02f;                            ///< water
  float refraction = 12.0f;                           ///< pixels of background offset per unit tilt
  float specular = 0.45f;
  float shininess = 120.0f;
};

/// Shades into `output` (linear RGB, alpha 1) from the G-buffer `gbuffer` (x: unsmoothed depth,
/// y: mask, z: thickness in world units, w: attribute), the smoothed `normals` and the hits'
/// `sphereNormals`. `environment` is a fixed image holding `map` (unused when map is empty).
/// The light follows the camera: `right`, `up`, `forward` are the frame's axes.
class SurfaceShading {
 public:
  SurfaceShading(ScreenDevice& device, const ShadingOptions& options, const EnvironmentMap& map);
  void shade(ScreenDevice& device, ScreenImage gbuffer, ScreenImage normals, ScreenImage sphereNormals,
             ScreenImage output);

 private:
  ShadingOptions mOptions;
  std::uint32_t mMapWidth = 0, mMapHeight = 0;
  ScreenImage mEnvironment = 0;
};

}  // namespace flipscope
