// The foam and absorption rows of `bench surface` and `bench render` (Reichl et al. 2014 §3.5,
// §3.6; Table 2 gives 0.15 ms of foam classification per 64^3 brick, Table 3 12 to 34 ms of
// volumetric foam and 12 to 14 ms of absorption per 1280x720 frame on a GTX Titan).
#pragma once

#include <filesystem>
#include <string>

#include "raycast/Camera.h"
#include "raycast/FrameRenderer.h"
#include "raycast/GpuRaycaster.h"

namespace flipscope::tools {

/// Foam classification of every brick a cold frame uploads, timed on the device (the median of
/// `repeats` fresh renderers).
struct FoamClassifyTiming {
  std::string device;
  std::uint64_t bricks = 0;
  double msPerBrick = 0;
};
FoamClassifyTiming timeFoamClassification(const std::filesystem::path& store, DeviceChoice device,
                                          const RenderSettings& settings, const Camera& camera, int repeats);

/// The ray-caster's warm trace (median of `frames` one-pass frames) with foam and absorption added
/// one at a time: spheres only (foam kept, no thickness), + the thickness trace (§3.6), + foam
/// cells skipped (--foam remove), + the volumetric foam (--foam volume).
struct FoamTraceTiming {
  std::string device;
  double spheresMs = 0, absorptionMs = 0, removeMs = 0, volumeMs = 0;
  double classifyMs = 0;  ///< of the cold frame with foam
  double absorptionCost() const { return absorptionMs - spheresMs; }
  double volumeCost() const { return volumeMs - removeMs; }
};
FoamTraceTiming timeFoamAndAbsorption(const std::filesystem::path& store, DeviceChoice device,
                                      const RenderSettings& settings, const Camera& camera, int frames);

}  // namespace flipscope::tools
