// The peer of `bench render --peer embree`: what a farm without flipscope would use to ray-trace
// the same particles on the CPU, Embree 3's sphere points (RTC_GEOMETRY_TYPE_SPHERE_POINT) with a
// low-quality BVH, primary rays in packets of 16 (4x4 pixels) over every core. It runs in a
// child process of its own (the hidden `bench embree-stage`), so that its peak memory is its
// own. Embree is optional at build time (FLIPSCOPE_HAVE_EMBREE); without it the stage says so.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace flipscope::tools {

/// Whether this build links Embree.
bool embreeAvailable();

struct EmbreeStageRequest {
  std::filesystem::path particles;   ///< any particle file (its positions)
  float radius = 0;                  ///< world units, every sphere
  std::filesystem::path cameraFile;  ///< the camera of the first frame
  std::string size = "1280x720";
  int orbitFrames = 4;               ///< warm frames, turned as the frame stage turns them
};

struct EmbreeStageResult {
  std::string version;            ///< "Embree 3.13.5"
  std::uint64_t particles = 0;
  double readSeconds = 0;         ///< the particle file read into the sphere array (before the build)
  double buildSeconds = 0;        ///< scene committed: the BVH built
  double firstFrameSeconds = 0;   ///< build + first frame
  std::vector<double> warmFrameMs;
  std::uint64_t hits = 0;         ///< pixels of the first frame that hit a sphere
  std::uint64_t embreeBytes = 0;  ///< the most Embree held at once (its memory monitor)
  std::uint64_t peakBytes = 0;    ///< the stage's peak RSS (the particles read included)
  double warmMeanMs() const;
};

/// Runs the stage as a child (output in `work`/embree.log, figures in embree.json, the first
/// frame's image in embree.png). Throws InputError naming the log when it fails.
EmbreeStageResult runEmbreeStage(const EmbreeStageRequest& request, const std::filesystem::path& work);

void addBenchEmbreeStageCommand(CLI::App& bench);

}  // namespace flipscope::tools
