// A render job: frames of a brick store through FrameRenderer to EXR/PNG files, shared by
// `flipscope render` and `flipscope demo`.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pipeline/FramePipeline.h"
#include "pipeline/RenderRequest.h"
#include "preprocess/particles/InputSequence.h"
#include "raycast/Camera.h"
#include "raycast/FrameRenderer.h"
#include "raycast/GpuRaycaster.h"

namespace flipscope::tools {

/// The store, frames and outputs of a render, beside what RenderRequest asks of the look.
struct RenderJob : RenderRequest {
  std::string store;
  std::string output;             ///< .exr or .png; '#' runs take the zero-padded frame number
  std::optional<int> firstFrame;  ///< default: the store's first frame
  std::optional<int> lastFrame;   ///< inclusive; default: firstFrame
  std::optional<Camera> camera;  ///< default: framed on the frames' bricks
  std::string saveCamera;        ///< where to write the camera used (--save-camera); empty: nowhere
  DeviceChoice device = DeviceChoice::Auto;
  bool quiet = false;
};

struct RenderedFile {
  int frame;
  std::string path;
  RenderStats stats;
  StageTimes stages;
};

/// Renders every frame of the job (frames missing from the store are an InputError naming the
/// store and the frame, checked before anything is written). Prints the device and one line per
/// frame unless quiet.
std::vector<RenderedFile> runRenderJob(const RenderJob& job);

/// Throws InputError unless `output` ends in .exr or .png and, for more than one frame, has a
/// '#' run for the frame number.
void checkOutputPattern(const std::string& output, FrameRange frames);

/// `pattern` with each run of '#' replaced by `frame`, zero-padded to the run's length.
std::string outputPathForFrame(const std::string& pattern, int frame);

}  // namespace flipscope::tools
