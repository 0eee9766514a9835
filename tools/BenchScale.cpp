// `flipscope bench scale`: one giga-scale frame end to end on this machine (Reichl et al. 2014
// §5: 500 M particles preprocessed in 12 s, the first frame in under a second, 50 to 72 ms a
// frame on a GTX Titan). Three stages, each a child process of its own so that each one's
// peak memory is its own:
//   synth    the frame as raw float32 (12 bytes a particle: 6 GB for 500 M);
//   convert  out of core within --mem;
//   render   the first image at --size on --device (the CPU by default), then a few warm
//            frames of an orbit about the up axis (BenchFrameStage.h).
// It prints each stage's time and peak RSS, the store's size and bits per particle, and the
// bricks the first image touched against the bricks of the frame, beside the paper's figures.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>

#include "core/AtomicFile.h"
#include "core/Error.h"
#include "core/Progress.h"
#include "preprocess/store/BrickStore.h"
#include "tools/BenchFrameStage.h"
#include "tools/ChildProcess.h"
#include "tools/CliValues.h"
#include "tools/Commands.h"
#include "tools/JsonOutput.h"

namespace flipscope::tools {
namespace {

namespace fs = std::filesystem;

struct BenchScaleArgs {
  std::string particles = "500M";
  std::string mem = "4G";
  std::string size = "1280x720";
  int orbitFrames = 4;
  std::string device = "cpu";
  std::string workDir;
  bool json = false;
};

std::uint64_t directoryBytes(const fs::path& dir) {
  std::uint64_t bytes = 0;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_regular_file()) bytes += entry.file_size();
  return bytes;
}

/// Runs one stage, saying so; throws naming it and its log when it fails.
ChildRun runStage(const char* name, const std::vector<std::string>& arguments, const fs::path& log, bool quiet) {
  if (!quiet) std::fprintf(stderr, "bench scale: %s ...\n", name);
  return runFlipscopeStage(std::string(name) + " stage", arguments, log);
}

void runBenchScale(const BenchScaleArgs& a) {
  const std::uint64_t particles = parseCount("--particles", a.particles);
  const std::uint64_t mem = parseBytes("--mem", a.mem);
  (void)parseImageSize("--size", a.size);
  (void)parseDeviceChoice("--device", a.device);
  const fs::path work = a.workDir.empty() ? fs::temp_directory_path() / "flipscope-bench-scale" : fs::path(a.workDir);
  fs::create_directories(work);
  const fs::path raw = work / "scale.bin", store = work / "scale.store";

  // synth: reused when the work directory holds the frame of this count (--work-dir).
  const fs::path marker = work / "scale.particles";
  ChildRun synth;
  bool reused = false;
  if (fs::exists(raw) && fs::exists(marker) && readTextFile(marker, "the synth marker") == a.particles + "\n") {
    reused = true;
  } else {
    synth = runStage("synth", {"synth", "-o", raw.string(), "--particles", a.particles}, work / "synth.log", a.json);
    writeTextAtomically(marker, a.particles + "\n");
  }
  const std::uint64_t rawBytes = fs::file_size(raw);
  fs::remove_all(store);
  const ChildRun convert = runStage("convert", {"convert", raw.string(), "-o", store.string(), "--mem", a.mem},
                                    work / "convert.log", a.json);
  const std::uint64_t storeBytes = directoryBytes(store);
  const BrickStore opened = BrickStore::open(store);
  const std::uint64_t stored = opened.frame(opened.frames().front())->stats.particles;
  if (!a.json) std::fprintf(stderr, "bench scale: render ...\n");
  FrameStageRequest frame;
  frame.store = store;
  frame.size = a.size;
  frame.orbitFrames = a.orbitFrames;
  frame.device = a.device;
  const FrameStageResult r = runFrameStage(frame, work, "scale_render");
  const double bitsPerParticle = stored ? 8.0 * double(storeBytes) / double(stored) : 0;

  if (a.json) {
    printJson({{"particles", stored},
               {"particles_asked", particles},
               {"raw_bytes", rawBytes},
               {"mem_bytes", mem},
               {"synth_s", reused ? nlohmann::json(nullptr) : nlohmann::json(synth.seconds)},
               {"synth_peak_rss_bytes", reused ? nlohmann::json(nullptr) : nlohmann::json(synth.peakBytes)},
               {"convert_s", convert.seconds},
               {"convert_peak_rss_bytes", convert.peakBytes},
               {"store_bytes", storeBytes},
               {"store_bits_per_particle", bitsPerParticle},
               {"render_device", r.device},
               {"first_image_s", r.firstImageSeconds},
               {"render_peak_rss_bytes", r.peakBytes},
               {"bricks_touched", r.bricksTouched},
               {"frame_bricks", r.frameBricks},
               {"warm_frame_ms", r.warmFrameMs}});
    return;
  }
  const auto gib = [](double bytes) { return bytes / double(1ull << 30); };
  std::printf("bench scale: %s particles in one frame (%s bytes raw float32), convert --mem %s, render %s on %s\n\n",
              Progress::humanCount(double(stored)).c_str(), Progress::humanCount(double(rawBytes)).c_str(),
              a.mem.c_str(), a.size.c_str(), r.device.c_str());
  std::printf("%-40s %12s %14s   %s\n", "stage", "seconds", "peak RSS GiB", "paper (GTX Titan, 8 cores, SSD)");
  if (reused)
    std::printf("%-40s %12s %14s\n", "synth (reused from --work-dir)", "-", "-");
  else
    std::printf("%-40s %12.1f %14.2f\n", "synth (raw float32 written)", synth.seconds, gib(double(synth.peakBytes)));
  std::printf("%-40s %12.1f %14.2f   %s\n", ("convert --mem " + a.mem).c_str(), convert.seconds,
              gib(double(convert.peakBytes)), "12 s for 500 M");
  std::printf("%-40s %12.2f %14.2f   %s\n", "render: first image (open to converged)", r.firstImageSeconds,
              gib(double(r.peakBytes)), "under 1 s");
  std::printf("%-40s %12.1f %14s   %s\n",
              ("render: warm orbit frame, ms (mean of " + std::to_string(r.warmFrameMs.size()) + ")").c_str(),
              r.warmMeanMs(), "", "50-72 ms");
  std::printf("\nstore: %s bytes, %.2f bits a particle; the first image touched %llu of the frame's %llu bricks\n",
              Progress::humanCount(double(storeBytes)).c_str(), bitsPerParticle, (unsigned long long)r.bricksTouched,
              (unsigned long long)r.frameBricks);
  std::printf("peak RSS against --mem %s: convert %.2f GiB; the particles alone would take %.1f GiB\n", a.mem.c_str(),
              gib(double(convert.peakBytes)), gib(double(rawBytes)));
  std::printf("files in %s (the first image: scale_render.png; each stage's log)\n", work.c_str());
}

}  // namespace

void addBenchScaleCommand(CLI::App& bench) {
  auto args = std::make_shared<BenchScaleArgs>();
  auto* cmd = bench.add_subcommand("scale", "One giga-scale frame end to end: synth, convert out of core, render");
  cmd->add_option("--particles", args->particles, "Particles in the frame (500M: 6 GB raw)")->capture_default_str();
  cmd->add_option("--mem", args->mem, "--mem of the convert")->capture_default_str();
  cmd->add_option("--size", args->size, "Image size WxH")->capture_default_str();
  cmd->add_option("--orbit-frames", args->orbitFrames, "Warm frames of the orbit")->capture_default_str();
  cmd->add_option("--device", args->device, "Render device: cpu, cpu-reference, gpu or auto")->capture_default_str();
  cmd->add_option("--work-dir", args->workDir,
                  "Where the raw frame, the store and the logs go (default: a temp directory); a frame of the same "
                  "--particles there is reused");
  cmd->add_flag("--json", args->json, "Machine-readable output");
  cmd->callback([args] { runBenchScale(*args); });
}

}  // namespace flipscope::tools
