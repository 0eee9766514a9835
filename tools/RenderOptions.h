// The options of the look of a render that `render` and `view` share (radius, jitter, surface
// filter, shading, colour, foam, memory, device, camera, up axis): registered once, parsed once
// into a RenderRequest.
#pragma once

#include <optional>
#include <string>

#include "pipeline/RenderRequest.h"
#include "raycast/Camera.h"
#include "raycast/GpuRaycaster.h"

namespace CLI {
class App;
}

namespace flipscope::tools {

struct RenderLookArgs {
  std::string size = "1280x720";
  std::string camera;
  std::string cameraFile;
  std::string saveCamera;
  std::string up = "auto";
  std::optional<float> radius;
  std::string smoothing = "rof";
  std::optional<int> smoothingIterations;
  std::optional<float> smoothingStrength;
  std::string shading = "liquid";
  std::string colorBy;  ///< empty: not given
  std::optional<std::string> colorMap;
  std::optional<std::string> colorRange;
  std::string environment;
  std::string jitter = "on";
  std::string foam = "volume";
  std::string foamFrom = "both";
  float foamThreshold = 0.2f;
  std::string bubbles = "hide";
  std::string gpuMem = "1G";
  std::string cpuMem = "2G";
  std::string device = "auto";
  int maxPasses = 1000;
};

/// Registers the shared options on `cmd`, writing into `args` (which must outlive parsing).
void addRenderLookOptions(CLI::App& cmd, RenderLookArgs& args);

struct ParsedLook {
  RenderRequest request;
  std::optional<Camera> camera;  ///< --camera or --camera-file
  DeviceChoice device = DeviceChoice::Auto;
};
/// Throws InputError naming the option for a bad value, FileError for a bad camera file.
ParsedLook parseRenderLook(const RenderLookArgs& args);

}  // namespace flipscope::tools
