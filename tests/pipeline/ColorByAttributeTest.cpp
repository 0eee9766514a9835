// Colouring by the stored attribute through the frame pipeline (CPU reference): a ball whose
// particles' speed grows along x, rendered with and without colour and with two colour maps; the
// image's attribute channel (values in the frame's range, growing along x) and its EXR channel.
#include <gtest/gtest.h>

#include <cmath>

#include "TestSupport.h"
#include "core/Error.h"
#include "pipeline/FramePipeline.h"
#include "pipeline/RenderRequest.h"
#include "raycast/RaycastScenes.h"

namespace flipscope {
namespace {

/// The ball scene's store with velocities (speed = x / 32): its attribute is speed.
BrickStore speedBall(const std::filesystem::path& dir) {
  const testing::BallScene ball;
  const auto particles = testing::ballParticles(ball.centre, ball.radius);
  std::vector<glm::vec3> velocities;
  for (const auto& p : particles) velocities.emplace_back(p.x / 32.0f, 0.0f, 0.0f);
  return testing::makeStore(dir, {particles}, 96.0f, 32, {velocities});
}

RenderImage render(const BrickStore& store, ShadingMode mode, bool colour, ColorMap map = ColorMap::Viridis,
                   std::optional<glm::vec2> range = std::nullopt) {
  const testing::BallScene ball;
  SurfaceSettings surface;
  surface.shading.mode = mode;
  surface.shading.colorByAttribute = colour;
  surface.shading.colorMap = map;
  surface.shading.colorRange = range;
  FramePipeline pipeline(store, DeviceChoice::Cpu, ball.settings(), surface);
  return pipeline.render(0, ball.camera()).image;
}

/// Largest colour difference over the pixels, and how many pixels differ by more than 0.02.
std::pair<float, int> difference(const RenderImage& a, const RenderImage& b) {
  float worst = 0;
  int pixels = 0;
  for (std::size_t i = 0; i < a.rgba.size(); ++i) {
    const float d = glm::length(glm::vec3(a.rgba[i] - b.rgba[i]));
    worst = std::max(worst, d);
    pixels += d > 0.02f;
  }
  return {worst, pixels};
}

TEST(ColorByAttribute, ChangesTheLiquidAndTheSpheresAndTheMapsDiffer) {
  testing::TempDir dir("color-by");
  const BrickStore store = speedBall(dir.path() / "store");
  for (ShadingMode mode : {ShadingMode::Liquid, ShadingMode::Spheres}) {
    SCOPED_TRACE(int(mode));
    const RenderImage plain = render(store, mode, false), viridis = render(store, mode, true),
                      magma = render(store, mode, true, ColorMap::Magma);
    const auto [byColour, colourPixels] = difference(plain, viridis);
    EXPECT_GT(byColour, 0.1f);
    EXPECT_GT(colourPixels, 500);  // the disk covers about 1500 pixels
    const auto [byMap, mapPixels] = difference(viridis, magma);
    EXPECT_GT(byMap, 0.1f);
    EXPECT_GT(mapPixels, 500);
    // Background pixels (no hit) are the same in every image.
    for (std::size_t i = 0; i < plain.rgba.size(); ++i)
      if (!std::isfinite(plain.depth[i])) {
        ASSERT_EQ(plain.rgba[i], viridis.rgba[i]) << i;
      }
  }
}

TEST(ColorByAttribute, TheImageCarriesTheAttributeInItsUnits) {
  testing::TempDir dir("color-attr");
  const BrickStore store = speedBall(dir.path() / "store");
  const FrameStats stats = store.frame(0)->stats;
  EXPECT_GT(stats.attributeMax, stats.attributeMin);
  const RenderImage image = render(store, ShadingMode::Liquid, false);
  EXPECT_EQ(image.attributeName, "speed");
  ASSERT_EQ(image.attribute.size(), image.rgba.size());
  // Speed grows with x: along the disk's middle row, left hits are slower than right ones.
  const std::uint32_t y = image.height / 2;
  float left = NAN, right = NAN;
  int hits = 0;
  for (std::uint32_t x = 0; x < image.width; ++x) {
    const std::size_t i = y * image.width + x;
    if (!std::isfinite(image.depth[i])) {
      EXPECT_EQ(image.attribute[i], 0.0f);
      continue;
    }
    ++hits;
    EXPECT_GE(image.attribute[i], stats.attributeMin - 1e-4f);
    EXPECT_LE(image.attribute[i], stats.attributeMax + 1e-4f);
    if (std::isnan(left)) left = image.attribute[i];
    right = image.attribute[i];
  }
  ASSERT_GT(hits, 20);
  // The ball spans x = 22..74: speeds about 0.7 and 2.3 at its silhouette.
  EXPECT_NEAR(left, 22.5f / 32.0f, 0.15f);
  EXPECT_NEAR(right, 74.5f / 32.0f, 0.15f);
  // The EXR carries it as a channel named after the attribute.
  const auto path = dir.path() / "a.exr";
  writeExr(path, image);
  const ExrContents exr = readExr(path);
  ASSERT_EQ(exr.others.count("speed"), 1u);
  EXPECT_EQ(exr.others.at("speed"), image.attribute);
  EXPECT_EQ(attributeChannel("Z"), "attribute.Z");
  EXPECT_EQ(attributeChannel("pscale"), "pscale");
}

TEST(ColorByAttribute, ARangeEqualToTheFramesChangesNothingAndAWiderOneDoes) {
  testing::TempDir dir("color-range");
  const BrickStore store = speedBall(dir.path() / "store");
  const FrameStats stats = store.frame(0)->stats;
  const RenderImage own = render(store, ShadingMode::Spheres, true);
  const RenderImage same =
      render(store, ShadingMode::Spheres, true, ColorMap::Viridis, glm::vec2(stats.attributeMin, stats.attributeMax));
  EXPECT_LT(difference(own, same).first, 1e-4f);
  const RenderImage wider = render(store, ShadingMode::Spheres, true, ColorMap::Viridis, glm::vec2(0.0f, 10.0f));
  EXPECT_GT(difference(own, wider).first, 0.1f);
}

TEST(ColorByAttribute, AStoreWithoutAttributeIsRefused) {
  testing::TempDir dir("color-none");
  const testing::BallScene ball;
  SurfaceSettings surface;
  surface.shading.colorByAttribute = true;
  EXPECT_THROW(FramePipeline(ball.makeStore(dir.path() / "store"), DeviceChoice::Cpu, ball.settings(), surface),
               InputError);
  const RenderImage plain = render(ball.makeStore(dir.path() / "plain"), ShadingMode::Liquid, false);
  EXPECT_TRUE(plain.attribute.empty());
}

TEST(ColorByAttribute, AnImageThatShowsNoAttributeReadsNone) {
  // RenderSettings::attributes off (a PNG, no colour by it): the bricks come without their
  // values (StoreBrickSource), the pool without their ring, the image without the channel; the
  // look is the same to the bit.
  testing::TempDir dir("color-read-none");
  const BrickStore store = speedBall(dir.path() / "store");
  const testing::BallScene ball;
  for (ShadingMode mode : {ShadingMode::Liquid, ShadingMode::Spheres}) {
    SCOPED_TRACE(int(mode));
    SurfaceSettings surface;
    surface.shading.mode = mode;
    RenderSettings settings = ball.settings();
    FramePipeline with(store, DeviceChoice::Cpu, settings, surface);
    settings.attributes = false;
    FramePipeline without(store, DeviceChoice::Cpu, settings, surface);
    EXPECT_TRUE(with.renderer().source().carriesAttributes());
    EXPECT_FALSE(without.renderer().source().carriesAttributes());
    const BrickKey key{0, store.frame(0)->bricks.front().coord};
    EXPECT_FALSE(with.renderer().source().read(key)->attributes.empty());
    EXPECT_TRUE(without.renderer().source().read(key)->attributes.empty());
    const FrameOutput a = with.render(0, ball.camera());
    const FrameOutput b = without.render(0, ball.camera());
    ASSERT_EQ(a.image.rgba.size(), b.image.rgba.size());
    for (std::size_t i = 0; i < a.image.rgba.size(); ++i) {
      ASSERT_EQ(a.image.rgba[i], b.image.rgba[i]) << "pixel " << i;
      ASSERT_EQ(std::isfinite(a.image.depth[i]), std::isfinite(b.image.depth[i])) << "pixel " << i;
    }
    EXPECT_EQ(a.image.attribute.size(), a.image.rgba.size());
    EXPECT_TRUE(b.image.attribute.empty());
    EXPECT_TRUE(b.image.attributeName.empty());
    EXPECT_LT(b.stats.poolBytes, a.stats.poolBytes);
  }
}

TEST(ColorByAttribute, TheAttributeIsReadWhereTheOutputOrTheLookUsesIt) {
  testing::TempDir dir("color-resolve");
  const BrickStore store = speedBall(dir.path() / "store");
  const auto attributes = [&](bool output, std::optional<bool> colour, ShadingMode mode) {
    RenderRequest request;
    request.attributeOutput = output;
    request.colorByAttribute = colour;
    request.surface.shading.mode = mode;
    return resolve(request, store).settings.attributes;
  };
  EXPECT_TRUE(attributes(true, std::nullopt, ShadingMode::Liquid));  // an EXR's channel
  EXPECT_FALSE(attributes(false, std::nullopt, ShadingMode::Liquid));
  EXPECT_FALSE(attributes(false, std::nullopt, ShadingMode::Spheres));
  EXPECT_TRUE(attributes(false, true, ShadingMode::Liquid));
  EXPECT_TRUE(attributes(false, std::nullopt, ShadingMode::Attribute));
  const BrickStore plain = testing::BallScene().makeStore(dir.path() / "plain");
  RenderRequest request;
  EXPECT_FALSE(resolve(request, plain).settings.attributes);  // none to read
}

}  // namespace
}  // namespace flipscope
