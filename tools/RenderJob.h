// A render job: frames of a brick store through FrameRenderer to EXR/PNG files, shared by
// `flipscope render` and `flipscope demo`.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pipeline/FramePipeline.h"
#include "raycast/Camera.h"
#include "raycast/FrameRenderer.h"
#include "raycast/GpuRaycaster.h"

namespace flipscope::tools {

struct RenderJob {
  std::string store;
  std::string output;             ///< .exr or .png; '#' runs take the zero-padded frame number
  std::optional<int> firstFrame;  ///< default: the store's first frame
  std::optional<int> lastFrame;   ///< inclusive; default: firstFrame
  RenderSettings settings;       ///< settings.radius is replaced by `radius`
  std::optional<float> radius;   ///< sphere radius in cells; default: defaultSphereRadius(store)
  SurfaceSettings surface;       ///< smoothing and shading; surface.up is set from `up`
  /// Colour by the store's attribute (--color-by; surface.shading.colorByAttribute is set from
  /// it). Unset: when the shading mode is `attribute` and the store has one. When set, an unset
  /// surface.shading.colorRange becomes the store's attribute range.
  std::optional<bool> colorByAttribute;
  std::optional<Camera> camera;  ///< default: framed on the frames' bricks
  glm::dvec3 up{0, 1, 0};        ///< up axis of the default camera
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

/// The camera a render job frames when none is given: frameOnBox over the occupied cells of
/// every frame of [first, last] (one camera for the whole flipbook), or over the domain when
/// they hold no brick. Throws FileError naming the source when no camera can frame it.
Camera defaultRenderCamera(BrickSource& source, int first, int last, std::uint32_t width, std::uint32_t height,
                           glm::dvec3 up);

/// `pattern` with each run of '#' replaced by `frame`, zero-padded to the run's length.
std::string outputPathForFrame(const std::string& pattern, int frame);

}  // namespace flipscope::tools
