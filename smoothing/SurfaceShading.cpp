#include "smoothing/SurfaceShading.h"

#include <cstddef>

#include <glm/geometric.hpp>

#include "core/Error.h"
#include "smoothing/detail/CpuScreenKernel.h"

namespace flipscope {

namespace glsl {
#include "smoothing/glsl/ColorMap.glsl"
#include "smoothing/glsl/ShadingTypes.glsl"
static_assert(sizeof(ShadingParams) == 8 * 16);
static_assert(offsetof(ShadingParams, lightDirection) == 0 && offsetof(ShadingParams, absorption) == 16 &&
              offsetof(ShadingParams, liquidColour) == 32 && offsetof(ShadingParams, albedo) == 48 &&
              offsetof(ShadingParams, foamColour) == 64);
static_assert(offsetof(ShadingParams, mode) == 80 && offsetof(ShadingParams, environmentWidth) == 84 &&
              offsetof(ShadingParams, environmentHeight) == 88 && offsetof(ShadingParams, colorMap) == 92);
static_assert(offsetof(ShadingParams, fresnelF0) == 96 && offsetof(ShadingParams, refraction) == 100 &&
              offsetof(ShadingParams, specular) == 104 && offsetof(ShadingParams, shininess) == 108);
static_assert(offsetof(ShadingParams, colorBy) == 112 && offsetof(ShadingParams, compositeFoam) == 116 &&
              offsetof(ShadingParams, attributeScale) == 120 && offsetof(ShadingParams, attributeOffset) == 124);
static_assert(kColorMapCount == 4u && kColorMapBlues == std::uint32_t(ColorMap::Blues));

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

namespace {
constexpr const char* kColorMapNames[] = {"viridis", "magma", "coolwarm", "blues"};
}

ColorMap parseColorMap(const std::string& text) {
  for (std::uint32_t i = 0; i < glsl::kColorMapCount; ++i)
    if (text == kColorMapNames[i]) return ColorMap(i);
  throw InputError("--color-map: unknown colour map '" + text + "'; valid values: " + colorMapNames());
}

const char* colorMapName(ColorMap map) {
  return std::uint32_t(map) < glsl::kColorMapCount ? kColorMapNames[std::uint32_t(map)] : "unknown";
}

std::string colorMapNames() {
  std::string names;
  for (const char* name : kColorMapNames) names += (names.empty() ? "" : ", ") + std::string(name);
  return names;
}

glm::vec3 colorMapColour(ColorMap map, float t) { return glsl::colorMap(std::uint32_t(map), t); }

SurfaceShading::SurfaceShading(ScreenDevice& device, const ShadingOptions& options, const EnvironmentMap& map)
    : mOptions(options), mMapWidth(map.width), mMapHeight(map.height) {
  FLIPSCOPE_CHECK(map.texels.size() == std::size_t(map.width) * map.height);
  mEnvironment = device.createFixedImage(std::max<std::size_t>(map.texels.size(), 1));
  if (!map.texels.empty()) device.upload(mEnvironment, map.texels);
}

void SurfaceShading::setFrameAttributeRange(float min, float max) {
  mFrameMin = min;
  mFrameMax = max;
}

void SurfaceShading::shade(ScreenDevice& device, ScreenImage gbuffer, ScreenImage normals, ScreenImage sphereNormals,
                           ScreenImage output) {
  const ScreenFrame& f = device.frame();
  const glm::vec3 right(f.right), up(f.up), forward(f.forward);
  const glm::vec3 light = glm::normalize(mOptions.lightFromCamera.x * right + mOptions.lightFromCamera.y * up -
                                         mOptions.lightFromCamera.z * forward);
  glsl::ShadingParams p{};
  p.lightDirection = glm::vec4(light, 0.0f);
  p.absorption = glm::vec4(mOptions.absorption, 0);
  p.liquidColour = glm::vec4(mOptions.liquidColour, 0);
  p.albedo = glm::vec4(mOptions.albedo, 0);
  p.foamColour = glm::vec4(mOptions.foamColour, 0.0f);
  p.compositeFoam = mOptions.foam && mOptions.mode != ShadingMode::Normals ? 1u : 0u;
  p.colorBy = mOptions.colorByAttribute ? 1u : 0u;
  p.colorMap = std::uint32_t(mOptions.colorMap);
  // t = (value - A) / (B - A), value = frameMin + w (frameMax - frameMin).
  p.attributeScale = 1.0f;
  p.attributeOffset = 0.0f;
  if (mOptions.colorRange) {
    const float a = mOptions.colorRange->x, b = mOptions.colorRange->y;
    FLIPSCOPE_CHECK(b > a, a << " " << b);
    p.attributeScale = (mFrameMax - mFrameMin) / (b - a);
    p.attributeOffset = (mFrameMin - a) / (b - a);
  }
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
