#include "tools/BenchFrameStage.h"

#include <chrono>
#include <fstream>

#include <nlohmann/json.hpp>

#include "core/AtomicFile.h"
#include "core/Elapsed.h"
#include "core/Error.h"
#include "core/ProcessMemory.h"
#include "pipeline/FramePipeline.h"
#include "pipeline/ImageWriter.h"
#include "pipeline/RenderRequest.h"
#include "tools/ChildProcess.h"
#include "tools/CliValues.h"

namespace flipscope::tools {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct FrameStageArgs {
  FrameStageRequest request;
  std::string store;
  std::string cameraFile;
  std::string statsFile;
  std::string image;
};

void runStage(const FrameStageArgs& a) {
  keepHeapForReuse();  // core/ProcessMemory.h
  const auto [width, height] = parseImageSize("--size", a.request.size);
  const auto start = Clock::now();
  BrickStore store = BrickStore::open(a.store);
  const std::vector<int> frames = store.frames();
  if (frames.empty()) throw FileError(a.store, "the store has no frame");
  RenderRequest request;
  request.settings.width = width;
  request.settings.height = height;
  if (a.request.spheres) {
    request.surface.smoothing.name = "none";
    request.surface.shading.mode = ShadingMode::Spheres;
    request.settings.foam.mode = FoamMode::Keep;  // as the peer: every particle a sphere
  }
  // As `render` to a PNG: a look that does not colour by the attribute reads none (the EXR this
  // stage writes to compare depths has no attribute channel).
  request.attributeOutput = false;
  const ResolvedRender look = resolve(request, store);
  FramePipeline pipeline(std::move(store), parseDeviceChoice("--device", a.request.device), look.settings,
                         look.surface);
  pipeline.setOutputLayers(OutputLayers::Colour);  // as `render` to a PNG, and as the Embree peer's image
  const Camera camera = a.cameraFile.empty() ? defaultRenderCamera(pipeline.renderer().source(), frames.front(),
                                                                   frames.front(), width, height, look.surface.up)
                                             : loadCamera(a.cameraFile);
  const FrameOutput& first = pipeline.render(frames.front(), camera);
  const double firstSeconds = secondsSince(start);
  const RenderStats firstStats = first.stats;  // the warm frames reuse the output
  const StageTimes firstStages = first.stages;
  if (!a.image.empty()) {  // to look at, and with its depth (EXR) to compare: read again, untimed
    writeImage(a.image, first.image);
    pipeline.setOutputLayers(OutputLayers::All);
    writeImage(fs::path(a.image).replace_extension(".exr"), pipeline.readOutput().image);
    pipeline.setOutputLayers(OutputLayers::Colour);
  }
  nlohmann::json warm = nlohmann::json::array(), warmTrace = nlohmann::json::array();
  nlohmann::json warmStages = nlohmann::json::array();  // where a warm frame's time goes
  for (int i = 1; i <= a.request.orbitFrames; ++i) {
    const auto t = Clock::now();
    const FrameOutput& frame =
        pipeline.render(frames.front(), orbitAbout(camera, look.surface.up, kOrbitStepDegrees * i));
    warm.push_back(secondsSince(t) * 1e3);
    warmTrace.push_back(frame.stats.traceMs);
    const StageTimes& st = frame.stages;
    warmStages.push_back({{"trace", st.trace},
                          {"gbuffer", st.gbuffer},
                          {"smoothing", st.smoothing},
                          {"normals", st.normals},
                          {"shading", st.shading},
                          {"readback", st.readback}});
  }
  const nlohmann::json j{{"device", pipeline.deviceName()},
                         {"first_image_s", firstSeconds},
                         {"bricks_touched", firstStats.bricksUploaded},
                         {"frame_bricks", firstStats.frameBricks},
                         {"first_frame",  // where the cold frame's time goes (FrameRenderer's RenderStats)
                          {{"passes", firstStats.passes},
                           {"trace_ms", firstStats.traceMs},
                           {"stream_ms", firstStats.streamMs},
                           {"upload_ms", firstStats.uploadMs},
                           {"foam_ms", firstStats.foamMs},
                           {"render_ms", firstStats.totalMs},
                           {"image_ms", firstStages.total}}},
                         {"warm_frame_ms", warm},
                         {"warm_trace_ms", warmTrace},
                         {"warm_stages_ms", warmStages},
                         {"peak_rss_bytes", peakResidentBytes()}};
  writeTextAtomically(a.statsFile, j.dump(2) + "\n");
}

}  // namespace

double meanOf(const std::vector<double>& values) {
  double sum = 0;
  for (double v : values) sum += v;
  return values.empty() ? 0 : sum / double(values.size());
}

double FrameStageResult::warmMeanMs() const { return meanOf(warmFrameMs); }
double FrameStageResult::warmTraceMeanMs() const { return meanOf(warmTraceMs); }

FrameStageResult runFrameStage(const FrameStageRequest& request, const fs::path& work, const std::string& name) {
  const fs::path stats = work / (name + ".json"), log = work / (name + ".log");
  std::vector<std::string> arguments{"bench",
                                     "frame-stage",
                                     request.store.string(),
                                     "--stats-file",
                                     stats.string(),
                                     "--image",
                                     (work / (name + ".png")).string(),
                                     "--size",
                                     request.size,
                                     "--orbit-frames",
                                     std::to_string(request.orbitFrames),
                                     "--device",
                                     request.device};
  if (!request.cameraFile.empty()) arguments.insert(arguments.end(), {"--camera-file", request.cameraFile.string()});
  if (request.spheres) arguments.push_back("--spheres");
  runFlipscopeStage("frame stage (" + name + ")", arguments, log);
  std::ifstream in(stats);
  const nlohmann::json j = nlohmann::json::parse(in);
  FrameStageResult r;
  r.device = j["device"].get<std::string>();
  r.firstImageSeconds = j["first_image_s"].get<double>();
  r.bricksTouched = j["bricks_touched"].get<std::uint64_t>();
  r.frameBricks = j["frame_bricks"].get<std::uint64_t>();
  r.warmFrameMs = j["warm_frame_ms"].get<std::vector<double>>();
  r.warmTraceMs = j["warm_trace_ms"].get<std::vector<double>>();
  r.peakBytes = j["peak_rss_bytes"].get<std::uint64_t>();
  return r;
}

void addBenchFrameStageCommand(CLI::App& bench) {
  auto args = std::make_shared<FrameStageArgs>();
  auto* cmd = bench.add_subcommand("frame-stage", "(internal) one store's frame from cold, then warm orbit frames");
  cmd->group("");  // run by the benchmarks, not listed
  cmd->add_option("store", args->store)->required();
  cmd->add_option("--stats-file", args->statsFile)->required();
  cmd->add_option("--image", args->image);
  cmd->add_option("--size", args->request.size);
  cmd->add_option("--orbit-frames", args->request.orbitFrames);
  cmd->add_option("--device", args->request.device);
  cmd->add_option("--camera-file", args->cameraFile);
  cmd->add_flag("--spheres", args->request.spheres);
  cmd->callback([args] { runStage(*args); });
}

}  // namespace flipscope::tools
