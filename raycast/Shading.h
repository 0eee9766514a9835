// Plain shading of the ray-caster's hits (Lambert diffuse plus a Blinn highlight from one key
// light), enough to judge a cache; smoothing and the final fluid look come with the surface
// stage (smoothing/). Colour follows the stored attribute (speed) when the store has one.
#pragma once

#include <glm/vec3.hpp>

#include "raycast/Camera.h"
#include "raycast/FrameRenderer.h"
#include "raycast/ImageWriter.h"

namespace flipscope {

struct ShadingOptions {
  glm::vec3 slowColour{0.05f, 0.26f, 0.55f};        ///< attribute 0, or every hit without attributes
  glm::vec3 fastColour{0.80f, 0.92f, 1.00f};        ///< attribute 1 (fastest particles of the frame)
  glm::vec3 lightFromCamera{-0.45f, 0.75f, 0.50f};  ///< towards the light: right, up, backwards
  float ambient = 0.18f;
  float specular = 0.35f;
  float shininess = 40.0f;
};

/// The shaded image (linear RGB, premultiplied alpha 1 on hits, 0 elsewhere) with camera depth
/// (+inf where nothing was hit) and world-space normals.
RenderImage shade(const RenderResult& result, const Camera& camera, const ShadingOptions& options = {});

}  // namespace flipscope
