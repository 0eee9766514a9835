// What `flipscope view` is asked to do (tools/ViewCommand.cpp parses the command line into it).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/RenderRequest.h"
#include "raycast/Camera.h"
#include "raycast/GpuRaycaster.h"

namespace flipscope::viewer {

struct ViewerOptions {
  /// A brick store directory, or particle inputs (files or sequence patterns) to convert into a
  /// cache store first (viewer/CacheConversion.h).
  std::vector<std::string> inputs;
  std::filesystem::path cacheDir;     ///< --cache: where a cache store goes; default beside the input
  std::vector<std::string> convertArgs;  ///< extra options of that convert (e.g. --resolution 256)
  /// The look; request.settings.width/height is the window's size in pixels (--size).
  RenderRequest request;
  std::optional<Camera> camera;       ///< --camera / --camera-file; default: framed on the frame
  std::optional<int> frame;           ///< --frame: the first frame shown; default: the first
  DeviceChoice device = DeviceChoice::Auto;
  /// Render size / window size; 0: 1 on a GPU, 0.5 on the CPU pipeline (--scale).
  double resolutionScale = 0;
  double budgetMs = 25;               ///< ray-casting per displayed frame (--budget-ms)
  int readAheadFrames = 8;            ///< frames prefetched in the playing direction
  int readDelayMs = 0;                ///< --read-delay-ms: every brick read waits this long (slow storage)
  std::filesystem::path screenshot;   ///< --screenshot: render once, converged, save, exit
  std::filesystem::path script;       ///< --script: timed input events (viewer/ViewerScript.h)
  std::filesystem::path saveCamera;   ///< where C writes the camera
  std::filesystem::path statsFile;    ///< --stats: JSON written at exit (longest UI frame, ...)
  std::filesystem::path program;      ///< the flipscope binary (for the cache conversion)
  bool quiet = false;
};

}  // namespace flipscope::viewer
