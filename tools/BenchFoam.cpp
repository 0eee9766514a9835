#include "tools/BenchFoam.h"

#include <algorithm>
#include <vector>

#include "pipeline/FramePipeline.h"
#include "streaming/BrickSource.h"
#include "tools/BenchStatistics.h"

namespace flipscope::tools {

namespace {
std::unique_ptr<FrameRenderer> renderer(const std::filesystem::path& store, DeviceChoice device,
                                        const RenderSettings& settings) {
  return std::make_unique<FrameRenderer>(std::make_shared<StoreBrickSource>(BrickStore::open(store)),
                                         createRaycastDevice(device), settings);
}
}  // namespace

FoamClassifyTiming timeFoamClassification(const std::filesystem::path& store, DeviceChoice device,
                                          const RenderSettings& settings, const Camera& camera, int repeats) {
  RenderSettings s = settings;
  s.foam.mode = FoamMode::Remove;
  s.foam.source = FoamSource::Classify;
  FoamClassifyTiming timing;
  std::vector<double> perBrick;
  for (int run = 0; run < std::max(repeats, 1); ++run) {
    auto r = renderer(store, device, s);
    timing.device = r->device().name();
    const RenderStats stats = r->render(0, camera).stats;
    timing.bricks = stats.bricksClassified;
    if (stats.bricksClassified) perBrick.push_back(stats.foamMs / double(stats.bricksClassified));
  }
  std::sort(perBrick.begin(), perBrick.end());
  timing.msPerBrick = perBrick.empty() ? 0 : perBrick[perBrick.size() / 2];
  return timing;
}

FoamTraceTiming timeFoamAndAbsorption(const std::filesystem::path& store, DeviceChoice device,
                                      const RenderSettings& settings, const Camera& camera, int frames) {
  // The four variants, warmed up, then timed in turn frame after frame (the median of each), so
  // that a change of load on the machine touches all of them alike.
  struct Variant {
    FoamMode mode;
    bool thickness;
    std::unique_ptr<FrameRenderer> renderer;
    std::vector<double> ms;
  };
  std::vector<Variant> variants;
  for (auto [mode, thickness] : {std::pair{FoamMode::Keep, false}, std::pair{FoamMode::Keep, true},
                                 std::pair{FoamMode::Remove, true}, std::pair{FoamMode::Volume, true}}) {
    RenderSettings s = settings;
    s.foam.mode = mode;
    s.thicknessSaturationCells = thickness ? thicknessSaturationCells(ShadingOptions{}) : 0.0f;
    variants.push_back({mode, thickness, renderer(store, device, s), {}});
  }
  FoamTraceTiming timing;
  timing.device = variants.front().renderer->device().name();
  for (Variant& v : variants) {
    const RenderStats cold = v.renderer->render(0, camera).stats;
    if (v.mode == FoamMode::Volume) timing.classifyMs = cold.foamMs;
  }
  for (int i = 0; i < std::max(frames, 1); ++i)
    for (Variant& v : variants) v.ms.push_back(v.renderer->render(0, camera).stats.traceMs);
  timing.spheresMs = median(variants[0].ms);
  timing.absorptionMs = median(variants[1].ms);
  timing.removeMs = median(variants[2].ms);
  timing.volumeMs = median(variants[3].ms);
  return timing;
}

}  // namespace flipscope::tools
