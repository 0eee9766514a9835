// `flipscope bench view`: the viewer's rates (Reichl et al. 2014 §5, "System Behavior": about
// 700 ms for a cold frame, which is also the rate of scrubbing through a sequence). Headless:
// the viewer's own progressive loop (FramePipeline::begin, then advance() slices of
// --budget-ms until the frame finishes), without the window.
//  - cold: step through a synth sequence whose bricks were never converted (every frame's
//    bricks are converted on request), ms per new frame shown converged;
//  - warm: the same frames again, their bricks in the CPU cache;
//  - orbit: one frame, the camera turning 3 degrees a frame, converged frames per second.
// On each device asked for: the CPU pipeline, and OpenGL through EGL (llvmpipe here).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <CLI/CLI.hpp>
#include <glm/gtc/constants.hpp>
#include <nlohmann/json.hpp>

#include "core/Elapsed.h"
#include "core/Error.h"
#include "core/ProcessMemory.h"
#include "pipeline/FramePipeline.h"
#include "pipeline/RenderRequest.h"
#include "preprocess/SynthFluid.h"
#include "tools/CliValues.h"
#include "tools/Commands.h"
#include "tools/JsonOutput.h"

namespace flipscope::tools {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct BenchViewArgs {
  std::string particles = "1M";
  int frames = 8;
  std::string size = "640x360";
  std::string orbitSize = "1280x720";
  int orbitFrames = 12;
  double budgetMs = 25;
  std::string devices = "cpu,gpu";
  std::string workDir;
  bool json = false;
};

struct ViewRates {
  std::string device;
  double coldFrameMs = 0;
  double warmFrameMs = 0;
  double orbitFps = 0;
  double slicesPerColdFrame = 0;
};

/// Shows `frame` through `camera` as the viewer does; returns the advance() calls it took.
int showConverged(FramePipeline& pipeline, int frame, const Camera& camera, int direction, double budgetMs) {
  pipeline.begin(frame, camera, direction);
  int slices = 0;
  while (!pipeline.finished()) {
    pipeline.advance(budgetMs);
    ++slices;
  }
  return slices;
}

std::unique_ptr<FramePipeline> makePipeline(const std::shared_ptr<StoreBrickSource>& source, bool gpu,
                                            std::uint32_t width, std::uint32_t height, int readAhead) {
  RenderSettings settings;
  settings.width = width;
  settings.height = height;
  settings.radius = defaultSphereRadius(source->header(), settings.jitter);
  settings.readAheadFrames = readAhead;
  if (gpu) return std::make_unique<FramePipeline>(source, DeviceChoice::Gpu, settings, SurfaceSettings{});
  return std::make_unique<FramePipeline>(source, DeviceChoice::Cpu, settings, SurfaceSettings{});
}

ViewRates measure(const fs::path& storeDir, bool gpu, const BenchViewArgs& a) {
  ViewRates r;
  auto source = std::make_shared<StoreBrickSource>(BrickStore::open(storeDir));
  const std::vector<int> frames = source->frames();
  const auto [width, height] = parseImageSize("--size", a.size);
  // Scrubbing: one pipeline (as the viewer keeps), every frame new to it; read-ahead off, so
  // each cold frame converts its own bricks on request.
  auto pipeline = makePipeline(source, gpu, width, height, 0);
  r.device = pipeline->deviceName();
  const Camera camera = defaultRenderCamera(*source, frames.front(), frames.back(), width, height, {0, 1, 0});
  int slices = 0;
  auto start = Clock::now();
  for (int f : frames) slices += showConverged(*pipeline, f, camera, 1, a.budgetMs);
  r.coldFrameMs = msSince(start) / double(frames.size());
  r.slicesPerColdFrame = double(slices) / double(frames.size());
  start = Clock::now();
  for (int f : frames) showConverged(*pipeline, f, camera, 1, a.budgetMs);
  r.warmFrameMs = msSince(start) / double(frames.size());
  // Orbit: a converged frame per step of 3 degrees about the up axis, at --orbit-size.
  const auto [ow, oh] = parseImageSize("--orbit-size", a.orbitSize);
  auto orbit = makePipeline(source, gpu, ow, oh, 0);
  Camera view = defaultRenderCamera(*source, frames.front(), frames.front(), ow, oh, {0, 1, 0});
  showConverged(*orbit, frames.front(), view, 0, a.budgetMs);  // the bricks of the view, once
  start = Clock::now();
  for (int i = 0; i < a.orbitFrames; ++i) {
    const double angle = glm::radians(3.0);
    const glm::dvec3 d = view.eye - view.target;
    view.eye = view.target + glm::dvec3(d.x * std::cos(angle) + d.z * std::sin(angle), d.y,
                                        -d.x * std::sin(angle) + d.z * std::cos(angle));  // about +y
    showConverged(*orbit, frames.front(), view, 0, a.budgetMs);
  }
  r.orbitFps = double(a.orbitFrames) / (msSince(start) / 1000.0);
  return r;
}

void runBenchView(const BenchViewArgs& a) {
  keepHeapForReuse();  // core/ProcessMemory.h
  if (a.frames < 2) throw InputError("--frames: at least 2");
  const fs::path work = a.workDir.empty() ? fs::temp_directory_path() / "flipscope-bench-view" : fs::path(a.workDir);
  fs::create_directories(work);
  const fs::path storeDir = work / "store";
  SynthOptions synth;
  synth.particles = parseCount("--particles", a.particles);
  if (!a.json)
    std::fprintf(stderr, "bench view: %d synth frames of %s particles -> %s ...\n", a.frames,
                 Progress::humanCount(double(synth.particles)).c_str(), storeDir.c_str());
  convertSynthFrames(synth, a.frames, storeDir);
  std::vector<ViewRates> results;
  for (const std::string& device : {std::string("cpu"), std::string("gpu")}) {
    if (a.devices.find(device) == std::string::npos) continue;
    try {
      results.push_back(measure(storeDir, device == "gpu", a));
    } catch (const gl::Unavailable& e) {
      std::fprintf(stderr, "bench view: no OpenGL device: %s\n", e.what());
    }
  }
  if (a.json) {
    nlohmann::json j;
    j["particles"] = synth.particles;
    j["frames"] = a.frames;
    j["size"] = a.size;
    j["orbit_size"] = a.orbitSize;
    j["budget_ms"] = a.budgetMs;
    for (const ViewRates& r : results)
      j["devices"].push_back({{"device", r.device},
                              {"cold_frame_ms", r.coldFrameMs},
                              {"warm_frame_ms", r.warmFrameMs},
                              {"orbit_fps", r.orbitFps},
                              {"slices_per_cold_frame", r.slicesPerColdFrame}});
    if (!results.empty()) {
      j["cold_frame_ms"] = results.front().coldFrameMs;
      j["warm_frame_ms"] = results.front().warmFrameMs;
      j["orbit_fps"] = results.front().orbitFps;
    }
    j["paper"] = {{"cold_frame_ms", 700}, {"device", "GTX Titan, 1280x720, 500 M particles"}};
    printJson(j);
    return;
  }
  std::printf("bench view: %d frames of %s synth particles; scrub at %s, orbit at %s; %.0f ms slices\n\n", a.frames,
              Progress::humanCount(double(synth.particles)).c_str(), a.size.c_str(), a.orbitSize.c_str(), a.budgetMs);
  std::printf("%-60s %14s %14s %10s %12s\n", "device", "cold ms/frame", "warm ms/frame", "orbit fps", "slices/cold");
  for (const ViewRates& r : results)
    std::printf("%-60.60s %14.0f %14.0f %10.2f %12.1f\n", r.device.c_str(), r.coldFrameMs, r.warmFrameMs, r.orbitFps,
                r.slicesPerColdFrame);
  std::printf("%-60s %14s %14s %10s %12s\n", "paper (GTX Titan, 1280x720, 500 M particles)", "~700", "-", "14-20", "-");
}

}  // namespace

void addBenchViewCommand(CLI::App& bench) {
  auto args = std::make_shared<BenchViewArgs>();
  auto* cmd = bench.add_subcommand("view", "The viewer's cold and warm scrub rates and orbit fps (headless)");
  cmd->add_option("--particles", args->particles, "Synth particles per frame")->capture_default_str();
  cmd->add_option("--frames", args->frames, "Frames of the sequence")->capture_default_str();
  cmd->add_option("--size", args->size, "Scrub image size WxH")->capture_default_str();
  cmd->add_option("--orbit-size", args->orbitSize, "Orbit image size WxH")->capture_default_str();
  cmd->add_option("--orbit-frames", args->orbitFrames, "Orbit steps timed")->capture_default_str();
  cmd->add_option("--budget-ms", args->budgetMs, "Ray-casting per slice, as view --budget-ms")->capture_default_str();
  cmd->add_option("--devices", args->devices, "cpu, gpu or cpu,gpu")->capture_default_str();
  cmd->add_option("--work-dir", args->workDir, "Where the store goes (default: a temp directory)");
  cmd->add_flag("--json", args->json, "Print JSON (cold_frame_ms, warm_frame_ms, orbit_fps of the first device)");
  cmd->callback([args] { runBenchView(*args); });
}

}  // namespace flipscope::tools
