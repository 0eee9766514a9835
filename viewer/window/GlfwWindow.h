// GlfwWindow: the viewer's window with its OpenGL context (GLFW 3.3), made current on the
// creating thread. Move-only RAII: the window is destroyed, and GLFW terminated, with the
// object; every GL object of the context must be gone before.
#pragma once

#include <string>

struct GLFWwindow;

namespace flipscope::viewer {

class GlfwWindow {
 public:
  /// Opens a `width` x `height` window titled `title`: OpenGL 4.5 core, or with `allowGl33`
  /// OpenGL 3.3 core where 4.5 is refused (enough to show the CPU pipeline's image). Throws
  /// gl::Unavailable naming what failed (no display, no such context).
  GlfwWindow(int width, int height, const std::string& title, bool allowGl33);
  ~GlfwWindow();
  GlfwWindow(const GlfwWindow&) = delete;
  GlfwWindow& operator=(const GlfwWindow&) = delete;

  GLFWwindow* handle() const { return mWindow; }
  /// The framebuffer's size in pixels.
  int width() const;
  int height() const;
  /// The context's OpenGL version as major * 10 + minor (45, 33).
  int glVersion() const { return mGlVersion; }

 private:
  GLFWwindow* mWindow = nullptr;
  int mGlVersion = 0;
};

}  // namespace flipscope::viewer
