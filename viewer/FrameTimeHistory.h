// FrameTimeHistory: the viewer's recent frames for its plots (like Reichl et al. 2014 Fig. 13:
// frame time and bricks uploaded per frame over the last seconds).
#pragma once

#include <cstdint>
#include <deque>
#include <vector>

namespace flipscope::viewer {

class FrameTimeHistory {
 public:
  /// Keeps the frames of the last `seconds`.
  explicit FrameTimeHistory(double seconds = 10.0) : mSeconds(seconds) {}
  /// One UI frame that ended at `timeSeconds` (monotonic), took `frameMs`, and uploaded
  /// `bricksUploaded` bricks.
  void add(double timeSeconds, double frameMs, std::uint64_t bricksUploaded);
  /// Frame times and uploads of the kept frames, oldest first (what ImGui::PlotLines takes).
  std::vector<float> frameMs() const;
  std::vector<float> bricksUploaded() const;
  /// Frames per second over the kept frames (0 with fewer than two).
  double fps() const;
  /// How many frames were added since construction.
  std::uint64_t frames() const { return mFrames; }

 private:
  struct Sample {
    double time;
    float ms;
    float bricks;
  };
  double mSeconds;
  std::deque<Sample> mSamples;
  std::uint64_t mFrames = 0;
};

}  // namespace flipscope::viewer
