// EglContext: a headless OpenGL 4.5 core context through EGL (no window, no X server), made
// current on the creating thread with no surface (EGL_KHR_surfaceless_context). GL entry points
// come from libepoxy. Displays are tried in this order:
//  1. "device": the EGL device platform (EGL_EXT_platform_device), hardware devices first
//     (NVIDIA's EGL_NV_device_cuda, then any device with a DRM node);
//  2. "surfaceless": Mesa's EGL_PLATFORM_SURFACELESS_MESA (llvmpipe when there is no GPU);
//  3. "default": eglGetDisplay(EGL_DEFAULT_DISPLAY);
//  4. "device" again with software devices (EGL_MESA_device_software).
// Builds with FLIPSCOPE_GL_DEBUG create a debug context and print GL errors and warnings to
// stderr. Not thread safe; GL objects (gl/Objects.h) must be destroyed while their
// context is alive and current.
#pragma once

#include <epoxy/egl.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace flipscope::gl {

/// No usable EGL display or OpenGL 4.5 context; what() names the step that failed and the EGL
/// error, for every display tried.
class Unavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class EglContext {
 public:
  /// Creates the context and makes it current on this thread. Throws Unavailable.
  static EglContext create();

  EglContext() = default;  ///< empty: no display, no context
  ~EglContext();
  EglContext(EglContext&& other) noexcept;
  EglContext& operator=(EglContext&& other) noexcept;
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  /// Makes this context current on the calling thread (create() already did for its thread).
  void makeCurrent() const;
  /// "GL_VENDOR / GL_RENDERER / GL_VERSION" on one line; the context must be current.
  std::string renderer() const;
  /// Which display was used: "device", "surfaceless" or "default".
  const std::string& platform() const { return mPlatform; }
  /// Why each display tried before this one (and each platform not offered) was passed over.
  const std::vector<std::string>& passedOver() const { return mPassedOver; }
  bool isValid() const { return mContext != EGL_NO_CONTEXT; }
  EGLDisplay display() const { return mDisplay; }
  EGLContext context() const { return mContext; }

 private:
  void reset() noexcept;

  EGLDisplay mDisplay = EGL_NO_DISPLAY;
  EGLContext mContext = EGL_NO_CONTEXT;
  std::string mPlatform;
  std::vector<std::string> mPassedOver;
};

/// The devices of the EGL device platform, in the order create() tries them, one line each
/// ("device platform, device 0 (NVIDIA /dev/dri/card1)"), then why any could not be listed or
/// opened; one line saying why when EGL itself is missing.
std::vector<std::string> listEglDevices();

/// "GL_VENDOR / GL_RENDERER / GL_VERSION" of the context current on this thread (any context:
/// EGL, or a window's GLX); one must be current.
std::string currentRenderer();
/// Whether `renderer` (as currentRenderer() gives it) is OpenGL on the CPU: Mesa's llvmpipe or
/// softpipe.
bool isSoftwareRenderer(const std::string& renderer);
/// Throws Unavailable naming `what` when the context current on this thread (one must be) is
/// below OpenGL 4.5.
void requireCurrentGl45(const std::string& what);

/// Name of an EGL error code ("EGL_BAD_MATCH"), or its hex value when unknown.
std::string eglErrorName(EGLint error);

}  // namespace flipscope::gl
