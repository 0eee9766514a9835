// `flipscope bench render`: time to the first converged image (store opened, device created,
// every visible brick converted and uploaded) and the per-frame time of a warm orbit, at
// 640x360 and 1280x720 (or --sizes), beside the classical pipeline on the same particles in the
// same run: `vdb_tool -read p.ply -points2ls ... -render ...` (OpenVDB's level-set meshing-free
// path, itself faster than meshing). Reichl et al. 2014 §5 report 8.5 ms to 50 ms per frame on a
// GTX 780 at 1280x720 (Table 3).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "core/Elapsed.h"
#include "core/Error.h"
#include "core/NumberText.h"
#include "pipeline/FramePipeline.h"
#include "preprocess/Convert.h"
#include "preprocess/SynthFluid.h"
#include "preprocess/particles/ParticleWriter.h"
#include "raycast/GpuRaycaster.h"
#include "tools/BenchFoam.h"
#include "tools/BenchFrameStage.h"
#include "tools/BenchStatistics.h"
#include "tools/ChildProcess.h"
#include "tools/CliValues.h"
#include "tools/Commands.h"
#include "tools/EmbreePeer.h"
#include "tools/JsonOutput.h"

namespace flipscope::tools {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct BenchRenderArgs {
  std::string particles = "4M";
  std::string workDir;
  std::string sizes = "640x360,1280x720";
  int orbitFrames = 12;
  std::string device = "auto";
  std::string gpuMem = "2G";
  bool skipVdbTool = false;
  std::string peer;  ///< "embree": the same particles through Embree in the same run
  int peerRuns = 1;  ///< the peer comparison this many times, one after another
  bool json = false;
};

struct SizeResult {
  std::uint32_t width, height;
  double firstImageSeconds;
  RenderStats cold;
  double frameMs;  // mean over the warm orbit
  double traceMs;  // mean device time of a warm frame
  int warmPasses;  // most passes of a warm frame
};

std::vector<std::pair<std::uint32_t, std::uint32_t>> parseSizes(const std::string& text) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> sizes;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) sizes.push_back(parseImageSize("--sizes", item));
  return sizes;
}

/// Seconds `vdb_tool` takes from the PLY to a rendered image; nullopt (with a message) when it
/// is not installed or fails.
std::optional<double> timeVdbTool(const fs::path& ply, const fs::path& image, double voxel, double radiusVoxels,
                                  const Camera& camera, std::uint32_t width, std::uint32_t height) {
  if (std::system("command -v vdb_tool >/dev/null 2>&1") != 0) return std::nullopt;
  char command[2048];
  std::snprintf(command, sizeof command,
                "vdb_tool -read '%s' -points2ls voxel=%.9g radius=%.4g width=3 -render files='%s' image=%ux%u "
                "'translate=(%.6g,%.6g,%.6g)' 'target=(%.6g,%.6g,%.6g)' 'up=(%.3g,%.3g,%.3g)' >/dev/null 2>&1",
                ply.c_str(), voxel, radiusVoxels, image.c_str(), width, height, camera.eye.x, camera.eye.y,
                camera.eye.z, camera.target.x, camera.target.y, camera.target.z, camera.up.x, camera.up.y, camera.up.z);
  const auto start = Clock::now();
  const int status = std::system(command);
  const double seconds = secondsSince(start);
  if (status != 0 || !fs::exists(image)) {
    std::fprintf(stderr, "bench render: vdb_tool failed (exit status %d): %s\n", status, command);
    return std::nullopt;
  }
  return seconds;
}

/// flipscope's convert and CPU ray-caster against Embree's sphere points, on the same particles
/// with the same camera and sphere radius, each in a child process (its own peak RSS).
struct PeerComparison {
  std::string size;
  double convertSeconds = 0;
  std::uint64_t convertPeakBytes = 0;
  FrameStageResult flipscope;
  /// The same again with the particle spacing given (`convert --particle-spacing`, the value the
  /// first convert measured), as Embree is given its sphere radius: no read of the frame for it.
  double givenConvertSeconds = 0;
  std::uint64_t givenConvertPeakBytes = 0;
  FrameStageResult given;
  std::optional<EmbreeStageResult> embree;  ///< nullopt: not built in
  float radiusWorld = 0;

  double flipscopeFirst() const { return convertSeconds + flipscope.firstImageSeconds; }
  double givenFirst() const { return givenConvertSeconds + given.firstImageSeconds; }
  /// The targets (issue 13), with Embree: flipscope's warm frame at most kWarmTarget times
  /// Embree's; its convert + first image at least kSoonerTarget times sooner than Embree's build
  /// + first frame (also with the particle spacing given).
  static constexpr double kWarmTarget = 1.0, kSoonerTarget = 10.0;
  double warmRatio() const { return flipscope.warmMeanMs() / embree->warmMeanMs(); }
  double soonerRatio() const { return embree->firstFrameSeconds / flipscopeFirst(); }
  double givenSoonerRatio() const { return embree->firstFrameSeconds / givenFirst(); }
  static bool warmMet(double ratio) { return ratio <= kWarmTarget; }
  static bool soonerMet(double ratio) { return ratio >= kSoonerTarget; }
  nlohmann::json json() const {
    nlohmann::json j{{"size", size},
                     {"radius_world", radiusWorld},
                     {"flipscope_convert_s", convertSeconds},
                     {"flipscope_first_image_s", flipscope.firstImageSeconds},
                     {"flipscope_convert_and_first_image_s", flipscopeFirst()},
                     {"flipscope_warm_frame_ms", flipscope.warmMeanMs()},
                     {"flipscope_warm_trace_ms", flipscope.warmTraceMeanMs()},
                     {"flipscope_convert_peak_rss_bytes", convertPeakBytes},
                     {"flipscope_render_peak_rss_bytes", flipscope.peakBytes},
                     {"flipscope_spacing_given_convert_s", givenConvertSeconds},
                     {"flipscope_spacing_given_convert_peak_rss_bytes", givenConvertPeakBytes},
                     {"flipscope_spacing_given_first_image_s", given.firstImageSeconds},
                     {"flipscope_spacing_given_convert_and_first_image_s", givenFirst()},
                     {"embree", nullptr}};
    if (embree)
      j["embree"] = {{"version", embree->version},
                     {"read_s", embree->readSeconds},
                     {"build_s", embree->buildSeconds},
                     {"build_and_first_frame_s", embree->firstFrameSeconds},
                     {"warm_frame_ms", embree->warmMeanMs()},
                     {"embree_bytes", embree->embreeBytes},
                     {"peak_rss_bytes", embree->peakBytes},
                     {"hits", embree->hits}};
    return j;
  }
  void print() const {
    const auto gib = [](std::uint64_t bytes) { return double(bytes) / double(1ull << 30); };
    std::printf("\npeer at %s, the same particles, camera and sphere radius (%.4g world units), CPU:\n", size.c_str(),
                double(radiusWorld));
    std::printf("  %-34s %16s %16s %14s %14s\n", "", "prepare s", "+ first image s", "warm frame ms", "peak RSS GiB");
    if (embree)
      std::printf("  %-34s %16.2f %16.2f %14.1f %14.2f\n", (embree->version + " sphere points").c_str(),
                  embree->buildSeconds, embree->firstFrameSeconds, embree->warmMeanMs(), gib(embree->peakBytes));
    else
      std::printf("  %-34s %16s\n", "Embree", "not built in (install libembree-dev and build again)");
    std::printf("  %-34s %16.2f %16.2f %14.1f %14.2f\n", ("flipscope (" + flipscope.device + ")").c_str(),
                convertSeconds, flipscopeFirst(), flipscope.warmMeanMs(),
                gib(std::max(convertPeakBytes, flipscope.peakBytes)));
    std::printf("  %-34s %16.2f %16.2f %14s %14.2f\n", "  the same, --particle-spacing given", givenConvertSeconds,
                givenFirst(), "", gib(std::max(givenConvertPeakBytes, given.peakBytes)));
    std::printf(
        "  (prepare: Embree's BVH build, flipscope's convert; flipscope's warm frames are the ray-caster's "
        "spheres, %.1f ms of it tracing)\n",
        flipscope.warmTraceMeanMs());
    if (!embree) return;
    std::printf("  target: a warm frame no slower than Embree's: %s (%.2fx)\n",
                warmMet(warmRatio()) ? "met" : "NOT met", warmRatio());
    std::printf("  target: convert + first image %.0fx sooner than Embree's build + first frame: %s (%.1fx sooner)\n",
                kSoonerTarget, soonerMet(soonerRatio()) ? "met" : "NOT met", soonerRatio());
    std::printf("  the same target with the particle spacing given, as Embree is given its radius: %s (%.1fx sooner)\n",
                soonerMet(givenSoonerRatio()) ? "met" : "NOT met", givenSoonerRatio());
    // flipscope's convert reads the file; Embree's build starts from particles in memory.
    const double embreeFromFile = embree->readSeconds + embree->firstFrameSeconds;
    std::printf(
        "  from the particle file, Embree's read of it counted too (%.2f s + %.2f s): %.1fx sooner, %.1fx with "
        "the spacing given\n",
        embree->readSeconds, embree->firstFrameSeconds, embreeFromFile / flipscopeFirst(),
        embreeFromFile / givenFirst());
  }
};

/// The Embree peer beside flipscope on `device`: the bench's --device when it names a CPU
/// ray-caster (cpu or cpu-reference), else cpu, since Embree runs on the CPU.
PeerComparison compareWithEmbree(const fs::path& work, const fs::path& particles, double cellSize, const Camera& camera,
                                 const std::string& size, int orbitFrames, const std::string& device) {
  PeerComparison c;
  c.size = size;
  const fs::path store = work / "peer.store", cameraFile = work / "peer_camera.json";
  saveCamera(cameraFile, camera);
  fs::remove_all(store);
  const std::string cell = exactNumberText(cellSize);
  const ChildRun convert =
      runFlipscopeStage("peer's convert", {"convert", particles.string(), "-o", store.string(), "--cell-size", cell},
                        work / "peer_convert.log");
  c.convertSeconds = convert.seconds;
  c.convertPeakBytes = convert.peakBytes;
  FrameStageRequest frame;
  frame.store = store;
  frame.size = size;
  frame.orbitFrames = orbitFrames;
  frame.device = device == "cpu-reference" ? device : "cpu";
  frame.cameraFile = cameraFile;
  frame.spheres = true;
  c.flipscope = runFrameStage(frame, work, "peer_flipscope");
  const StoreHeader header = BrickStore::open(store).header();
  c.radiusWorld = float(defaultSphereRadius(header, RenderSettings{}.jitter) * header.cellSize);
  const fs::path givenStore = work / "peer_spacing_given.store";
  fs::remove_all(givenStore);
  const std::string spacing = exactNumberText(header.particleSpacing);
  const ChildRun given = runFlipscopeStage(
      "peer's convert, the spacing given",
      {"convert", particles.string(), "-o", givenStore.string(), "--cell-size", cell, "--particle-spacing", spacing},
      work / "peer_spacing_given_convert.log");
  c.givenConvertSeconds = given.seconds;
  c.givenConvertPeakBytes = given.peakBytes;
  frame.store = givenStore;
  frame.orbitFrames = 0;  // the first image only: the store is the same
  c.given = runFrameStage(frame, work, "peer_spacing_given");
  fs::remove_all(givenStore);
  if (embreeAvailable()) c.embree = runEmbreeStage({particles, c.radiusWorld, cameraFile, size, orbitFrames}, work);
  return c;
}

/// Over the runs of the peer comparison (with Embree): each target's ratio per run, its median
/// and range, and in how many runs it was met.
struct PeerSummary {
  RunRatios warm;         ///< PeerComparison::warmRatio
  RunRatios sooner;       ///< PeerComparison::soonerRatio
  RunRatios givenSooner;  ///< PeerComparison::givenSoonerRatio

  /// nullopt when Embree is not built in.
  static std::optional<PeerSummary> of(const std::vector<PeerComparison>& peers) {
    if (peers.empty() || !peers.front().embree) return std::nullopt;
    PeerSummary s;
    for (const PeerComparison& p : peers) {
      s.warm.add(p.warmRatio(), PeerComparison::warmMet(p.warmRatio()));
      s.sooner.add(p.soonerRatio(), PeerComparison::soonerMet(p.soonerRatio()));
      s.givenSooner.add(p.givenSoonerRatio(), PeerComparison::soonerMet(p.givenSoonerRatio()));
    }
    return s;
  }
  nlohmann::json json() const {
    return {{"runs", warm.perRun.size()},
            {"warm_frame_x_embree", warm.json()},
            {"first_image_x_sooner", sooner.json()},
            {"spacing_given_first_image_x_sooner", givenSooner.json()}};
  }
  void print() const {
    const std::size_t n = warm.perRun.size();
    std::printf("\npeer over %zu runs: median, range, runs that met the target\n", n);
    const auto row = [n](const std::string& what, const RunRatios& r, int decimals) {
      std::printf("  %-62s %6.*fx %6.*fx to %.*fx %3d of %zu\n", what.c_str(), decimals, r.median(), decimals, r.min(),
                  decimals, r.max(), r.met, n);
    };
    char target[64];
    std::snprintf(target, sizeof target, "(target: at most %.0f)", PeerComparison::kWarmTarget);
    row(std::string("warm frame, x Embree's ") + target, warm, 2);
    std::snprintf(target, sizeof target, "(target: %.0f)", PeerComparison::kSoonerTarget);
    row(std::string("convert + first image, x sooner than Embree's ") + target, sooner, 1);
    row("the same, the particle spacing given", givenSooner, 1);
  }
};

void runBenchRender(const BenchRenderArgs& a) {
  const auto sizes = parseSizes(a.sizes);
  const fs::path work = a.workDir.empty() ? fs::temp_directory_path() / "flipscope-bench-render" : fs::path(a.workDir);
  fs::create_directories(work);
  const fs::path ply = work / "synth.ply";
  const fs::path storeDir = work / "store";

  SynthOptions synth;
  synth.particles = parseCount("--particles", a.particles);
  synth.velocity = true;
  SynthFluid fluid(synth);
  if (!a.json)
    std::fprintf(stderr, "bench render: %s synth particles -> %s and %s ...\n",
                 Progress::humanCount(double(fluid.count())).c_str(), ply.c_str(), storeDir.c_str());
  {
    auto writer = createParticleWriter(ply, WriteOptions{.velocity = true});
    ParticleChunk chunk;
    while (fluid.read(chunk, 1 << 20)) writer->write(chunk);
    writer->commit();
    fluid.rewind();
  }
  fs::remove_all(storeDir);
  ConvertOptions options;
  options.cellSize = fluid.cellSize();
  options.domain = fluid.domain();
  options.progress = Progress::Mode::Silent;
  {
    BrickStore store =
        BrickStore::createOrAppend(storeDir, makeStoreHeader(*options.domain, options, AttributeKind::Speed));
    convertFrame(fluid, store, 0, options);
  }

  const DeviceChoice choice = parseDeviceChoice("--device", a.device);
  std::string deviceName;
  std::vector<SizeResult> results;
  Camera lastCamera;
  for (auto [width, height] : sizes) {
    RenderSettings settings;
    settings.width = width;
    settings.height = height;
    settings.gpuBudgetBytes = parseBytes("--gpu-mem", a.gpuMem);
    // Cold: everything a first image needs, from opening the store.
    const auto start = Clock::now();
    BrickStore store = BrickStore::open(storeDir);
    settings.radius = defaultSphereRadius(store.header(), settings.jitter);
    FramePipeline pipeline(std::move(store), choice, settings, SurfaceSettings{});
    pipeline.setOutputLayers(OutputLayers::Colour);  // a PNG's, as `render` reads it back
    deviceName = pipeline.deviceName();
    const Camera camera = frameOnBox(pipeline.renderer().occupiedBounds(0), double(width) / height, {0, 1, 0});
    const FrameOutput& cold = pipeline.render(0, camera);
    const double firstImage = secondsSince(start);
    const RenderStats coldStats = cold.stats;  // the warm frames reuse the output
    writeImage(work / ("flipscope_" + std::to_string(width) + "x" + std::to_string(height) + ".png"), cold.image);
    // Warm: an orbit of small steps around the target (bricks resident, one pass each).
    double frameMs = 0, traceMs = 0;
    int warmPasses = 0;
    for (int i = 0; i < a.orbitFrames; ++i) {
      const Camera orbit = orbitAbout(camera, {0, 1, 0}, -2.0 * (i + 1));
      const auto t = Clock::now();
      const FrameOutput& warm = pipeline.render(0, orbit);
      frameMs += secondsSince(t) * 1e3 / a.orbitFrames;
      traceMs += warm.stats.traceMs / a.orbitFrames;
      warmPasses = std::max(warmPasses, warm.stats.passes);
    }
    results.push_back({width, height, firstImage, coldStats, frameMs, traceMs, warmPasses});
    lastCamera = camera;
  }

  // Foam and absorption at the last size, each added on its own (the same camera).
  RenderSettings foamSettings;
  foamSettings.width = sizes.back().first;
  foamSettings.height = sizes.back().second;
  foamSettings.gpuBudgetBytes = parseBytes("--gpu-mem", a.gpuMem);
  foamSettings.radius = defaultSphereRadius(BrickStore::open(storeDir).header(), foamSettings.jitter);
  if (!a.json)
    std::fprintf(stderr, "bench render: foam and absorption at %ux%u ...\n", foamSettings.width, foamSettings.height);
  const FoamTraceTiming foam = timeFoamAndAbsorption(storeDir, choice, foamSettings, lastCamera, a.orbitFrames);

  std::optional<double> vdbTool;
  const auto [vw, vh] = sizes.back();
  if (!a.skipVdbTool) {
    if (!a.json) std::fprintf(stderr, "bench render: vdb_tool -points2ls -render at %ux%u ...\n", vw, vh);
    vdbTool = timeVdbTool(ply, work / "vdb_tool.png", fluid.cellSize(), 2.0, lastCamera, vw, vh);
  }

  std::vector<PeerComparison> peers;
  for (int run = 1; !a.peer.empty() && run <= a.peerRuns; ++run) {
    if (!a.json)
      std::fprintf(stderr, "bench render: the Embree peer at %ux%u, run %d of %d ...\n", vw, vh, run, a.peerRuns);
    peers.push_back(compareWithEmbree(work, ply, fluid.cellSize(), lastCamera,
                                      std::to_string(vw) + "x" + std::to_string(vh), a.orbitFrames, a.device));
  }
  const std::optional<PeerSummary> peerSummary = PeerSummary::of(peers);

  const SizeResult& main = results.back();
  if (a.json) {
    nlohmann::json j{{"device", deviceName},
                     {"particles", fluid.count()},
                     {"width", main.width},
                     {"height", main.height},
                     {"first_image_s", main.firstImageSeconds},
                     {"frame_ms", main.frameMs},
                     {"vdb_tool_s", vdbTool ? nlohmann::json(*vdbTool) : nlohmann::json(nullptr)},
                     {"foam",
                      {{"trace_spheres_ms", foam.spheresMs},
                       {"trace_absorption_ms", foam.absorptionMs},
                       {"trace_remove_ms", foam.removeMs},
                       {"trace_volume_ms", foam.volumeMs},
                       {"absorption_ms", foam.absorptionCost()},
                       {"volumetric_foam_ms", foam.volumeCost()},
                       {"classification_ms", foam.classifyMs}}}};
    for (const SizeResult& r : results)
      j["sizes"].push_back({{"width", r.width},
                            {"height", r.height},
                            {"first_image_s", r.firstImageSeconds},
                            {"cold_passes", r.cold.passes},
                            {"cold_bricks", r.cold.bricksUploaded},
                            {"frame_ms", r.frameMs},
                            {"trace_ms", r.traceMs}});
    if (!peers.empty()) {
      j["peer"] = peers.back().json();  // the run whose images the work directory holds
      for (const PeerComparison& p : peers) j["peer_runs"].push_back(p.json());
      j["peer_summary"] = peerSummary ? peerSummary->json() : nlohmann::json(nullptr);
    }
    printJson(j);
    return;
  }
  std::printf("bench render: %s synth particles (1 frame, %zu non-empty bricks), device %s\n\n",
              Progress::humanCount(double(fluid.count())).c_str(), main.cold.frameBricks, deviceName.c_str());
  std::printf("%-11s %14s %8s %10s %12s %14s %14s\n", "size", "first image s", "passes", "bricks", "convert ms",
              "warm frame ms", "warm trace ms");
  for (const SizeResult& r : results)
    std::printf("%5ux%-5u %14.3f %8d %10llu %12.0f %14.1f %14.1f\n", r.width, r.height, r.firstImageSeconds,
                r.cold.passes, (unsigned long long)r.cold.bricksUploaded, r.cold.streamMs, r.frameMs, r.traceMs);
  std::printf("%-11s %14s %8s %10s %12s %14s %14s\n", "paper", "-", "-", "-", "-", "8.5-50 (GPU)", "");
  std::printf("\nfoam and absorption at %ux%u, warm trace ms (median of %d frames, the variants in turn), %s:\n",
              main.width, main.height, a.orbitFrames, foam.device.c_str());
  std::printf("  %-44s %10s %10s %18s\n", "", "trace ms", "added ms", "paper (GTX Titan)");
  std::printf("  %-44s %10.1f %10s %18s\n", "spheres (--foam keep, no thickness)", foam.spheresMs, "-",
              "20-27 (Sphere)");
  std::printf("  %-44s %10.1f %+10.1f %18s\n", "+ absorption (density trace, §3.6)", foam.absorptionMs,
              foam.absorptionCost(), "12-14 (Trans)");
  std::printf("  %-44s %10.1f %+10.1f %18s\n", "+ foam cells skipped (--foam remove)", foam.removeMs,
              foam.removeMs - foam.absorptionMs, "-");
  std::printf("  %-44s %10.1f %+10.1f %18s\n", "+ volumetric foam (--foam volume, default)", foam.volumeMs,
              foam.volumeCost(), "12-34 (Foam)");
  std::printf("  foam classification of the cold frame's bricks: %.1f ms\n", foam.classifyMs);
  if (vdbTool)
    std::printf("\nfirst image at %ux%u: vdb_tool -points2ls -render %.2f s, flipscope %.2f s (%.1fx faster)\n", vw, vh,
                *vdbTool, main.firstImageSeconds, *vdbTool / main.firstImageSeconds);
  else if (!a.skipVdbTool)
    std::printf("\nvdb_tool not found (Debian package libopenvdb-tools): no comparison\n");
  for (const PeerComparison& p : peers) p.print();
  if (peerSummary && peers.size() > 1) peerSummary->print();
  std::printf("images in %s\n", work.c_str());
}

}  // namespace

void addBenchRenderCommand(CLI::App& bench) {
  auto args = std::make_shared<BenchRenderArgs>();
  auto* cmd = bench.add_subcommand("render", "First-image and per-frame times, beside vdb_tool -points2ls -render");
  cmd->add_option("--particles", args->particles, "Synth particles in the frame")->capture_default_str();
  cmd->add_option("--work-dir", args->workDir, "Where the PLY, store and images go (default: a temp directory)");
  cmd->add_option("--sizes", args->sizes, "Image sizes WxH,... (the last one is compared with vdb_tool)")
      ->capture_default_str();
  cmd->add_option("--orbit-frames", args->orbitFrames, "Warm frames timed")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  cmd->add_option("--device", args->device, "auto, gpu, cpu or cpu-reference")
      ->check(CLI::IsMember({"auto", "gpu", "cpu", "cpu-reference"}))
      ->capture_default_str();
  cmd->add_option("--gpu-mem", args->gpuMem, "The most the brick pool may take")->capture_default_str();
  cmd->add_flag("--no-vdb-tool", args->skipVdbTool, "Skip the vdb_tool comparison");
  auto* peer =
      cmd->add_option("--peer", args->peer,
                      "Also render the same particles with this peer, in the same run: embree (Embree 3 sphere points, "
                      "when built in), beside flipscope's convert and CPU ray-caster")
          ->check(CLI::IsMember({"embree"}));
  cmd->add_option("--peer-runs", args->peerRuns,
                  "Run the peer comparison this many times, one after another, and print each target's median, "
                  "range and the runs that met it")
      ->check(CLI::Range(1, 100))
      ->capture_default_str()
      ->needs(peer);
  cmd->add_flag("--json", args->json, "Machine-readable output");
  cmd->callback([args] { runBenchRender(*args); });
}

}  // namespace flipscope::tools
