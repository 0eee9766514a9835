// The colour maps of `render --color-map` (smoothing/glsl/ColorMap.glsl, compiled as C++) and
// colouring by attribute in the shading pass on the CPU reference: control points, clamping, the
// maps' character (sequential, diverging) and that they differ, the --color-range mapping, and
// the attribute changing the picture in every mode but normals.
#include <gtest/gtest.h>

#include <cmath>

#include "core/Error.h"
#include "smoothing/CpuScreenDevice.h"
#include "smoothing/ShadingScenes.h"

namespace flipscope {
namespace {

const ColorMap kMaps[] = {ColorMap::Viridis, ColorMap::Magma, ColorMap::Coolwarm, ColorMap::Blues};

float srgbToLinear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }
glm::vec3 linear(int r, int g, int b) {
  return {srgbToLinear(float(r) / 255.0f), srgbToLinear(float(g) / 255.0f), srgbToLinear(float(b) / 255.0f)};
}
float luminance(const glm::vec3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
float distance(const glm::vec3& a, const glm::vec3& b) { return glm::length(a - b); }

TEST(ColorMap, EndsAndControlPointsAreThePublishedColours) {
  const auto expectNear = [](const glm::vec3& got, const glm::vec3& want, const char* what) {
    EXPECT_NEAR(got.x, want.x, 1e-5f) << what;
    EXPECT_NEAR(got.y, want.y, 1e-5f) << what;
    EXPECT_NEAR(got.z, want.z, 1e-5f) << what;
  };
  expectNear(colorMapColour(ColorMap::Viridis, 0.0f), linear(68, 1, 84), "viridis 0 (#440154)");
  expectNear(colorMapColour(ColorMap::Viridis, 0.5f), linear(33, 144, 141), "viridis 0.5 (#21908d)");
  expectNear(colorMapColour(ColorMap::Viridis, 1.0f), linear(253, 231, 37), "viridis 1 (#fde725)");
  expectNear(colorMapColour(ColorMap::Magma, 0.0f), linear(0, 0, 4), "magma 0 (#000004)");
  expectNear(colorMapColour(ColorMap::Magma, 1.0f), linear(252, 253, 191), "magma 1 (#fcfdbf)");
  expectNear(colorMapColour(ColorMap::Coolwarm, 0.5f), linear(221, 221, 221), "coolwarm 0.5");
  expectNear(colorMapColour(ColorMap::Blues, 0.0f), linear(247, 251, 255), "blues 0 (#f7fbff)");
  expectNear(colorMapColour(ColorMap::Blues, 1.0f), linear(8, 48, 107), "blues 1 (#08306b)");
  // Between control points: linear in sRGB, halfway between 0 and 1/8 of viridis.
  const glm::vec3 halfway(srgbToLinear(69.5f / 255.0f), srgbToLinear(22.5f / 255.0f), srgbToLinear(103.0f / 255.0f));
  expectNear(colorMapColour(ColorMap::Viridis, 1.0f / 16.0f), halfway, "viridis 1/16");
}

TEST(ColorMap, ClampsAndTreatsNaNAsTheLowEnd) {
  for (ColorMap map : kMaps) {
    EXPECT_EQ(colorMapColour(map, -3.0f), colorMapColour(map, 0.0f));
    EXPECT_EQ(colorMapColour(map, 7.0f), colorMapColour(map, 1.0f));
    EXPECT_EQ(colorMapColour(map, std::nanf("")), colorMapColour(map, 0.0f));
    EXPECT_EQ(colorMapColour(map, -INFINITY), colorMapColour(map, 0.0f));
    EXPECT_EQ(colorMapColour(map, INFINITY), colorMapColour(map, 1.0f));
  }
}

TEST(ColorMap, SequentialMapsAreMonotoneAndTheDivergingOneGoesBlueToRed) {
  for (int i = 1; i <= 64; ++i) {
    const float a = float(i - 1) / 64.0f, b = float(i) / 64.0f;
    EXPECT_GT(luminance(colorMapColour(ColorMap::Viridis, b)), luminance(colorMapColour(ColorMap::Viridis, a))) << b;
    EXPECT_GT(luminance(colorMapColour(ColorMap::Magma, b)), luminance(colorMapColour(ColorMap::Magma, a))) << b;
    EXPECT_LT(luminance(colorMapColour(ColorMap::Blues, b)), luminance(colorMapColour(ColorMap::Blues, a))) << b;
  }
  const glm::vec3 cold = colorMapColour(ColorMap::Coolwarm, 0.0f), hot = colorMapColour(ColorMap::Coolwarm, 1.0f);
  EXPECT_GT(cold.z, 2.0f * cold.x);
  EXPECT_GT(hot.x, 5.0f * hot.z);
}

TEST(ColorMap, TheMapsDifferFromEachOther) {
  for (std::size_t a = 0; a < 4; ++a)
    for (std::size_t b = a + 1; b < 4; ++b) {
      float total = 0;
      for (int i = 0; i <= 16; ++i)
        total += distance(colorMapColour(kMaps[a], i / 16.0f), colorMapColour(kMaps[b], i / 16.0f));
      EXPECT_GT(total / 17.0f, 0.1f) << colorMapName(kMaps[a]) << " vs " << colorMapName(kMaps[b]);
    }
}

TEST(ColorMap, NamesParseAndAnUnknownOneListsTheValidOnes) {
  for (ColorMap map : kMaps) EXPECT_EQ(parseColorMap(colorMapName(map)), map);
  EXPECT_EQ(colorMapNames(), "viridis, magma, coolwarm, blues");
  try {
    parseColorMap("jet");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--color-map: unknown colour map 'jet'; valid values: viridis, magma, "
                                         "coolwarm, blues"),
              std::string::npos)
        << e.what();
  }
}

float maxDifference(const std::vector<glm::vec4>& a, const std::vector<glm::vec4>& b) {
  float worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, glm::length(glm::vec3(a[i] - b[i])));
  return worst;
}

TEST(ShadingColorByAttribute, ChangesTheShadedSurfaceInEveryModeButNormals) {
  CpuScreenDevice device;
  for (ShadingMode mode : {ShadingMode::Liquid, ShadingMode::Spheres, ShadingMode::Attribute, ShadingMode::Normals}) {
    SCOPED_TRACE(int(mode));
    ShadingOptions plain;
    plain.mode = mode;
    ShadingOptions viridis = plain, magma = plain;
    viridis.colorByAttribute = magma.colorByAttribute = true;
    magma.colorMap = ColorMap::Magma;
    const auto a = testing::shadeRamp(device, plain), b = testing::shadeRamp(device, viridis),
               c = testing::shadeRamp(device, magma);
    if (mode == ShadingMode::Normals) {
      EXPECT_EQ(maxDifference(a, b), 0.0f);
      continue;
    }
    EXPECT_GT(maxDifference(a, b), 0.1f);
    EXPECT_GT(maxDifference(b, c), 0.1f);
    // The background (the top rows) is the same.
    for (std::size_t i = 0; i < 64 * 4; ++i) ASSERT_EQ(a[i], b[i]) << i;
  }
}

TEST(ShadingColorByAttribute, TheLitSurfaceIsTheMapsColourTimesTheLight) {
  // In attribute mode the colour is albedo * light + highlight, the light and highlight the same
  // in every column of a row: so columns differ exactly as the colour map's colours, scaled.
  CpuScreenDevice device;
  ShadingOptions options;
  options.mode = ShadingMode::Attribute;
  options.colorByAttribute = true;
  options.colorMap = ColorMap::Coolwarm;
  options.specular = 0;
  const std::uint32_t width = 64, y = 10;
  const auto out = testing::shadeRamp(device, options, width);
  const glm::vec3 first = colorMapColour(options.colorMap, 0.0f);
  const glm::vec3 light = glm::vec3(out[y * width]) / first;
  for (std::uint32_t x = 0; x < width; ++x) {
    const glm::vec3 expected = colorMapColour(options.colorMap, testing::rampAttribute(x, width)) * light;
    const glm::vec3 got(out[y * width + x]);
    EXPECT_LT(distance(got, expected), 1e-4f) << x;
  }
}

TEST(ShadingColorByAttribute, TheColourRangePlacesTheFramesValuesOnTheMap) {
  // The frame's attribute spans 10..20; a range 10..30 puts its top at the middle of the map,
  // so the ramp shows the lower half of the map: column x as the full range's value x / 2.
  CpuScreenDevice device;
  ShadingOptions full;
  full.mode = ShadingMode::Attribute;
  full.colorByAttribute = true;
  full.specular = 0;  // the highlight follows the pixel's ray; the rest of the light does not
  ShadingOptions ranged = full;
  ranged.colorRange = glm::vec2(10.0f, 30.0f);
  const std::uint32_t width = 65, y = 10;
  const auto narrow = testing::shadeRamp(device, ranged, width, 16, 10.0f, 20.0f);
  const auto wide = testing::shadeRamp(device, full, width, 16, 10.0f, 20.0f);
  for (std::uint32_t x = 0; x < width; x += 2)
    EXPECT_LT(glm::length(glm::vec3(narrow[y * width + x] - wide[y * width + x / 2])), 1e-3f) << x;
  // The frame's own range (no colorRange) is the same as a range equal to it.
  ShadingOptions same = full;
  same.colorRange = glm::vec2(10.0f, 20.0f);
  EXPECT_LT(maxDifference(testing::shadeRamp(device, same, width, 16, 10.0f, 20.0f), wide), 1e-5f);
}

}  // namespace
}  // namespace flipscope
