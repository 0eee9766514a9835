#include "smoothing/SurfaceShading.h"

#include <cstddef>

#include <glm/geometric.hpp>

#include "core/Error.h"
#include "smoothing/detail/CpuScreenKernel.h"

namespace flipscope {

namespace glsl {
#include "smoothing/glsl/ShadingTypes.glsl"
static_assert(sizeof(ShadingParams) == 7 * 16 && offsetof(ShadingParams, mode) == 80 &&
              offsetof(ShadingParams, fresnelF0) == 96 && offsetof(ShadingParams, shininess) == 108);

struct ShadingKernel : CpuScreenKernel {
  ShadingParams S;
#include "smoothing/glsl/Shading.glsl"
};
}  // namespace glsl

namespace {
const ScreenPass kShade{"Shading.comp", "shadeSurface",
                        cpuScreenPass<glsl::ShadingKernel, &glsl::ShadingKernel::shadeSurface>};
}

ShadingMode parseShadingMode(const std::string& text) {
  if (text == "liquid") return ShadingMode::Liquid;
  if (text == "spheres") return ShadingMode::Spheres;
  if (text == "attribute") return ShadingMode::Attribute;
  if (text == "normals") return ShadingMode::Normals;
  throw InputError("--shading: unknown mode '" + text + "'; valid values: liquid, spheres, attribute, normals");
}

SurfaceShading::SurfaceShading(ScreenDevice& device, const ShadingOptions& options, const EnvironmentMap& map)
    : mOptions(options), mMapWidth(map.width), mMapHeight(map.height) {
  FLIPSCOPE_CHECK(map.texels.size() == std::size_t(map.width) * map.height);
  mEnvironment = device.createFixedImage(std::max<std::size_t>(map.texels.size(), 1));
  if (!map.texels.empty()) device.upload(mEnvironment, map.texels);
}

void SurfaceShading::shade(ScreenDevice& device, ScreenImage gbuffer, ScreenImage normals, ScreenImage sphereNormals,
                           ScreenImage output) {
  const ScreenFrame& f = device.frame();
  const glm::vec3 right(f.right), up(f.up), forward(f.forward);
  const glm::vec3 light = glm::normalize(mOptions.lightFromCamera.x * right + mOptions.lightFromCamera.y * up -
                                         mOptions.lightFromCamera.z * forward);
  glsl::ShadingParams p{};
  p.lightDirection = glm::vec4(light, 1.0f);
  p.absorption = glm::vec4(mOptions.absorption, 0);
  p.liquidColour = glm::vec4(mOptions.liquidColour, 0);
  p.slowColour = glm::vec4(mOptions.slowColour, 0);
  p.fastColour = glm::vec4(mOptions.fastColour, 0);
  switch (mOptions.mode) {
    case ShadingMode::Liquid: p.mode = glsl::kShadeLiquid; break;
    case ShadingMode::Spheres: p.mode = glsl::kShadeSpheres; break;
    case ShadingMode::Attribute: p.mode = glsl::kShadeAttribute; break;
    case ShadingMode::Normals: p.mode = glsl::kShadeNormals; break;
  }
  p.environmentWidth = mMapWidth;
  p.environmentHeight = mMapHeight;
  p.fresnelF0 = mOptions.fresnelF0;
  p.refraction = mOptions.refraction;
  p.specular = mOptions.specular;
  p.shininess = mOptions.shininess;
  device.run(kShade, p, {gbuffer, normals, sphereNormals, mEnvironment}, output);
}

}  // namespace flipscope
