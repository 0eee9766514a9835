// flipscope devices: the render devices this machine offers, for checking a farm node or a
// workstation before a job. Lists the EGL device platform's devices, the OpenGL context that
// `--device gpu` gets (its display and renderer, and why any display before it was passed
// over), and the device `--device auto` picks, with its reason when that is the CPU.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>
#include <string>

#include "gl/EglContext.h"
#include "raycast/GpuRaycaster.h"
#include "tools/Commands.h"

namespace flipscope::tools {
namespace {

void runDevices() {
  std::printf("EGL devices:\n");
  for (const std::string& line : gl::listEglDevices()) std::printf("  %s\n", line.c_str());
  try {
    const gl::EglContext context = gl::EglContext::create();
    std::printf("--device gpu: OpenGL (%s): %s\n", context.platform().c_str(), context.renderer().c_str());
    for (const std::string& line : context.passedOver()) std::printf("  passed over: %s\n", line.c_str());
  } catch (const gl::Unavailable& e) {
    std::printf("--device gpu: unavailable: %s\n", e.what());
  }
  std::string reason;
  const std::unique_ptr<RaycastDevice> device = createRaycastDevice(DeviceChoice::Auto, &reason);
  std::printf("--device auto: %s%s\n", device->name().c_str(), reason.empty() ? "" : (", because " + reason).c_str());
}

}  // namespace

void addDevicesCommand(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("devices", "List the render devices: EGL devices, OpenGL, and what auto picks");
  cmd->callback(runDevices);
}

}  // namespace flipscope::tools
