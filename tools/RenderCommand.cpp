// flipscope render: brick store frames -> EXR (R G B A Z unsmoothed.Z thickness N.*) or PNG
// previews of the smoothed, shaded liquid surface, headless. Given particle files instead of a
// store, it converts the frames it renders into a temporary store first (TemporaryStore), with
// convert's defaults, and removes it after.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "core/Error.h"
#include "core/Progress.h"
#include "preprocess/Convert.h"
#include "preprocess/particles/InputSequence.h"
#include "tools/CliValues.h"
#include "tools/Commands.h"
#include "tools/RenderJob.h"
#include "tools/RenderOptions.h"
#include "tools/TemporaryStore.h"

namespace flipscope::tools {
namespace {

struct RenderArgs {
  std::vector<std::string> inputs;
  std::string mem = "4G";
  std::string output;
  std::optional<int> frame;
  std::string frames;
  RenderLookArgs look;
  bool quiet = false;
};

/// The frames of particle `inputs` a render converts: `range`, else the first frame found.
std::vector<FrameInput> framesToConvert(const std::vector<std::string>& inputs, std::optional<FrameRange> range) {
  if (range && range->last > range->first && std::none_of(inputs.begin(), inputs.end(), hasFramePattern))
    throw InputError("--frames " + std::to_string(range->first) + "-" + std::to_string(range->last) + ": the inputs " +
                     "have no frame pattern (name_####.ext), so they are one frame; give --frame");
  const int first = range ? range->first : firstFrameOf(inputs);
  return expandInputs(inputs, range.value_or(FrameRange{first, first}));
}

/// Converts `frames` into `store` with convert's defaults and `memoryBudget`.
void convertForRender(const std::vector<FrameInput>& frames, std::uint64_t memoryBudget, bool quiet,
                      TemporaryStore& store) {
  ConvertOptions options;
  options.memoryBudget = memoryBudget;
  options.progress = quiet ? Progress::Mode::Silent : Progress::Mode::Auto;
  const std::string which =
      frames.size() == 1 ? "frame " + std::to_string(frames.front().frame)
                         : "frames " + std::to_string(frames.front().frame) + "-" + std::to_string(frames.back().frame);
  if (!quiet)
    std::printf(
        "render: converting %s of the particle files into a temporary store (flipscope convert makes one "
        "to keep)\n",
        which.c_str());
  std::fflush(stdout);
  ConvertReport report;
  try {
    report = convert(frames, store.store(), options);
  } catch (const OutputError& e) {  // a full or small $TMPDIR: say where the store went
    throw OutputError(e.path(), e.reason() + " " + std::string(kTemporaryStoreHint));
  }
  store.registerForSignalCleanup();
  testStopPoint("render-store");
  for (const auto& warning : report.warnings) std::fprintf(stderr, "warning: %s\n", warning.c_str());
  if (quiet) return;
  std::uint64_t particles = 0;
  double seconds = 0;
  for (const FrameReport& f : report.frames) particles += f.stats.particles, seconds += f.seconds;
  std::printf("render: converted %s particles in %.2f s; cell size %g (%s)\n",
              particles < 1000 ? std::to_string(particles).c_str() : Progress::humanCount(double(particles)).c_str(),
              seconds, report.header.cellSize, report.cellSizeOrigin.c_str());
}

void runRender(const RenderArgs& a) {
  RenderJob job;
  job.output = a.output;
  std::optional<FrameRange> range;
  if (a.frame) range = FrameRange{*a.frame, *a.frame};
  if (!a.frames.empty()) range = parseFrameRange(a.frames);
  if (range) {
    job.firstFrame = range->first;
    job.lastFrame = range->last;
  }
  ParsedLook look = parseRenderLook(a.look);
  static_cast<RenderRequest&>(job) = look.request;
  job.camera = look.camera;
  job.device = look.device;
  job.saveCamera = a.look.saveCamera;
  job.quiet = a.quiet;
  std::optional<TemporaryStore> temporary;
  if (isStoreDirectory(a.inputs)) {
    job.store = a.inputs.front();
  } else {
    // What runRenderJob checks of the output and the inputs, before a convert that may take long.
    checkOutputPattern(job.output, range.value_or(FrameRange{}));
    const std::uint64_t budget = parseBytes("--mem", a.mem);
    const std::vector<FrameInput> frames = framesToConvert(a.inputs, range);
    installCleanupSignalHandlers();  // the convert's temporaries, then the store, go on a signal
    temporary.emplace();
    convertForRender(frames, budget, a.quiet, *temporary);
    job.store = temporary->store().string();
  }
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
  auto* cmd = app.add_subcommand(
      "render", "Render brick store (or particle file) frames headless to EXR (R G B A Z N thickness foam) or PNG");
  cmd->add_option("inputs", args->inputs,
                  "A brick store directory, or particle files / sequence patterns as convert takes them (the "
                  "frames rendered are converted into a temporary store first)")
      ->required();
  cmd->add_option("-o,--output", args->output, "Output .exr or .png; '####' takes the frame number")->required();
  auto* frame = cmd->add_option("--frame", args->frame, "Frame to render (default: the first)");
  cmd->add_option("--frames", args->frames, "Frame range A-B (a flipbook; needs '#' in the output name)")
      ->excludes(frame);
  cmd->add_option("--mem", args->mem,
                  "Converting particle files (not used with a store): the memory budget, e.g. 512M, 8G")
      ->capture_default_str();
  addRenderLookOptions(*cmd, args->look);
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing");
  cmd->callback([args] { runRender(*args); });
}

}  // namespace flipscope::tools
