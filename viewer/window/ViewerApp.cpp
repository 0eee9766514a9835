#include "viewer/window/ViewerApp.h"

#include <epoxy/gl.h>

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include <nlohmann/json.hpp>

#include "core/AtomicFile.h"
#include "core/Error.h"
#include "gl/EglContext.h"
#include "pipeline/ImageWriter.h"
#include "preprocess/particles/InputSequence.h"
#include "raycast/CpuRaycaster.h"
#include "raycast/GpuRaycaster.h"
#include "raycast/TiledCpuRaycaster.h"
#include "streaming/DelayedBrickSource.h"
#include "viewer/window/DisplayTexture.h"
#include "viewer/window/GlfwWindow.h"

namespace flipscope::viewer {

namespace {
double msBetween(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

ViewerApp* appOf(GLFWwindow* window) { return static_cast<ViewerApp*>(glfwGetWindowUserPointer(window)); }

/// GLFW key -> the name the script uses (viewer/ViewerScript.h); "" for keys the viewer ignores.
std::string keyName(int key) {
  if (key >= GLFW_KEY_A && key <= GLFW_KEY_Z) return std::string(1, char('a' + (key - GLFW_KEY_A)));
  if (key >= GLFW_KEY_0 && key <= GLFW_KEY_9) return std::string(1, char('0' + (key - GLFW_KEY_0)));
  switch (key) {
    case GLFW_KEY_SPACE: return "space";
    case GLFW_KEY_LEFT: return "left";
    case GLFW_KEY_RIGHT: return "right";
    case GLFW_KEY_HOME: return "home";
    case GLFW_KEY_END: return "end";
    case GLFW_KEY_ESCAPE: return "escape";
    case GLFW_KEY_TAB: return "tab";
    default: return "";
  }
}

/// W A S D Q E: the keys that move the camera in fly mode.
bool isFlyKey(const std::string& name) {
  return name.size() == 1 && std::string_view("wasdqe").find(name[0]) != std::string_view::npos;
}
}  // namespace

int runViewer(const ViewerOptions& options) {
  ViewerApp app(options);
  return app.run();
}

ViewerApp::ViewerApp(const ViewerOptions& options) : mOptions(options), mStart(Clock::now()) {
  if (mOptions.inputs.empty()) throw InputError("view: give a brick store or particle files to view");
  if (!mOptions.script.empty()) mScript = loadViewerScript(mOptions.script);
  if (!mOptions.screenshot.empty() && !isImagePath(mOptions.screenshot))
    throw InputError("--screenshot: '" + mOptions.screenshot.string() + "' must end in .exr or .png");
  const RenderSettings& s = mOptions.request.settings;
  mWindow = std::make_unique<GlfwWindow>(int(s.width), int(s.height), "flipscope view",
                                         mOptions.device != DeviceChoice::Gpu);
  glfwSetWindowUserPointer(mWindow->handle(), this);
  glfwSetKeyCallback(mWindow->handle(), keyCallback);
  glfwSetCursorPosCallback(mWindow->handle(), cursorCallback);
  glfwSetMouseButtonCallback(mWindow->handle(), buttonCallback);
  glfwSetScrollCallback(mWindow->handle(), scrollCallback);

  // The device: the GPU pipeline in this window's context, unless that is software OpenGL.
  const std::string renderer = gl::currentRenderer();
  const bool software = gl::isSoftwareRenderer(renderer);
  if (mOptions.device == DeviceChoice::Gpu) {
    mGpu = true;
  } else if (mOptions.device == DeviceChoice::Auto) {
    mGpu = !software && mWindow->glVersion() >= 45;
    if (!mGpu)
      mFallbackReason = mWindow->glVersion() < 45 ? "the window has no OpenGL 4.5"
                                                  : "the window's OpenGL is software (" + renderer + ")";
  }

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini beside the user's files
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(mWindow->handle(), true);  // chains to the callbacks above
  ImGui_ImplOpenGL3_Init("#version 330 core");
  mImGui = true;
  mTexture = std::make_unique<DisplayTexture>();
  mLook.scale = float(mOptions.resolutionScale > 0 ? mOptions.resolutionScale
                      : (mGpu || !mOptions.screenshot.empty()) ? 1.0
                                                               : 0.5);
  openSource();
}

ViewerApp::~ViewerApp() {
  if (mWindow) glfwMakeContextCurrent(mWindow->handle());
  mPipeline.reset();  // its GL objects (GPU pipeline) go while the context lives
  mTexture.reset();
  if (mImGui) {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
  }
  mConversion.reset();  // stops a convert still running
  mWindow.reset();
}

void ViewerApp::openSource() {
  if (isStoreDirectory(mOptions.inputs)) {
    mStoreDir = mOptions.inputs.front();
    BrickStore store = BrickStore::open(mStoreDir);
    if (store.incomplete())
      throw FileError(mStoreDir, "the store has no complete frame (an interrupted convert? convert again)");
    mSource = std::make_shared<StoreBrickSource>(std::move(store));
  } else {
    mStoreDir = cacheStorePath(mOptions.inputs, mOptions.cacheDir);
    if (BrickStore::exists(mStoreDir) && !BrickStore::open(mStoreDir).incomplete()) {
      mMessage = "cache " + mStoreDir.string() + " (delete it to convert again)";
      mSource = std::make_shared<StoreBrickSource>(BrickStore::open(mStoreDir));
    } else {
      mConversion = std::make_unique<CacheConversion>(mOptions.program, mOptions.inputs, mStoreDir, mOptions.convertArgs);
      mConversionStatus = "converting into " + mStoreDir.string();
      if (!mOptions.quiet) std::printf("view: converting into %s\n", mStoreDir.c_str());
    }
  }
  if (mSource) pollSource();
}

bool ViewerApp::pollSource() {
  if (mConversion) {
    const bool running = mConversion->running();
    mConversionStatus = running ? "converting: " + mConversion->lastLine() : "";
    if (!running && mConversion->exitCode() != 0) {
      mConversionStatus = "convert failed (exit " + std::to_string(mConversion->exitCode()) +
                          "): " + mConversion->lastLine() + " (log: " + mConversion->logPath().string() + ")";
      if (!mSource) throw FileError(mStoreDir, "the conversion failed: " + mConversion->lastLine());
    }
    if (!mSource) {
      if (BrickStore::exists(mStoreDir)) {
        BrickStore store = BrickStore::open(mStoreDir);
        if (!store.incomplete()) mSource = std::make_shared<StoreBrickSource>(std::move(store));
      }
      if (!mSource) return false;
    } else if (msBetween(mLastReload, Clock::now()) > 250 || !running) {
      mLastReload = Clock::now();
      mSource->reloadFrames();
    }
    if (!running && mConversion->exitCode() == 0) {
      mConversion.reset();
      mMessage = "converted into " + mStoreDir.string();
    }
  }
  const std::vector<int> frames = mSource->frames();
  if (!mTimeline) {
    mTimeline.emplace(frames);
    if (mOptions.frame) {
      if (!mSource->hasFrame(*mOptions.frame))
        throw InputError(mStoreDir.string() + ": the store has no frame " + std::to_string(*mOptions.frame));
      mTimeline->seek(*mOptions.frame);
    }
    // The panel starts from what the command line asked, resolved against the store.
    const ResolvedRender resolved = resolve(mOptions.request, mSource->store());
    mLook.filter = resolved.surface.smoothing.name;
    mLook.iterations = resolved.surface.smoothing.iterations;
    mLook.strength = resolved.surface.smoothing.strength;
    mLook.foam = resolved.settings.foam.mode;
    mLook.radius = resolved.settings.radius;
    mLook.jitter = resolved.settings.jitter > 0;
    mLook.colorByAttribute = resolved.surface.shading.colorByAttribute;
    const glm::uvec2 size = renderSize();
    const Camera home =
        mOptions.camera ? *mOptions.camera
                        : defaultRenderCamera(*mSource, mTimeline->frame(), mTimeline->frame(), size.x, size.y,
                                              resolved.surface.up);
    mNavigation.emplace(home, resolved.surface.up);
  } else if (frames != mTimeline->frames()) {
    mTimeline->setFrames(frames);
  }
  return true;
}

glm::uvec2 ViewerApp::renderSize() const {
  if (!mOptions.screenshot.empty())
    return {mOptions.request.settings.width, mOptions.request.settings.height};  // what `render --size` makes
  const double scale = std::clamp(double(mLook.scale), 0.1, 2.0);
  return {std::max(1u, std::uint32_t(std::lround(std::max(1, mWindow->width()) * scale))),
          std::max(1u, std::uint32_t(std::lround(std::max(1, mWindow->height()) * scale)))};
}

void ViewerApp::buildPipeline() {
  const glm::uvec2 size = renderSize();
  if (mPipeline && mBuiltLook == mLook && mBuiltSize == size) return;
  // The command line's request with the panel's look, resolved as `render` resolves it.
  RenderRequest request = mOptions.request;
  request.settings.width = size.x;
  request.settings.height = size.y;
  request.settings.jitter =
      mLook.jitter ? (mOptions.request.settings.jitter > 0 ? mOptions.request.settings.jitter : RenderSettings{}.jitter)
                   : 0.0f;
  request.settings.foam.mode = mLook.foam;
  request.settings.readAheadFrames = mOptions.readAheadFrames;
  request.radius = mLook.radius;
  request.surface.smoothing = {mLook.filter, mLook.iterations, mLook.strength};
  request.colorByAttribute = mLook.colorByAttribute;
  const auto [settings, surface] = resolve(request, mSource->store());
  mPipeline.reset();
  std::unique_ptr<RaycastDevice> raycaster;
  if (mGpu)
    raycaster = std::make_unique<GpuRaycaster>(GpuRaycaster::AdoptCurrentContext{});
  else if (mOptions.device == DeviceChoice::CpuReference)
    raycaster = std::make_unique<CpuRaycaster>();
  else
    raycaster = std::make_unique<TiledCpuRaycaster>();
  std::shared_ptr<BrickSource> source = mSource;
  if (mOptions.readDelayMs > 0)
    source = std::make_shared<DelayedBrickSource>(mSource, std::chrono::milliseconds(mOptions.readDelayMs));
  mPipeline = std::make_unique<FramePipeline>(std::move(source), std::move(raycaster), settings, surface);
  mDeviceName = mPipeline->deviceName();
  mBuiltLook = mLook;
  mBuiltSize = size;
  mRestart = true;
  if (!mOptions.quiet)
    std::printf("view: %s; %ux%u; radius %.3g cells; smoothing %s%s\n", mDeviceName.c_str(), size.x, size.y,
                settings.radius, surface.smoothing.name.c_str(),
                mFallbackReason.empty() ? "" : (" (CPU pipeline: " + mFallbackReason + ")").c_str());
}

void ViewerApp::onKey(const std::string& name) {
  if (!mNavigation || !mTimeline) return;
  const double flyStep = mNavigation->distance() * 0.05;
  if (mFlyMode && isFlyKey(name)) {
    const char k = name[0];
    mNavigation->fly(k == 'w' ? flyStep : k == 's' ? -flyStep : 0, k == 'd' ? flyStep : k == 'a' ? -flyStep : 0,
                     k == 'e' ? flyStep : k == 'q' ? -flyStep : 0);
    return;
  }
  if (name == "space") {
    mTimeline->togglePlaying();
  } else if (name == "right") {
    mTimeline->stepForward();
  } else if (name == "left") {
    mTimeline->stepBackward();
  } else if (name == "home") {
    mTimeline->home();
  } else if (name == "end") {
    mTimeline->end();
  } else if (name == "f") {
    const glm::uvec2 size = renderSize();
    mNavigation->frame(framedBounds(*mSource, mTimeline->frame(), mTimeline->frame()).box, double(size.x) / size.y);
  } else if (name == "r") {
    mNavigation->reset();
  } else if (name == "tab") {
    mFlyMode = !mFlyMode;
  } else if (name == "c") {
    const std::filesystem::path path = mOptions.saveCamera.empty() ? "view_camera.json" : mOptions.saveCamera;
    saveCamera(path, mNavigation->camera());
    mMessage = "camera saved to " + path.string();
    if (!mOptions.quiet) std::printf("view: %s\n", mMessage.c_str());
  } else if (name == "s") {
    std::filesystem::path path;
    do {
      path = "view_frame" + std::to_string(mTimeline->frame()) + "_" + std::to_string(++mScreenshots) + ".png";
    } while (std::filesystem::exists(path));
    saveScreenshot(path);
  } else if (name == "escape") {
    glfwSetWindowShouldClose(mWindow->handle(), GLFW_TRUE);
  }
}

void ViewerApp::onDrag(int button, double dx, double dy) {
  if (!mNavigation) return;
  const double height = double(std::max(1, mWindow->height()));
  const bool shift = glfwGetKey(mWindow->handle(), GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS;
  if (button == 0 && !shift)
    mNavigation->orbit(dx, dy, height);
  else
    mNavigation->pan(dx, dy, height);
}

void ViewerApp::onScroll(double steps) {
  if (mNavigation) mNavigation->zoom(steps);
}

void ViewerApp::keyCallback(GLFWwindow* window, int key, int, int action, int) {
  if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
  if (ImGui::GetIO().WantCaptureKeyboard) return;
  ViewerApp& app = *appOf(window);
  const std::string name = keyName(key);
  // Fly keys held down move every frame (step()); a press alone would move once more.
  if (app.mFlyMode && isFlyKey(name)) return;
  if (!name.empty()) app.onKey(name);
}

void ViewerApp::cursorCallback(GLFWwindow* window, double x, double y) {
  ViewerApp& app = *appOf(window);
  const double dx = x - app.mCursorX, dy = y - app.mCursorY;
  app.mCursorX = x;
  app.mCursorY = y;
  for (int b = 0; b < 3; ++b)
    if (app.mDragging[b]) {
      app.onDrag(b, dx, dy);
      break;
    }
}

void ViewerApp::buttonCallback(GLFWwindow* window, int button, int action, int) {
  ViewerApp& app = *appOf(window);
  if (button < 0 || button > 2) return;
  if (action == GLFW_PRESS && ImGui::GetIO().WantCaptureMouse) return;
  app.mDragging[button] = action == GLFW_PRESS;
  glfwGetCursorPos(window, &app.mCursorX, &app.mCursorY);
}

void ViewerApp::scrollCallback(GLFWwindow* window, double, double dy) {
  if (ImGui::GetIO().WantCaptureMouse) return;
  appOf(window)->onScroll(dy);
}

void ViewerApp::runScript() {
  if (mScriptNext >= mScript.size()) return;
  const ScriptEvent& e = mScript[mScriptNext];
  if (mScriptNext == 0 && mScriptLast == Clock::time_point{}) mScriptLast = Clock::now();
  if (msBetween(mScriptLast, Clock::now()) < e.delaySeconds * 1000.0) return;
  if (e.kind == ScriptEvent::Kind::Converge && (!mPipeline || mRestart || !mPipeline->finished())) return;
  // Events about the view wait for the first frame; quit does not.
  if (e.kind != ScriptEvent::Kind::Converge && e.kind != ScriptEvent::Kind::Quit && !mNavigation) return;
  switch (e.kind) {
    case ScriptEvent::Kind::Key: onKey(e.key); break;
    case ScriptEvent::Kind::Drag: onDrag(e.button, e.delta.x, e.delta.y); break;
    case ScriptEvent::Kind::Scroll: onScroll(e.delta.y); break;
    case ScriptEvent::Kind::Frame:
      if (!mSource->hasFrame(e.frame))
        throw FileError(mOptions.script, "line " + std::to_string(e.line) + ": the store has no frame " +
                                             std::to_string(e.frame));
      mTimeline->seek(e.frame);
      break;
    case ScriptEvent::Kind::Converge: break;
    case ScriptEvent::Kind::Screenshot: saveScreenshot(e.path); break;
    case ScriptEvent::Kind::SaveCamera:
      saveCamera(e.path, mNavigation->camera());
      mMessage = "camera saved to " + e.path.string();
      break;
    case ScriptEvent::Kind::Quit: glfwSetWindowShouldClose(mWindow->handle(), GLFW_TRUE); break;
  }
  mScriptLast = Clock::now();
  ++mScriptNext;
}

void ViewerApp::saveScreenshot(const std::filesystem::path& path) {
  if (!mPipeline) return;
  const FrameOutput& out = mPipeline->readOutput();
  writeImage(path, out.image);
  mMessage = "saved " + path.string() + (mPipeline->finished() ? "" : " (not converged yet)");
  if (!mOptions.quiet) std::printf("view: %s\n", mMessage.c_str());
}

void ViewerApp::step(double dtSeconds) {
  if ((mConversion || !mSource) && !pollSource()) return;  // a store being filled: its new frames
  buildPipeline();
  if (mFlyMode && !ImGui::GetIO().WantCaptureKeyboard) {
    const double speed = mNavigation->distance() * dtSeconds;  // the distance to the target in a second
    auto held = [&](int key) { return glfwGetKey(mWindow->handle(), key) == GLFW_PRESS ? 1.0 : 0.0; };
    const double f = held(GLFW_KEY_W) - held(GLFW_KEY_S), r = held(GLFW_KEY_D) - held(GLFW_KEY_A),
                 u = held(GLFW_KEY_E) - held(GLFW_KEY_Q);
    if (f != 0 || r != 0 || u != 0) mNavigation->fly(f * speed, r * speed, u * speed);
  }
  // Playing shows every frame converged, at most at the play speed.
  if (mTimeline->playing() && mPipeline->finished() && !mRestart) mTimeline->update(dtSeconds);
  const Camera& camera = mNavigation->camera();
  if (mRestart || !(camera == mBegunCamera) || mTimeline->frame() != mBegunFrame) {
    mPipeline->begin(mTimeline->frame(), camera, mTimeline->direction());
    mBegunCamera = camera;
    mBegunFrame = mTimeline->frame();
    mRestart = false;
    mFrameStartedMs = msBetween(mStart, Clock::now());
    mProgress = {};  // the new frame's statistics start at zero
  }
  mUploadedThisFrame = 0;
  if (!mPipeline->finished()) {
    const std::uint64_t uploadedBefore = mProgress.stats.bricksUploaded;
    mProgress = mPipeline->advance(mOptions.budgetMs);
    mUploadedThisFrame = mProgress.stats.bricksUploaded - uploadedBefore;
    if (mProgress.changed) {
      mLastStages = mProgress.stages;
      const glm::uvec2 size = mBuiltSize;
      if (const gl::Buffer* buffer = mPipeline->displayBuffer())
        mTexture->copyFrom(*buffer, size.x, size.y);
      else
        mTexture->upload(mPipeline->downloadDisplay(), size.x, size.y);
    }
    if (mPipeline->finished()) {
      ++mConverged;
      mConvergeMs = msBetween(mStart, Clock::now()) - mFrameStartedMs;
      mLongestConvergeMs = std::max(mLongestConvergeMs, mConvergeMs);
    }
  }
  // Counting the cached frames walks the whole CPU cache under its lock: twice a second is enough.
  if (msBetween(mFramesCachedAt, Clock::now()) > 500) {
    mFramesCached = mPipeline->renderer().streamer().cache().frames().size();
    mFramesCachedAt = Clock::now();
  }
  if (!mOptions.screenshot.empty() && mPipeline->finished()) {
    saveScreenshot(mOptions.screenshot);
    if (!mProgress.stats.converged) mExitCode = kExitNotConverged;
    glfwSetWindowShouldClose(mWindow->handle(), GLFW_TRUE);
  }
}

int ViewerApp::run() {
  auto last = Clock::now();
  while (!glfwWindowShouldClose(mWindow->handle())) {
    // Sleep until input when nothing is left to refine or play (a scripted event, a converting
    // store's next frame, or the first frame of one, wake it sooner); while rays wait for bricks,
    // look again soon. Either way the cores go to the conversion, not to redrawing the same image.
    double wait = 0;
    if (!mPipeline) {
      wait = 0.05;
    } else if (!mRestart && !mTimeline->playing()) {
      if (mPipeline->finished())
        wait = mScriptNext < mScript.size() ? 0.01 : mConversion ? 0.1 : 0.25;
      else if (!mProgress.changed)
        wait = 0.005;
    }
    if (wait > 0)
      glfwWaitEventsTimeout(wait);
    else
      glfwPollEvents();
    // A UI frame is the work after the wait: what input waits for.
    const auto frameStart = Clock::now();
    const double dt = std::min(msBetween(last, frameStart) / 1000.0, 0.25);
    last = frameStart;
    runScript();
    step(dt);

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    const ImVec2 display = ImGui::GetIO().DisplaySize;
    if (mPipeline)
      ImGui::GetBackgroundDrawList()->AddImage(reinterpret_cast<ImTextureID>(std::intptr_t(mTexture->id())),
                                               ImVec2(0, 0), display);
    drawPanel();
    ImGui::Render();
    glViewport(0, 0, mWindow->width(), mWindow->height());
    glClearColor(0.1f, 0.1f, 0.12f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    glfwSwapBuffers(mWindow->handle());
    const double frameMs = msBetween(frameStart, Clock::now());
    mHistory.add(msBetween(mStart, Clock::now()) / 1000.0, frameMs, mUploadedThisFrame);
    // Opening (the window, the store, the default camera's bounds, the pipeline) is not a
    // frame of interaction: the longest frame counts from the first image shown.
    if (mStartupMs >= 0)
      mLongestUiMs = std::max(mLongestUiMs, frameMs);
    else if (mProgress.changed)
      mStartupMs = msBetween(mStart, Clock::now());
  }
  writeStats();
  return mExitCode;
}

void ViewerApp::writeStats() const {
  if (mOptions.statsFile.empty()) return;
  nlohmann::json j;
  j["frames_shown"] = mHistory.frames();
  j["longest_ui_frame_ms"] = mLongestUiMs;
  j["startup_ms"] = mStartupMs;
  j["longest_converge_ms"] = mLongestConvergeMs;
  j["converged_frames"] = mConverged;
  j["budget_ms"] = mOptions.budgetMs;
  j["device"] = mDeviceName;
  j["frame"] = mTimeline ? mTimeline->frame() : 0;
  j["frames"] = mTimeline ? mTimeline->frames() : std::vector<int>{};
  if (mNavigation) {
    const Camera& c = mNavigation->camera();
    j["camera"] = {{"eye", {c.eye.x, c.eye.y, c.eye.z}},
                   {"target", {c.target.x, c.target.y, c.target.z}},
                   {"up", {c.up.x, c.up.y, c.up.z}},
                   {"fov", c.fovYDegrees}};
  }
  writeTextAtomically(mOptions.statsFile, j.dump(2) + "\n");
}

}  // namespace flipscope::viewer
