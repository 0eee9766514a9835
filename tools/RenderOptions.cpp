// The look options shared by `render` and `view` (tools/RenderOptions.h).
#include "tools/RenderOptions.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <stdexcept>
#include <tuple>

#include "core/Error.h"
#include "core/NumberText.h"
#include "raycast/FrameRenderer.h"
#include "smoothing/SurfaceFilter.h"
#include "smoothing/SurfaceShading.h"
#include "tools/CliValues.h"

namespace flipscope::tools {
namespace {

float parseJitter(const std::string& text) {
  if (text == "on") return 0.25f;
  if (text == "off") return 0.0f;
  try {
    std::size_t used = 0;
    const float cells = std::stof(text, &used);
    if (used == text.size()) return cells;
  } catch (const std::exception&) {
  }
  throw InputError("--jitter: expected on, off or a number of cells, got '" + text + "'");
}

/// "A,B" with A < B, both finite.
glm::vec2 parseColorRange(const std::string& text) {
  const auto fail = [&](const std::string& why) {
    return InputError("--color-range: " + why + ", got '" + text + "'; valid values: A,B with A < B (e.g. 0,2.5)");
  };
  const std::size_t comma = text.find(',');
  if (comma == std::string::npos || text.find(',', comma + 1) != std::string::npos)
    throw fail("expected two numbers A,B");
  float values[2];
  const std::string parts[2] = {text.substr(0, comma), text.substr(comma + 1)};
  for (int i = 0; i < 2; ++i) {
    try {
      std::size_t used = 0;
      values[i] = std::stof(parts[i], &used);
      if (used != parts[i].size()) throw fail("'" + parts[i] + "' is not a number");
    } catch (const std::logic_error&) {
      throw fail("'" + parts[i] + "' is not a number");
    }
    if (!std::isfinite(values[i])) throw fail("'" + parts[i] + "' is not finite");
  }
  if (!(values[0] < values[1])) throw fail("A must be less than B");
  return {values[0], values[1]};
}

}  // namespace

ParsedLook parseRenderLook(const RenderLookArgs& a) {
  ParsedLook look;
  RenderRequest& job = look.request;
  std::tie(job.settings.width, job.settings.height) = parseImageSize("--size", a.size);
  job.radius = a.radius;
  if (a.radius) {
    job.settings.radius = *a.radius;
    validate(job.settings);
  }
  job.surface.smoothing.name = a.smoothing;
  job.surface.smoothing.iterations = a.smoothingIterations.value_or(-1);
  job.surface.smoothing.strength = a.smoothingStrength.value_or(-1.0f);
  if (a.smoothingIterations && *a.smoothingIterations < 0)
    throw InputError("--smoothing-iterations: must be 0 or more, got " + std::to_string(*a.smoothingIterations));
  if (a.smoothingStrength && !(*a.smoothingStrength >= 0))
    throw InputError("--smoothing-strength: must be 0 or more, got " + numberText(*a.smoothingStrength));
  job.surface.smoothing = resolve(job.surface.smoothing);
  job.surface.shading.mode = parseShadingMode(a.shading);
  if (a.colorMap) job.surface.shading.colorMap = parseColorMap(*a.colorMap);
  if (a.colorRange) job.surface.shading.colorRange = parseColorRange(*a.colorRange);
  if (a.colorBy == "attribute")
    job.colorByAttribute = true;
  else if (a.colorBy == "none")
    job.colorByAttribute = false;
  else if (!a.colorBy.empty())
    throw InputError("--color-by: unknown value '" + a.colorBy + "'; valid values: attribute, none");
  else if (a.colorMap || a.colorRange)
    job.colorByAttribute = true;  // a colour map or range asks for colour
  job.surface.environment = a.environment;
  job.settings.jitter = parseJitter(a.jitter);
  job.settings.foam.mode = parseFoamMode(a.foam);
  job.settings.foam.source = parseFoamSource(a.foamFrom);
  job.settings.foam.threshold = a.foamThreshold;
  if (a.bubbles != "hide" && a.bubbles != "show")
    throw InputError("--bubbles: unknown value '" + a.bubbles + "'; valid values: hide, show");
  job.settings.foam.hideBubbles = a.bubbles == "hide";
  job.settings.gpuBudgetBytes = parseBytes("--gpu-mem", a.gpuMem);
  job.settings.cpuCacheBytes = parseBytes("--cpu-mem", a.cpuMem);
  job.settings.maxPasses = a.maxPasses;
  validate(job.settings);
  if (!a.camera.empty()) look.camera = parseCamera("--camera", a.camera);
  if (!a.cameraFile.empty()) look.camera = loadCamera(a.cameraFile);
  job.up = parseUpAxis("--up", a.up);
  look.device = parseDeviceChoice("--device", a.device);
  return look;
}

void addRenderLookOptions(CLI::App& command, RenderLookArgs& a) {
  CLI::App* cmd = &command;
  auto* args = &a;
  cmd->add_option("--size", args->size, "Image size WxH")->capture_default_str();
  auto* camera = cmd->add_option("--camera", args->camera, "ex,ey,ez,tx,ty,tz,ux,uy,uz,fov (world units, degrees)");
  cmd->add_option("--camera-file", args->cameraFile, "JSON {\"eye\", \"target\", \"up\", \"fov\"}")->excludes(camera);
  cmd->add_option("--save-camera", args->saveCamera, "Write the camera of the render to this JSON file (--camera-file reads it)");
  cmd->add_option("--up", args->up,
                  "The scene's up axis, for the default camera framed on the data and the sky: auto (the one the "
                  "store records, else y), x, y or z")
      ->capture_default_str();
  cmd->add_option("--radius", args->radius,
                  "Sphere radius in cells (default: " + numberText(kDefaultRadiusPerSpacing) +
                      " particle spacings of the store, at least 1 cell)");
  cmd->add_option("--smoothing", args->smoothing, "Surface filter: " + surfaceFilterNames())->capture_default_str();
  cmd->add_option("--smoothing-iterations", args->smoothingIterations,
                  "Filter iterations (default: the filter's; see README, Smoothing)");
  cmd->add_option("--smoothing-strength", args->smoothingStrength,
                  "Filter strength: lambda0 in particle radii for rof, the filter's size for the others");
  cmd->add_option("--shading", args->shading,
                  "liquid, spheres (lit spheres), attribute (the lit surface, coloured by the attribute) or normals")
      ->capture_default_str();
  cmd->add_option("--color-by", args->colorBy,
                  "attribute: colour by the store's per-particle attribute (the liquid dyed, the spheres' and lit "
                  "surface's albedo), none (default: attribute with --shading attribute, --color-map or "
                  "--color-range)");
  cmd->add_option("--color-map", args->colorMap,
                  "Colour map for --color-by attribute: " + colorMapNames() + " (default: viridis)");
  cmd->add_option("--color-range", args->colorRange,
                  "A,B: attribute values at the ends of the colour map (default: the store's range)");
  cmd->add_option("--env", args->environment, "Equirectangular EXR environment (default: procedural sky and ground)");
  cmd->add_option("--jitter", args->jitter, "Per-cell jitter: on (0.25 cells), off, or cells")->capture_default_str();
  cmd->add_option("--foam", args->foam,
                  "Foam: volume (rendered as a volume over the surface), remove (dropped, exposing the surface), "
                  "keep (spheres like the rest)")
      ->capture_default_str();
  cmd->add_option("--foam-from", args->foamFrom,
                  "What is foam: classify (cells with few neighbours), kind (the store's foam and spray particles), "
                  "both")
      ->capture_default_str();
  cmd->add_option("--foam-threshold", args->foamThreshold,
                  "A cell is foam when fewer than this fraction of the cells within the sphere radius are set (0..1)")
      ->capture_default_str();
  cmd->add_option("--bubbles", args->bubbles,
                  "Stores with particle kinds: hide (the bubbles inside the liquid) or show (as particles)")
      ->capture_default_str();
  cmd->add_option("--gpu-mem", args->gpuMem, "The most the brick pool on the device may take")->capture_default_str();
  cmd->add_option("--cpu-mem", args->cpuMem, "Converted-brick cache in CPU memory")->capture_default_str();
  cmd->add_option("--device", args->device, "auto: OpenGL through EGL on a hardware GPU, else the CPU; gpu; cpu; cpu-reference (the exact, slower CPU ray-caster)")
      ->check(CLI::IsMember({"auto", "gpu", "cpu", "cpu-reference"}))
      ->capture_default_str();
  cmd->add_option("--max-passes", args->maxPasses, "Ray-casting passes per frame at most")->capture_default_str();
}

}  // namespace flipscope::tools
