// The frame stage of the benchmarks that time a frame in a process of its own (bench scale,
// bench render --peer): the hidden `flipscope bench frame-stage STORE`, which renders the
// store's first frame once from cold (store opened to converged image) and then warm frames of
// an orbit, and writes its figures and its own peak RSS as JSON; and the parent's side, which
// runs it as a child and reads them.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace flipscope::tools {

struct FrameStageRequest {
  std::filesystem::path store;
  std::string size = "1280x720";
  int orbitFrames = 4;
  std::string device = "cpu";
  std::filesystem::path cameraFile;  ///< empty: `render`'s default camera, framed on the frame
  /// The ray-caster's lit spheres of every particle only (--smoothing none --shading spheres
  /// --foam keep), else `render`'s look.
  bool spheres = false;
};

struct FrameStageResult {
  std::string device;
  double firstImageSeconds = 0;     ///< store opened to converged first image
  std::uint64_t bricksTouched = 0;  ///< uploaded for the first image
  std::uint64_t frameBricks = 0;    ///< non-empty bricks of the frame
  std::vector<double> warmFrameMs;  ///< each warm frame of the orbit, whole
  std::vector<double> warmTraceMs;  ///< the ray-caster's share of each
  std::uint64_t peakBytes = 0;      ///< the stage's peak RSS
  double warmMeanMs() const;
  double warmTraceMeanMs() const;
};

/// Runs the frame stage as a child (its output in `work`/`name`.log, its figures in
/// `work`/`name`.json, its first image in `work`/`name`.png and, with depth, `name`.exr).
/// Throws InputError naming the log when it fails.
FrameStageResult runFrameStage(const FrameStageRequest& request, const std::filesystem::path& work,
                               const std::string& name);

/// The mean of `values`; 0 for none.
double meanOf(const std::vector<double>& values);

/// The degrees between two frames of the benchmarks' orbits, about the up axis.
inline constexpr double kOrbitStepDegrees = 2.0;

void addBenchFrameStageCommand(CLI::App& bench);

}  // namespace flipscope::tools
