// RenderRequest: what a user asks of a render (the command line of `render`, `view` and `demo`)
// before a store is known, and its resolution against a store: the defaults that depend on the
// data (the sphere radius from the particle spacing, colour by the attribute, the colour range
// over the store's frames).
#pragma once

#include <optional>
#include <string>

#include <glm/vec3.hpp>

#include "pipeline/FramePipeline.h"
#include "preprocess/store/BrickStore.h"
#include "raycast/Camera.h"
#include "streaming/BrickSource.h"

namespace flipscope {

struct RenderRequest {
  RenderSettings settings;      ///< settings.radius is replaced by `radius`
  std::optional<float> radius;  ///< sphere radius in cells; default: defaultSphereRadius(store)
  SurfaceSettings surface;      ///< smoothing and shading; surface.up is set from `up`
  /// Colour by the store's attribute (--color-by). Unset: when the shading mode is `attribute`
  /// and the store has one. When set, an unset surface.shading.colorRange becomes the store's
  /// attribute range.
  std::optional<bool> colorByAttribute;
  /// The scene's up axis (the default camera's, the navigation's, the sky's); unset: the one
  /// the store records (StoreHeader::upAxis), +y when it records none.
  std::optional<UpAxis> up;
  /// The output keeps the attribute's values (an EXR's channel); false for a PNG. Without it,
  /// a look that does not colour by the attribute reads none (RenderSettings::attributes).
  bool attributeOutput = true;
};

struct ResolvedRender {
  RenderSettings settings;
  SurfaceSettings surface;  ///< surface.up: the scene's up axis, as a unit vector
};

/// The settings `request` gives for `store`. Throws InputError naming `store` when colour by
/// attribute is asked of a store without one. settings.attributes: whether the output or the
/// look uses the store's attribute.
ResolvedRender resolve(const RenderRequest& request, const BrickStore& store);

/// The camera a render frames when none is given: frameOnBox over the framedBounds of every
/// frame of [first, last] (one camera for a whole flipbook: the occupied cells less particles
/// flung far away, whose count goes to `particlesLeftOut` when given), or over the domain when
/// they hold no brick. Throws FileError naming the source when no camera can frame it.
Camera defaultRenderCamera(BrickSource& source, int first, int last, std::uint32_t width, std::uint32_t height,
                           glm::dvec3 up, std::uint64_t* particlesLeftOut = nullptr);

/// What to tell a user whose default camera left out `particlesLeftOut` (> 0) particles far from
/// the liquid (in one frame, or the most in any frame of a flipbook).
std::string framingNote(std::uint64_t particlesLeftOut, bool flipbook);

}  // namespace flipscope
