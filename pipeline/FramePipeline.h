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
#include <memory>
#include <string>

#include <glm/vec3.hpp>

#include "raycast/Camera.h"
#include "raycast/FrameRenderer.h"
#include "raycast/GpuRaycaster.h"
#include "raycast/ImageWriter.h"
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
  RenderImage image;
  RenderStats stats;   ///< the ray-caster's
  StageTimes stages;
};

class FramePipeline {
 public:
  /// Renders the bricks of `source`, shared with the ray-caster's Streamer (`settings` as given,
  /// but for the thickness trace, which thicknessSaturationCells sets). Throws InputError
  /// for bad settings, FileError for an unreadable environment map, and gl::Unavailable when
  /// `device` is Gpu and there is none. `fallbackReason` says why Auto chose the CPU.
  FramePipeline(std::shared_ptr<BrickSource> source, DeviceChoice device, const RenderSettings& settings,
                const SurfaceSettings& surface, std::string* fallbackReason = nullptr);
  /// The same over a store (through a StoreBrickSource).
  FramePipeline(BrickStore store, DeviceChoice device, const RenderSettings& settings,
                const SurfaceSettings& surface, std::string* fallbackReason = nullptr);
  ~FramePipeline();
  FramePipeline(const FramePipeline&) = delete;
  FramePipeline& operator=(const FramePipeline&) = delete;

  FrameOutput render(int frame, const Camera& camera, int direction = 0);

  FrameRenderer& renderer() { return *mRenderer; }
  const FrameRenderer& renderer() const { return *mRenderer; }
  /// The ray-caster's device and the screen stages' ("OpenGL (device): ..." or "CPU reference").
  std::string deviceName() const;
  /// The frame block of `camera` for this pipeline's image size, radius and up axis.
  ScreenFrame screenFrame(const Camera& camera) const;

 private:
  struct Stages;
  std::unique_ptr<FrameRenderer> mRenderer;
  std::unique_ptr<ScreenDevice> mScreen;  // destroyed before the renderer's GL context
  std::unique_ptr<Stages> mStages;
  SurfaceSettings mSurface;
};

/// Liquid cells at which the thickness trace behind a hit stops (§3.6): where the channel that
/// `shading` absorbs least keeps 1% of the light, at most kThicknessMaxCells.
float thicknessSaturationCells(const ShadingOptions& shading);

/// Loads an equirectangular environment (any EXR with R, G, B). Throws FileError naming `path`.
EnvironmentMap loadEnvironmentMap(const std::filesystem::path& path);

}  // namespace flipscope
