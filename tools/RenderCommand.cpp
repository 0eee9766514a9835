// flipscope render: brick store frames -> EXR (R G B A Z unsmoothed.Z thickness N.*) or PNG
// previews of the smoothed, shaded liquid surface, headless.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <memory>

#include "core/Error.h"
#include "preprocess/particles/InputSequence.h"
#include "tools/Commands.h"
#include "tools/RenderJob.h"
#include "tools/RenderOptions.h"

namespace flipscope::tools {
namespace {

struct RenderArgs {
  std::string store;
  std::string output;
  std::optional<int> frame;
  std::string frames;
  RenderLookArgs look;
  bool quiet = false;
};

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
  ParsedLook look = parseRenderLook(a.look);
  static_cast<RenderRequest&>(job) = look.request;
  job.camera = look.camera;
  job.device = look.device;
  job.saveCamera = a.look.saveCamera;
  job.quiet = a.quiet;
  const auto files = runRenderJob(job);
  const auto unconverged = std::count_if(files.begin(), files.end(), [](const RenderedFile& f) { return !f.stats.converged; });
  if (unconverged > 0)
    throw CommandFailed("render: " + std::to_string(unconverged) + " of " + std::to_string(files.size()) +
                            " frame(s) stopped at --max-passes " + std::to_string(a.look.maxPasses) +
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
  addRenderLookOptions(*cmd, args->look);
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing");
  cmd->callback([args] { runRender(*args); });
}

}  // namespace flipscope::tools
