// The CPU thickness blur against its reference, gbufferBlurThickness compiled from GBuffer.glsl.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <random>
#include <utility>
#include <vector>

#include "pipeline/GBufferPasses.h"

namespace flipscope {
namespace {

/// A surface image (x depth, y mask, z thickness, w attribute) of `width` x `height`: two
/// surfaces apart by more than the blur's depth tolerance, and background, at random.
std::vector<glm::vec4> randomSurface(std::uint32_t width, std::uint32_t height, float radius, std::mt19937& random) {
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<glm::vec4> image(std::size_t(width) * height);
  for (glm::vec4& pixel : image) {
    const float pick = unit(random);
    if (pick < 0.2f) {
      pixel = glm::vec4(0.0f);  // background
      continue;
    }
    const float depth = (pick < 0.6f ? 2.0f : 2.0f + 5.0f * radius) + radius * unit(random);  // two surfaces
    pixel = glm::vec4(depth, 1.0f, 10.0f * unit(random), unit(random));
  }
  return image;
}

TEST(GBufferPasses, TheCpuThicknessBlurIsItsReferenceBitForBit) {
  std::mt19937 random(11);
  std::uint64_t blurred = 0;  // foreground pixels compared
  for (const auto& [width, height] : {std::pair{1u, 1u}, {5u, 3u}, {37u, 29u}, {64u, 48u}}) {
    // Blur radii of 1 to 8 pixels: int(focalPixels * particleRadius / depth) clamped to [1, 8],
    // over the two surfaces' depths (2 to 2.25, 3.25 to 3.5), gives 1; 1; 2 to 4; 3 to 6; 4 to 7; 8.
    for (const float focalPixels : {1.0f, 12.0f, 40.0f, 52.0f, 64.0f, 400.0f}) {
      SCOPED_TRACE(::testing::Message() << width << "x" << height << ", focal " << focalPixels);
      const float radius = 0.25f;
      const std::vector<glm::vec4> surface = randomSurface(width, height, radius, random);
      CpuPassInputs inputs;
      inputs.frame.width = width;
      inputs.frame.height = height;
      inputs.frame.focalPixels = focalPixels;
      inputs.frame.particleRadius = radius;
      inputs.images[0] = surface.data();
      inputs.sizes[0] = surface.size();
      std::vector<glm::vec4> fast(surface.size(), glm::vec4(-1.0f)), reference(surface.size(), glm::vec4(-2.0f));
      kBlurThickness.cpu(inputs, nullptr, fast.data(), nullptr);
      kBlurThicknessReference.cpu(inputs, nullptr, reference.data(), nullptr);
      EXPECT_EQ(std::memcmp(fast.data(), reference.data(), fast.size() * sizeof(glm::vec4)), 0);
      for (std::size_t i = 0; i < surface.size(); ++i) {
        if (surface[i].y < 0.5f) continue;
        ++blurred;
        EXPECT_EQ(fast[i].x, surface[i].x);  // only the thickness changes
      }
    }
  }
  EXPECT_GT(blurred, 5000u);
}

}  // namespace
}  // namespace flipscope
