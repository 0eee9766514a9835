// FramePipeline: one frame from the brick store to a shaded image, on one device (Reichl et al.
// 2014 §3.3 Fig. 3): the request-driven ray-caster (raycast/FrameRenderer.h) writes its hits;
// they stay on the device as the G-buffer (linear depth, mask, thickness, attribute, sphere
// normals); the surface filter smooths the depth (smoothing/SurfaceFilter.h, §3.4); normals are
// reconstructed from the smoothed depth and the surface is shaded (§3.6). On a GPU every stage
// is a compute pass in the ray-caster's context; on the CPU every stage is its C++ reference.
// `render`, `demo`, `bench` and the viewer all render through it. Bricks come from any
// BrickSource (streaming/BrickSource.h): a store, or a synthetic source in tests.
//
//   FramePipeline pipeline(BrickStore::open(dir), DeviceChoice::Auto, RenderSettings{}, SurfaceSettings{});
//   FramePipeline synthetic(std::make_shared<SyntheticBrickSource>(32, glm::uvec3(4, 4, 2), 1, 0.3),
//                           DeviceChoice::Cpu, RenderSettings{}, SurfaceSettings{});
//   FrameOutput out = pipeline.render(frame, camera);
//   writeImage("a.exr", out.image);
//
// Not thread safe; one pipeline per device.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include <glm/vec3.hpp>

#include "pipeline/ImageWriter.h"
#include "raycast/Camera.h"
#include "raycast/FrameRenderer.h"
#include "raycast/GpuRaycaster.h"
#include "smoothing/ScreenDevice.h"
#include "smoothing/SurfaceFilter.h"
#include "smoothing/SurfaceShading.h"

namespace flipscope {

struct SurfaceSettings {
  SmoothingOptions smoothing;          ///< --smoothing, --smoothing-iterations, --smoothing-strength
  ShadingOptions shading;              ///< --shading and the look
  std::filesystem::path environment;   ///< equirectangular EXR (--env); empty: procedural sky
  glm::dvec3 up{0, 1, 0};              ///< the scene's up axis (the environment's)
};

/// Milliseconds of each stage of a frame (GPU stages are timed to completion).
struct StageTimes {
  double trace = 0;      ///< the ray-caster's passes, streaming and uploads included
  double gbuffer = 0;
  double smoothing = 0;
  double normals = 0;
  double shading = 0;
  double readback = 0;   ///< images to host memory
  double total = 0;
};

struct FrameOutput {
  int frame = 0;
  /// rgba: the shaded frame (alpha 1, the environment behind the liquid); depth: the smoothed
  /// surface (+inf on the background); unsmoothedDepth; normal (smoothed); thickness; foam (with
  /// --foam volume: its premultiplied colour and opacity, composited into rgba); attribute
  /// (when the store has one: the value of the nearest hit cell, the largest of its particles'
  /// 16-bit values, in the attribute's units; 0 on the background), named after the attribute.
  /// With OutputLayers::Colour, rgba alone: the other layers are empty.
  RenderImage image;
  RenderStats stats;   ///< the ray-caster's
  StageTimes stages;
};

/// What readOutput() reads back: every layer of the image (an EXR keeps them), or the colour
/// alone (a PNG): at 3840x2160, 330 MB of layers and the pass that fills them.
enum class OutputLayers { All, Colour };

class FramePipeline {
 public:
  /// Renders the bricks of `source`, shared with the ray-caster's Streamer (`settings` as given,
  /// but for the thickness trace, which thicknessSaturationCells sets). Throws InputError
  /// for bad settings, FileError for an unreadable environment map, and gl::Unavailable when
  /// `device` is Gpu and there is none. `fallbackReason` says why Auto chose the CPU.
  FramePipeline(std::shared_ptr<BrickSource> source, DeviceChoice device, const RenderSettings& settings,
                const SurfaceSettings& surface, std::string* fallbackReason = nullptr);
  /// The same on a ray-caster made by the caller (the viewer's GpuRaycaster in its window's
  /// context, which must be current while the pipeline is used and destroyed).
  FramePipeline(std::shared_ptr<BrickSource> source, std::unique_ptr<RaycastDevice> raycaster,
                const RenderSettings& settings, const SurfaceSettings& surface);
  /// The same over a store (through a StoreBrickSource).
  FramePipeline(BrickStore store, DeviceChoice device, const RenderSettings& settings,
                const SurfaceSettings& surface, std::string* fallbackReason = nullptr);
  ~FramePipeline();
  FramePipeline(const FramePipeline&) = delete;
  FramePipeline& operator=(const FramePipeline&) = delete;

  /// The frame converged (or stopped at the pass limit), shaded and read back. The output is
  /// the pipeline's, valid until the next render() or readOutput(), which reuse its images.
  const FrameOutput& render(int frame, const Camera& camera, int direction = 0);

  /// Progressive rendering for the viewer. begin() starts `frame` from `camera`; each advance()
  /// runs ray-caster passes for about `budgetMs` without waiting for brick conversion
  /// (FrameRenderer::advance), then, when any ray changed, the screen stages over the rays so
  /// far and the display image: the shaded frame where rays have finished, the image shown
  /// before where they are still pending (pipeline/glsl/Progressive.glsl). Once finished() the
  /// display is the image render() gives.
  struct Progress {
    bool changed = false;  ///< the display image was redrawn in this call
    RenderStats stats;     ///< the frame's so far
    StageTimes stages;     ///< of this call: trace and, when changed, the screen stages
  };
  void begin(int frame, const Camera& camera, int direction = 0);
  Progress advance(double budgetMs);
  bool finished() const { return mRenderer->finished(); }
  /// The images of the last shaded frame (begin()'s frame), as render() returns them (and as
  /// long).
  const FrameOutput& readOutput();
  /// What render() and readOutput() read back from now on (OutputLayers::All at first).
  void setOutputLayers(OutputLayers layers) { mOutputLayers = layers; }
  /// The display image, rgba per pixel, row 0 at the top (zeros before the first advance()).
  std::vector<glm::vec4> downloadDisplay();
  /// The display image's shader storage buffer (vec4 per pixel) in the pipeline's OpenGL
  /// context; nullptr when the pipeline runs on the CPU.
  const gl::Buffer* displayBuffer();

  FrameRenderer& renderer() { return *mRenderer; }
  const FrameRenderer& renderer() const { return *mRenderer; }
  /// The ray-caster's device ("OpenGL (device): ...", "CPU (2 threads)" or "CPU reference (2 threads)").
  std::string deviceName() const;
  /// The frame block of `camera` for this pipeline's image size, radius and up axis.
  ScreenFrame screenFrame(const Camera& camera) const;

 private:
  struct Stages;
  void init(std::shared_ptr<BrickSource> source, const std::function<std::unique_ptr<RaycastDevice>()>& makeRaycaster,
            const RenderSettings& settings);
  /// The screen stages over the ray-caster's current hits, into the stages' images.
  void shade(int frame, const Camera& camera, StageTimes& stages);
  /// The progressive display's images, made (cleared) on first use: a batch render has none.
  void makeDisplayImages();
  std::unique_ptr<FrameRenderer> mRenderer;
  std::unique_ptr<ScreenDevice> mScreen;  // destroyed before the renderer's GL context
  std::unique_ptr<Stages> mStages;
  FrameOutput mOutput;  ///< the last read back, its images reused frame to frame
  OutputLayers mOutputLayers = OutputLayers::All;
  SurfaceSettings mSurface;
  int mFrame = 0;          ///< of the last begin() or render()
  Camera mCamera;
};

/// Liquid cells at which the thickness trace behind a hit stops (§3.6): where the channel that
/// `shading` absorbs least keeps 1% of the light, at most kThicknessMaxCells.
float thicknessSaturationCells(const ShadingOptions& shading);

/// Loads an equirectangular environment (any EXR with R, G, B). Throws FileError naming `path`.
EnvironmentMap loadEnvironmentMap(const std::filesystem::path& path);

}  // namespace flipscope
