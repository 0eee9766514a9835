#include "gl/EglContext.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <string_view>
#include <utility>
#include <vector>

namespace flipscope::gl {

namespace {

bool hasExtension(const char* extensions, std::string_view name) {
  if (!extensions) return false;
  std::string_view all(extensions);
  for (std::size_t start = 0; start < all.size();) {
    std::size_t end = all.find(' ', start);
    if (end == std::string_view::npos) end = all.size();
    if (all.substr(start, end - start) == name) return true;
    start = end + 1;
  }
  return false;
}

std::string lastEglError() { return eglErrorName(eglGetError()); }

// EGL displays are per-process singletons and eglTerminate ends every context on them, so two
// live EglContexts on one display must not terminate it twice: count the users.
std::mutex gDisplayMutex;
std::map<EGLDisplay, int> gDisplayUsers;

bool acquireDisplay(EGLDisplay display) {
  std::lock_guard lock(gDisplayMutex);
  EGLint major = 0, minor = 0;
  if (!eglInitialize(display, &major, &minor)) return false;
  ++gDisplayUsers[display];
  return true;
}

void releaseDisplay(EGLDisplay display) {
  std::lock_guard lock(gDisplayMutex);
  auto it = gDisplayUsers.find(display);
  if (it == gDisplayUsers.end()) return;
  if (--it->second == 0) {
    gDisplayUsers.erase(it);
    eglTerminate(display);
  }
}

#if FLIPSCOPE_GL_DEBUG
// Errors and warnings to stderr; compiler messages are left to Program::compute's exception.
void GLAPIENTRY printDebugMessage(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei length,
                                  const GLchar* message, const void* /*user*/) {
  if (severity == GL_DEBUG_SEVERITY_NOTIFICATION || source == GL_DEBUG_SOURCE_SHADER_COMPILER) return;
  const char* kind = type == GL_DEBUG_TYPE_ERROR ? "error" : "warning";
  std::fprintf(stderr, "flipscope: GL %s %u: %.*s\n", kind, id, int(length), message);
}
#endif

struct Candidate {
  EGLDisplay display;
  std::string platform;  // "device", "surfaceless" or "default"
  std::string label;     // for error messages
};

struct DeviceCandidate {
  Candidate candidate;
  int rank;  // 3 NVIDIA, 2 DRM node, 1 other, 0 software
};

std::vector<DeviceCandidate> enumerateDevices(const char* clientExtensions, std::vector<std::string>& failures) {
  std::vector<DeviceCandidate> devices;
  if (!hasExtension(clientExtensions, "EGL_EXT_platform_device") ||
      !(hasExtension(clientExtensions, "EGL_EXT_device_enumeration") ||
        hasExtension(clientExtensions, "EGL_EXT_device_base"))) {
    failures.push_back("device platform: EGL_EXT_platform_device or EGL_EXT_device_enumeration missing");
    return devices;
  }
  EGLint count = 0;
  if (!eglQueryDevicesEXT(0, nullptr, &count) || count <= 0) {
    failures.push_back("device platform: eglQueryDevicesEXT found no device (" + lastEglError() + ")");
    return devices;
  }
  std::vector<EGLDeviceEXT> handles(static_cast<std::size_t>(count));
  if (!eglQueryDevicesEXT(count, handles.data(), &count)) {
    failures.push_back("device platform: eglQueryDevicesEXT failed: " + lastEglError());
    return devices;
  }
  handles.resize(std::size_t(std::max(count, 0)));
  for (std::size_t i = 0; i < handles.size(); ++i) {
    const char* extensions = eglQueryDeviceStringEXT(handles[i], EGL_EXTENSIONS);
    const char* drmFile = hasExtension(extensions, "EGL_EXT_device_drm")
                              ? eglQueryDeviceStringEXT(handles[i], EGL_DRM_DEVICE_FILE_EXT)
                              : nullptr;
    int rank = 1;
    std::string what = "device " + std::to_string(i);
    if (hasExtension(extensions, "EGL_NV_device_cuda")) {
      rank = 3;
      what += " (NVIDIA";
    } else if (drmFile) {
      rank = 2;
      what += " (DRM";
    } else if (hasExtension(extensions, "EGL_MESA_device_software")) {
      rank = 0;
      what += " (software";
    } else {
      what += " (unknown kind";
    }
    if (drmFile) what += std::string(" ") + drmFile;
    what += ")";
    EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, handles[i], nullptr);
    if (display == EGL_NO_DISPLAY) {
      failures.push_back("device platform, " + what + ": eglGetPlatformDisplayEXT failed: " + lastEglError());
      continue;
    }
    devices.push_back({{display, "device", "device platform, " + what}, rank});
  }
  std::stable_sort(devices.begin(), devices.end(),
                   [](const DeviceCandidate& a, const DeviceCandidate& b) { return a.rank > b.rank; });
  return devices;
}

}  // namespace

std::string eglErrorName(EGLint error) {
  switch (error) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE:
      return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP:
      return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW:
      return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE:
      return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST:
      return "EGL_CONTEXT_LOST";
    case EGL_BAD_DEVICE_EXT:
      return "EGL_BAD_DEVICE_EXT";
    default: {
      std::ostringstream os;
      os << "EGL error 0x" << std::hex << error;
      return os.str();
    }
  }
}

EglContext EglContext::create() {
  if (!epoxy_has_egl()) throw Unavailable("no EGL: libEGL.so.1 could not be loaded");
  std::vector<std::string> failures;
  // Client extensions (EGL_EXT_client_extensions); null without them, which is not an error.
  const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!clientExtensions) eglGetError();

  std::vector<Candidate> candidates;
  std::vector<Candidate> softwareDevices;
  for (DeviceCandidate& device : enumerateDevices(clientExtensions, failures))
    (device.rank > 0 ? candidates : softwareDevices).push_back(std::move(device.candidate));
  if (hasExtension(clientExtensions, "EGL_MESA_platform_surfaceless") &&
      hasExtension(clientExtensions, "EGL_EXT_platform_base")) {
    EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (display != EGL_NO_DISPLAY)
      candidates.push_back({display, "surfaceless", "surfaceless platform"});
    else
      failures.push_back("surfaceless platform: eglGetPlatformDisplayEXT failed: " + lastEglError());
  } else {
    failures.push_back("surfaceless platform: EGL_MESA_platform_surfaceless missing");
  }
  if (EGLDisplay display = eglGetDisplay(EGL_DEFAULT_DISPLAY); display != EGL_NO_DISPLAY)
    candidates.push_back({display, "default", "default display"});
  else
    failures.push_back("default display: eglGetDisplay failed: " + lastEglError());
  for (Candidate& device : softwareDevices) candidates.push_back(std::move(device));

  for (const Candidate& candidate : candidates) {
    const auto fail = [&](const std::string& step) { failures.push_back(candidate.label + ": " + step); };
    if (!acquireDisplay(candidate.display)) {
      fail("eglInitialize failed: " + lastEglError());
      continue;
    }
    EglContext result;
    result.mDisplay = candidate.display;  // from here on, `result` releases the display
    result.mPlatform = candidate.platform;
    const char* extensions = eglQueryString(candidate.display, EGL_EXTENSIONS);
    if (!hasExtension(extensions, "EGL_KHR_create_context")) {
      fail("EGL_KHR_create_context missing");
      continue;
    }
    if (!hasExtension(extensions, "EGL_KHR_surfaceless_context")) {
      fail("EGL_KHR_surfaceless_context missing");
      continue;
    }
    if (!eglBindAPI(EGL_OPENGL_API)) {
      fail("eglBindAPI(EGL_OPENGL_API) failed: " + lastEglError());
      continue;
    }
    EGLConfig config = EGL_NO_CONFIG_KHR;
    if (!hasExtension(extensions, "EGL_KHR_no_config_context") &&
        !hasExtension(extensions, "EGL_MESA_configless_context")) {
      const EGLint configAttributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};
      EGLint configs = 0;
      if (!eglChooseConfig(candidate.display, configAttributes, &config, 1, &configs) || configs < 1) {
        fail("eglChooseConfig found no OpenGL config (" + lastEglError() + ")");
        continue;
      }
    }
    const EGLint contextAttributes[] = {
      EGL_CONTEXT_MAJOR_VERSION_KHR,
      4,
      EGL_CONTEXT_MINOR_VERSION_KHR,
      5,
      EGL_CONTEXT_OPENGL_PROFILE_MASK_KHR,
      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT_KHR,
#if FLIPSCOPE_GL_DEBUG
      EGL_CONTEXT_FLAGS_KHR,
      EGL_CONTEXT_OPENGL_DEBUG_BIT_KHR,
#endif
      EGL_NONE
    };
    result.mContext = eglCreateContext(candidate.display, config, EGL_NO_CONTEXT, contextAttributes);
    if (result.mContext == EGL_NO_CONTEXT) {
      fail("eglCreateContext (OpenGL 4.5 core) failed: " + lastEglError());
      continue;
    }
    if (!eglMakeCurrent(candidate.display, EGL_NO_SURFACE, EGL_NO_SURFACE, result.mContext)) {
      fail("eglMakeCurrent without a surface failed: " + lastEglError());
      continue;
    }
    if (epoxy_gl_version() < 45) {
      fail("context reports OpenGL " + std::to_string(epoxy_gl_version()) + ", need 45");
      continue;
    }
#if FLIPSCOPE_GL_DEBUG
    glEnable(GL_DEBUG_OUTPUT);
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageCallback(printDebugMessage, nullptr);
#endif
    result.mPassedOver = std::move(failures);
    return result;
  }
  std::string reason = "no EGL display gives an OpenGL 4.5 core context";
  for (const std::string& failure : failures) reason += "\n  " + failure;
  throw Unavailable(reason);
}

std::vector<std::string> listEglDevices() {
  if (!epoxy_has_egl()) return {"no EGL: libEGL.so.1 could not be loaded"};
  const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!clientExtensions) eglGetError();
  std::vector<std::string> failures, lines;
  for (const DeviceCandidate& device : enumerateDevices(clientExtensions, failures))
    lines.push_back(device.candidate.label);
  lines.insert(lines.end(), failures.begin(), failures.end());
  return lines;
}

EglContext::~EglContext() { reset(); }

EglContext::EglContext(EglContext&& other) noexcept
    : mDisplay(std::exchange(other.mDisplay, EGL_NO_DISPLAY)),
      mContext(std::exchange(other.mContext, EGL_NO_CONTEXT)),
      mPlatform(std::move(other.mPlatform)),
      mPassedOver(std::move(other.mPassedOver)) {}

EglContext& EglContext::operator=(EglContext&& other) noexcept {
  if (this != &other) {
    reset();
    mDisplay = std::exchange(other.mDisplay, EGL_NO_DISPLAY);
    mContext = std::exchange(other.mContext, EGL_NO_CONTEXT);
    mPlatform = std::move(other.mPlatform);
    mPassedOver = std::move(other.mPassedOver);
  }
  return *this;
}

void EglContext::reset() noexcept {
  if (mContext != EGL_NO_CONTEXT) {
    if (eglGetCurrentContext() == mContext) eglMakeCurrent(mDisplay, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(mDisplay, mContext);
    mContext = EGL_NO_CONTEXT;
  }
  if (mDisplay != EGL_NO_DISPLAY) {
    releaseDisplay(mDisplay);
    mDisplay = EGL_NO_DISPLAY;
  }
}

void EglContext::makeCurrent() const {
  if (mContext == EGL_NO_CONTEXT) throw Unavailable("EglContext::makeCurrent: empty context");
  if (!eglMakeCurrent(mDisplay, EGL_NO_SURFACE, EGL_NO_SURFACE, mContext))
    throw Unavailable("EglContext::makeCurrent: eglMakeCurrent failed: " + lastEglError());
}

std::string EglContext::renderer() const {
  if (mContext == EGL_NO_CONTEXT) return "(no context)";
  return currentRenderer();
}

std::string currentRenderer() {
  const auto text = [](GLenum name) {
    const GLubyte* s = glGetString(name);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
  };
  return text(GL_VENDOR) + " / " + text(GL_RENDERER) + " / " + text(GL_VERSION);
}

bool isSoftwareRenderer(const std::string& renderer) {
  return renderer.find("llvmpipe") != std::string::npos || renderer.find("softpipe") != std::string::npos;
}

void requireCurrentGl45(const std::string& what) {
  if (epoxy_gl_version() < 45)
    throw Unavailable(what + ": the current context is OpenGL " + std::to_string(epoxy_gl_version()) + ", need 45");
}

}  // namespace flipscope::gl
