// flipscope view: the interactive previewer (viewer/window/ViewerApp.h) on a brick store, or on
// particle files that it converts into a cache store first.
#include <CLI/CLI.hpp>

#include <memory>

#include "core/Error.h"
#include "core/NumberText.h"
#include "core/ProcessMemory.h"
#include "gl/EglContext.h"
#include "tools/CliChecks.h"
#include "tools/CliValues.h"
#include "tools/Commands.h"
#include "tools/RenderOptions.h"
#include "viewer/window/ViewerApp.h"

namespace flipscope::tools {
namespace {

struct ViewArgs {
  std::vector<std::string> inputs;
  std::string cache;
  std::optional<int> frame;
  double scale = 0;
  double budgetMs = 25;
  int readAhead = 8;
  int readDelayMs = 0;
  std::string screenshot;
  std::string script;
  std::string stats;
  std::optional<std::uint32_t> resolution;
  std::optional<double> cellSize;
  RenderLookArgs look;
  bool quiet = false;
};

void runView(const ViewArgs& a) {
  keepHeapForReuse();  // core/ProcessMemory.h
  viewer::ViewerOptions o;
  o.inputs = a.inputs;
  o.cacheDir = a.cache;
  if (a.resolution) o.convertArgs.insert(o.convertArgs.end(), {"--resolution", std::to_string(*a.resolution)});
  if (a.cellSize) o.convertArgs.insert(o.convertArgs.end(), {"--cell-size", exactNumberText(*a.cellSize)});
  ParsedLook look = parseRenderLook(a.look);
  o.request = look.request;
  o.camera = look.camera;
  o.device = look.device;
  o.frame = a.frame;
  if (a.scale < 0 || a.scale > 2) throw InputError("--scale: must be in (0, 2], got " + numberText(a.scale));
  o.resolutionScale = a.scale;
  if (!(a.budgetMs > 0)) throw InputError("--budget-ms: must be positive");
  o.budgetMs = a.budgetMs;
  if (a.readAhead < 0) throw InputError("--read-ahead: must be 0 or more");
  o.readAheadFrames = a.readAhead;
  if (a.readDelayMs < 0) throw InputError("--read-delay-ms: must be 0 or more");
  o.readDelayMs = a.readDelayMs;
  o.screenshot = a.screenshot;
  o.script = a.script;
  o.saveCamera = a.look.saveCamera;
  o.statsFile = a.stats;
  o.program = "/proc/self/exe";
  o.quiet = a.quiet;
  int code = 0;
  try {
    code = viewer::runViewer(o);
  } catch (const gl::Unavailable& e) {
    throw CommandFailed(std::string("view: ") + e.what(), kExitFailure);
  }
  if (code == kExitNotConverged)
    throw CommandFailed("view: the screenshot stopped at --max-passes before every ray finished", code);
  if (code != 0) throw CommandFailed("view: exit " + std::to_string(code), code);
}

}  // namespace

void addViewCommand(CLI::App& app) {
  auto args = std::make_shared<ViewArgs>();
  auto* cmd = app.add_subcommand(
      "view", "Interactive previewer: orbit, zoom and scrub a brick store (or particle files, converted first)");
  cmd->add_option("input", args->inputs,
                  "A brick store directory, or particle files / sequence patterns (converted into a cache store)")
      ->required();
  cmd->add_option("--cache", args->cache, "Directory of the cache store of particle inputs (default: beside them)");
  auto* cell = cmd->add_option("--cell-size", args->cellSize, "Converting particle inputs: cell size in world units")
                   ->check(positiveNumber());
  cmd->add_option("--resolution", args->resolution, "Converting particle inputs: cells along the longest axis")
      ->check(positiveCount())
      ->excludes(cell);
  cmd->add_option("--frame", args->frame, "The frame shown first (default: the first)");
  cmd->add_option("--scale", args->scale,
                  "Render size / window size (default: 1 on a GPU, 0.5 on the CPU pipeline; 1 with --screenshot)");
  cmd->add_option("--budget-ms", args->budgetMs, "Ray-casting time per displayed frame, milliseconds")
      ->capture_default_str();
  cmd->add_option("--read-ahead", args->readAhead, "Frames prefetched in the playing direction, within --cpu-mem")
      ->capture_default_str();
  cmd->add_option("--read-delay-ms", args->readDelayMs,
                  "Wait this long before every brick read: try the viewer as on slow (network) storage");
  cmd->add_option("--screenshot", args->screenshot,
                  "Render the first frame once, converged, at --size, save it (.png or .exr) and exit");
  cmd->add_option("--script", args->script, "Timed input events to play (see README, \"The viewer\")");
  cmd->add_option("--stats", args->stats, "Write statistics as JSON here at exit (longest UI frame, camera, ...)");
  addRenderLookOptions(*cmd, args->look);
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing");
  cmd->callback([args] { runView(*args); });
}

}  // namespace flipscope::tools
