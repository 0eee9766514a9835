// flipscope demo: the main job on generated data, from nothing to a preview image:
// synth frames -> convert into a brick store -> info -> render the last frame to PNG.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <tuple>

#include "core/Error.h"
#include "preprocess/store/StoreInspection.h"
#include "preprocess/SynthFluid.h"
#include "tools/CliValues.h"
#include "tools/Commands.h"
#include "tools/RenderJob.h"

namespace flipscope::tools {
namespace {

namespace fs = std::filesystem;

struct DemoArgs {
  std::string output = "flipscope-demo";
  std::string particles = "2M";
  int frames = 3;
  std::string size = "960x540";
  std::string device = "auto";
};

void runDemo(const DemoArgs& a) {
  const fs::path out = a.output;
  const fs::path storeDir = out / "store";
  fs::create_directories(out);

  SynthOptions synth;
  synth.particles = parseCount("--particles", a.particles);
  const SynthFluid first(synth);
  std::printf("demo: %d synth frames of %s particles (FLIP-like wave, sheets, spray) -> %s\n", a.frames,
              Progress::humanCount(double(first.count())).c_str(), storeDir.c_str());
  Progress progress("demo convert", first.count() * std::uint64_t(a.frames));
  BrickStore store = convertSynthFrames(synth, a.frames, storeDir, &progress);
  const StoreHeader& header = store.header();
  progress.finish();
  for (int f : store.frames()) {
    const FrameSummary s = summarizeFrame(*store.frame(f), header);
    std::printf("  frame %d: %llu particles in %u bricks, %.2f bits/particle, store %.1fx smaller than float32\n",
                s.frame, (unsigned long long)s.particles, s.bricks, s.bitsPerParticle, s.ratioToRaw);
  }
  std::printf("demo: wrote brick store %s (inspect with: flipscope info %s)\n", storeDir.c_str(), storeDir.c_str());

  RenderJob job;
  job.store = storeDir.string();
  job.output = (out / "preview.png").string();
  job.firstFrame = job.lastFrame = a.frames - 1;
  std::tie(job.settings.width, job.settings.height) = parseImageSize("--size", a.size);
  validate(job.settings);
  job.device = parseDeviceChoice("--device", a.device);
  runRenderJob(job);
  std::printf("demo: wrote preview image %s (render more with: flipscope render %s -o out_####.exr --frames 0-%d)\n",
              job.output.c_str(), storeDir.c_str(), a.frames - 1);
}

}  // namespace

void addDemoCommand(CLI::App& app) {
  auto args = std::make_shared<DemoArgs>();
  auto* cmd =
      app.add_subcommand("demo", "The main job on generated data: synth -> convert -> info -> render a preview");
  cmd->add_option("-o,--output", args->output, "Output directory")->capture_default_str();
  cmd->add_option("--particles", args->particles, "Synth particles per frame")->capture_default_str();
  cmd->add_option("--frames", args->frames, "Frames to generate")->check(CLI::Range(1, 1000))->capture_default_str();
  cmd->add_option("--size", args->size, "Preview image size WxH")->capture_default_str();
  cmd->add_option("--device", args->device, "auto, gpu, cpu or cpu-reference")
      ->check(CLI::IsMember({"auto", "gpu", "cpu", "cpu-reference"}))
      ->capture_default_str();
  cmd->callback([args] { runDemo(*args); });
}

}  // namespace flipscope::tools
