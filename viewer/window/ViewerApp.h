// `flipscope view`: the interactive previewer (Reichl et al. 2014 §3.3, §5 "System Behavior").
// A window (GLFW, OpenGL 4.5 core) in whose context the GPU frame pipeline runs, or, where the
// only OpenGL is software, the CPU pipeline with its image shown as a texture. Every displayed
// frame runs one bounded slice of work (FramePipeline::advance): it never waits for brick
// conversion, which runs on the Streamer's threads, and the picture refines over the next
// frames. Orbit, pan, zoom, fly; a timeline with read-ahead; a Dear ImGui panel of settings and
// live statistics (ViewerPanel.cpp); screenshots and camera files that `render` reads.
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/FramePipeline.h"
#include "viewer/CacheConversion.h"
#include "viewer/FrameTimeHistory.h"
#include "viewer/Timeline.h"
#include "viewer/ViewNavigation.h"
#include "viewer/ViewerOptions.h"
#include "viewer/ViewerScript.h"

struct GLFWwindow;

namespace flipscope {
class StoreBrickSource;
}

namespace flipscope::viewer {

class GlfwWindow;
class DisplayTexture;

/// Runs the viewer until its window is closed (or --screenshot is written, or the script
/// quits). Returns the exit code; throws InputError/FileError for bad input (main() reports
/// them) and gl::Unavailable when no window can be opened.
int runViewer(const ViewerOptions& options);

/// The look the panel edits; any change rebuilds the frame pipeline.
struct ViewerLook {
  std::string filter = "rof";
  int iterations = -1;     ///< -1: the filter's default
  float strength = -1.0f;  ///< -1: the filter's default
  FoamMode foam = FoamMode::Volume;
  float radius = 1.0f;     ///< cells
  bool jitter = true;
  bool colorByAttribute = false;
  float scale = 1.0f;      ///< render size / window size
  bool operator==(const ViewerLook&) const = default;
};

class ViewerApp {
 public:
  explicit ViewerApp(const ViewerOptions& options);
  ~ViewerApp();  // releases every GL object, then the window
  int run();

 private:
  using Clock = std::chrono::steady_clock;
  // Input, from GLFW's callbacks and from the script alike.
  void onKey(const std::string& name);
  void onDrag(int button, double dx, double dy);
  void onScroll(double steps);
  static void keyCallback(GLFWwindow* window, int key, int scancode, int action, int mods);
  static void cursorCallback(GLFWwindow* window, double x, double y);
  static void buttonCallback(GLFWwindow* window, int button, int action, int mods);
  static void scrollCallback(GLFWwindow* window, double dx, double dy);

  void openSource();           // the store, or the cache conversion of the inputs
  bool pollSource();           // opens the cache store once it has a frame; picks up new frames
  void buildPipeline();        // (re)creates the pipeline for the current look and window size
  void runScript();            // at most one scripted event per frame
  void step(double dtSeconds);  // the frame's slice of work
  void drawPanel();            // ViewerPanel.cpp
  void saveScreenshot(const std::filesystem::path& path);
  void writeStats() const;
  glm::uvec2 renderSize() const;

  ViewerOptions mOptions;
  std::unique_ptr<GlfwWindow> mWindow;
  bool mImGui = false;
  std::unique_ptr<DisplayTexture> mTexture;
  bool mGpu = false;
  std::string mDeviceName;
  std::string mFallbackReason;

  std::filesystem::path mStoreDir;
  std::unique_ptr<CacheConversion> mConversion;
  std::string mConversionStatus;
  Clock::time_point mLastReload{};  ///< of the frame table, while a convert fills the store
  std::shared_ptr<StoreBrickSource> mSource;
  std::unique_ptr<FramePipeline> mPipeline;
  ViewerLook mLook;
  ViewerLook mBuiltLook;
  glm::uvec2 mBuiltSize{0};
  std::optional<Timeline> mTimeline;
  std::optional<ViewNavigation> mNavigation;

  bool mRestart = true;  ///< begin() the frame again (camera, frame or pipeline changed)
  Camera mBegunCamera;
  int mBegunFrame = 0;
  FramePipeline::Progress mProgress;
  StageTimes mLastStages;
  double mFrameStartedMs = 0;   ///< clock of the current frame's begin()
  double mConvergeMs = 0;       ///< begin() to finished of the last converged frame
  double mLongestConvergeMs = 0;
  std::uint64_t mConverged = 0;  ///< frames (begin()s) that converged
  std::uint64_t mUploadedThisFrame = 0;
  std::size_t mFramesCached = 0;  ///< frames with bricks in the CPU cache, as of mFramesCachedAt
  Clock::time_point mFramesCachedAt{};

  FrameTimeHistory mHistory;
  double mStartupMs = -1;   ///< from start until the first image was shown
  double mLongestUiMs = 0;  ///< the longest UI frame after the first image
  Clock::time_point mStart;
  bool mFlyMode = false;
  bool mDragging[3] = {false, false, false};
  double mCursorX = 0, mCursorY = 0;
  std::vector<ScriptEvent> mScript;
  std::size_t mScriptNext = 0;
  Clock::time_point mScriptLast{};
  int mScreenshots = 0;
  std::string mMessage;  ///< the last thing the viewer did or refused (shown in the panel)
  int mExitCode = 0;
};

}  // namespace flipscope::viewer
