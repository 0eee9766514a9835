// A synthetic G-buffer for the shading pass: a plane facing the camera whose attribute ramps from
// 0 at the left edge to 1 at the right, so that colouring by attribute shows the colour map
// across the image. Shared by the CPU and the GPU shading tests.
#pragma once

#include <vector>

#include "smoothing/SmoothingScenes.h"
#include "smoothing/SurfaceShading.h"

namespace flipscope::testing {

/// The attribute (G-buffer w) of column x of a ramp `width` pixels wide.
inline float rampAttribute(std::uint32_t x, std::uint32_t width) { return float(x) / float(width - 1); }

/// Shades the ramp (width x height, the top quarter background) on `device` with `options`,
/// the G-buffer's 0..1 standing for frameMin..frameMax. Returns the shaded pixels.
inline std::vector<glm::vec4> shadeRamp(ScreenDevice& device, const ShadingOptions& options, std::uint32_t width = 64,
                                        std::uint32_t height = 16, float frameMin = 0.0f, float frameMax = 1.0f) {
  const ScreenFrame frame = testFrame(width, height, 0.05f);
  device.setFrame(frame);
  std::vector<glm::vec4> gbuffer(std::size_t(width) * height), normals(gbuffer.size()), spheres(gbuffer.size());
  for (std::uint32_t y = 0; y < height; ++y)
    for (std::uint32_t x = 0; x < width; ++x) {
      const std::size_t i = std::size_t(y) * width + x;
      if (y < height / 4) continue;  // background: the procedural sky
      // A slightly tilted plane: the sun highlight and Fresnel vary a little across it.
      const glm::vec3 n = glm::normalize(glm::vec3(0.2f * (float(y) / float(height) - 0.5f), 0.1f, 1.0f));
      gbuffer[i] = glm::vec4(5.0f, 1.0f, 0.05f * float(1 + x % 5), rampAttribute(x, width));
      normals[i] = glm::vec4(n, 1.0f);
      spheres[i] = glm::vec4(glm::normalize(n + glm::vec3(0.3f * float(x % 3) - 0.3f, 0.0f, 0.0f)), 1.0f);
    }
  const ScreenImage g = device.createFrameImage(), n = device.createFrameImage(), s = device.createFrameImage(),
                    out = device.createFrameImage();
  device.upload(g, gbuffer);
  device.upload(n, normals);
  device.upload(s, spheres);
  SurfaceShading shading(device, options, EnvironmentMap{});
  shading.setFrameAttributeRange(frameMin, frameMax);
  shading.shade(device, g, n, s, out);
  return device.download(out);
}

}  // namespace flipscope::testing
