// flipscope render: brick store frames -> EXR (R G B A Z unsmoothed.Z thickness N.*) or PNG
// previews of the smoothed, shaded liquid surface, headless.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <tuple>

#include "core/Error.h"
#include "preprocess/particles/InputSequence.h"
#include "tools/CliValues.h"
#include "tools/Commands.h"
#include "smoothing/SurfaceFilter.h"
#include "smoothing/SurfaceShading.h"
#include "tools/RenderJob.h"

namespace flipscope::tools {
namespace {

struct RenderArgs {
  std::string store;
  std::string output;
  std::optional<int> frame;
  std::string frames;
  std::string size = "1280x720";
  std::string camera;
  std::string cameraFile;
  std::string saveCamera;
  std::string up = "y";
  std::optional<float> radius;
  std::string smoothing = "rof";
  std::optional<int> smoothingIterations;
  std::optional<float> smoothingStrength;
  std::string shading = "liquid";
  std::string colorBy;  ///< empty: not given
  std::optional<std::string> colorMap;
  std::optional<std::string> colorRange;
  std::string environment;
  std::string jitter = "on";
  std::string foam = "volume";
  std::string foamFrom = "both";
  float foamThreshold = 0.2f;
  std::string bubbles = "hide";
  std::string gpuMem = "1G";
  std::string cpuMem = "2G";
  std::string device = "auto";
  int maxPasses = 1000;
  bool quiet = false;
};

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

void runRender(const RenderArgs& a) {
  RenderJob job;
  job.store = a.store;
  job.output = a.output;
  if (a.frame) job.firstFrame = job.lastFrame = *a.frame;
  if (!a.frames.empty()) {
    const FrameRange range = parseFrameRange(a.frames);
    job.firstFrame = range.first;
    job.lastFrame = range.last;
  }
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
    throw InputError("--smoothing-strength: must be 0 or more, got " + std::to_string(*a.smoothingStrength));
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
  if (!a.camera.empty()) job.camera = parseCamera("--camera", a.camera);
  if (!a.cameraFile.empty()) job.camera = loadCamera(a.cameraFile);
  job.saveCamera = a.saveCamera;
  job.up = parseUpAxis("--up", a.up);
  job.device = parseDeviceChoice("--device", a.device);
  job.quiet = a.quiet;
  const auto files = runRenderJob(job);
  const auto unconverged = std::count_if(files.begin(), files.end(), [](const RenderedFile& f) { return !f.stats.converged; });
  if (unconverged > 0)
    throw CommandFailed("render: " + std::to_string(unconverged) + " of " + std::to_string(files.size()) +
                            " frame(s) stopped at --max-passes " + std::to_string(a.maxPasses) +
                            " before every ray finished; the images are written but incomplete (raise --max-passes, "
                            "or give --gpu-mem enough for the frame)",
                        kExitNotConverged);
}

}  // namespace

void addRenderCommand(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  auto* cmd = app.add_subcommand("render", "Render brick store frames headless to EXR (R G B A Z N thickness foam) or PNG");
  cmd->add_option("store", args->store, "Brick store directory")->required();
  cmd->add_option("-o,--output", args->output, "Output .exr or .png; '####' takes the frame number")->required();
  auto* frame = cmd->add_option("--frame", args->frame, "Frame to render (default: the first)");
  cmd->add_option("--frames", args->frames, "Frame range A-B (a flipbook; needs '#' in the output name)")
      ->excludes(frame);
  cmd->add_option("--size", args->size, "Image size WxH")->capture_default_str();
  auto* camera = cmd->add_option("--camera", args->camera, "ex,ey,ez,tx,ty,tz,ux,uy,uz,fov (world units, degrees)");
  cmd->add_option("--camera-file", args->cameraFile, "JSON {\"eye\", \"target\", \"up\", \"fov\"}")->excludes(camera);
  cmd->add_option("--save-camera", args->saveCamera, "Write the camera of the render to this JSON file (--camera-file reads it)");
  cmd->add_option("--up", args->up, "Up axis of the default camera framed on the data (x, y or z)")
      ->capture_default_str();
  cmd->add_option("--radius", args->radius,
                  "Sphere radius in cells (default: the store's particle spacing, at least 1 cell)");
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
  cmd->add_option("--gpu-mem", args->gpuMem, "Brick pool budget on the device")->capture_default_str();
  cmd->add_option("--cpu-mem", args->cpuMem, "Converted-brick cache in CPU memory")->capture_default_str();
  cmd->add_option("--device", args->device, "auto: OpenGL through EGL, else the CPU reference; gpu; cpu")
      ->check(CLI::IsMember({"auto", "gpu", "cpu"}))
      ->capture_default_str();
  cmd->add_option("--max-passes", args->maxPasses, "Ray-casting passes per frame at most")->capture_default_str();
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing");
  cmd->callback([args] { runRender(*args); });
}

}  // namespace flipscope::tools
