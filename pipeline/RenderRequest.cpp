#include "pipeline/RenderRequest.h"

#include "core/Error.h"

namespace flipscope {

ResolvedRender resolve(const RenderRequest& request, const BrickStore& store) {
  ResolvedRender out{request.settings, request.surface};
  const StoreHeader& header = store.header();
  out.settings.radius = request.radius.value_or(defaultSphereRadius(header, out.settings.jitter));
  out.surface.up = upAxisVector(request.up.value_or(header.upAxis));
  const bool hasAttribute = header.attribute != AttributeKind::None;
  if (request.colorByAttribute.value_or(false) && !hasAttribute)
    throw InputError(store.directory().string() +
                     ": the store has no per-particle attribute to colour by (--color-by attribute); "
                     "convert with --attribute NAME");
  out.surface.shading.colorByAttribute =
      request.colorByAttribute.value_or(out.surface.shading.mode == ShadingMode::Attribute && hasAttribute);
  out.settings.attributes = hasAttribute && (request.attributeOutput || out.surface.shading.colorByAttribute ||
                                             out.surface.shading.mode == ShadingMode::Attribute);
  if (out.surface.shading.colorByAttribute && !out.surface.shading.colorRange)
    if (const auto range = store.attributeRange(); range && range->max > range->min)
      out.surface.shading.colorRange = glm::vec2(range->min, range->max);
  return out;
}

Camera defaultRenderCamera(BrickSource& source, int first, int last, std::uint32_t width, std::uint32_t height,
                           glm::dvec3 up, std::uint64_t* particlesLeftOut) {
  const FramedBounds framed = framedBounds(source, first, last);
  if (particlesLeftOut) *particlesLeftOut = framed.particlesLeftOut;
  Box bounds = framed.box;
  if (bounds.isEmpty()) bounds = Box{source.header().origin, source.header().domainMax()};
  try {
    return frameOnBox(bounds, double(width) / height, up);
  } catch (const InputError& e) {
    throw FileError(source.name(), e.what());
  }
}

std::string framingNote(std::uint64_t particlesLeftOut, bool flipbook) {
  return "the camera frames the liquid and leaves out " + std::string(flipbook ? "up to " : "") +
         std::to_string(particlesLeftOut) + " particle" + (particlesLeftOut == 1 ? "" : "s") +
         (flipbook ? " a frame" : "") + " far from it (give --camera or --camera-file to frame them)";
}

}  // namespace flipscope
