#include "raycast/Shading.h"

#include <cmath>
#include <limits>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

namespace flipscope {

RenderImage shade(const RenderResult& result, const Camera& camera, const ShadingOptions& options) {
  RenderImage image;
  image.width = result.width;
  image.height = result.height;
  const std::size_t pixels = std::size_t(result.width) * result.height;
  image.rgba.assign(pixels, glm::vec4(0));
  image.depth.assign(pixels, std::numeric_limits<float>::infinity());
  image.normal.assign(pixels, glm::vec3(0));
  const glm::dvec3 l = double(options.lightFromCamera.x) * camera.right() +
                       double(options.lightFromCamera.y) * camera.trueUp() -
                       double(options.lightFromCamera.z) * camera.forward();
  const glm::vec3 light = glm::normalize(glm::vec3(l));
  for (std::uint32_t y = 0; y < result.height; ++y) {
    for (std::uint32_t x = 0; x < result.width; ++x) {
      const std::size_t i = std::size_t(y) * result.width + x;
      const RayHit& hit = result.hits[i];
      if (hit.status != kRayHit) continue;
      const glm::vec3 n(hit.normal);
      const glm::vec3 view = -glm::vec3(camera.pixelRay(x, y, result.width, result.height));
      const float diffuse = std::max(0.0f, glm::dot(n, light));
      const glm::vec3 halfway = glm::normalize(light + view);
      const float highlight = diffuse > 0 ? std::pow(std::max(0.0f, glm::dot(n, halfway)), options.shininess) : 0.0f;
      const glm::vec3 albedo = glm::mix(options.slowColour, options.fastColour, glm::clamp(hit.normal.w, 0.0f, 1.0f));
      const glm::vec3 colour =
          albedo * (options.ambient + (1 - options.ambient) * diffuse) + glm::vec3(options.specular * highlight);
      image.rgba[i] = glm::vec4(colour, 1.0f);
      image.depth[i] = hit.depth;
      image.normal[i] = n;
    }
  }
  return image;
}

}  // namespace flipscope
