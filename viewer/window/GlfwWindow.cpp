#include "viewer/window/GlfwWindow.h"

#include <epoxy/gl.h>

#include <GLFW/glfw3.h>

#include "gl/EglContext.h"

namespace flipscope::viewer {

namespace {
std::string gLastGlfwError;
void recordGlfwError(int code, const char* description) {
  gLastGlfwError = "GLFW error " + std::to_string(code) + ": " + (description ? description : "?");
}
}  // namespace

GlfwWindow::GlfwWindow(int width, int height, const std::string& title, bool allowGl33) {
  glfwSetErrorCallback(recordGlfwError);
  if (!glfwInit()) throw gl::Unavailable("view: cannot open a window (" + gLastGlfwError + "); is DISPLAY set?");
  for (int version : {45, 33}) {
    if (version == 33 && !allowGl33) break;
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, version / 10);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, version % 10);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    mWindow = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    if (mWindow) {
      mGlVersion = version;
      break;
    }
  }
  if (!mWindow) {
    const std::string why = gLastGlfwError;
    glfwTerminate();
    throw gl::Unavailable("view: cannot create an OpenGL " + std::string(allowGl33 ? "3.3" : "4.5") +
                          " core window (" + why + ")");
  }
  glfwMakeContextCurrent(mWindow);
  glfwSwapInterval(0);  // frames are paced by the work, not by the display
}

GlfwWindow::~GlfwWindow() {
  if (mWindow) glfwDestroyWindow(mWindow);
  glfwTerminate();
}

int GlfwWindow::width() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(mWindow, &w, &h);
  return w;
}

int GlfwWindow::height() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(mWindow, &w, &h);
  return h;
}

}  // namespace flipscope::viewer
