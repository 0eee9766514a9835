// A private X server for the viewer's window tests: Xvfb on a free display number (it picks one
// and reports it through -displayfd), DISPLAY set for the flipscope runs of the test, stopped
// with the object. Without Xvfb the tests skip, unless FLIPSCOPE_REQUIRE_GL is set (CI).
#pragma once

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

extern char** environ;

namespace flipscope::testing {

class XvfbDisplay {
 public:
  XvfbDisplay() {
    int fds[2];
    if (pipe(fds) != 0) return;
    const std::string fd = std::to_string(fds[1]);
    const char* argv[] = {"Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "1280x1024x24", "-nolisten", "tcp", nullptr};
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addclose(&actions, fds[0]);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", 1 /* O_WRONLY */, 0);
    const int error =
        posix_spawnp(&mPid, "Xvfb", &actions, nullptr, const_cast<char* const*>(argv), environ);
    posix_spawn_file_actions_destroy(&actions);
    close(fds[1]);
    if (error != 0) {
      mPid = -1;
      close(fds[0]);
      return;
    }
    std::string number;
    char c;
    while (read(fds[0], &c, 1) == 1 && c != '\n') number += c;
    close(fds[0]);
    if (number.empty()) return;
    mDisplay = ":" + number;
    setenv("DISPLAY", mDisplay.c_str(), 1);
  }
  ~XvfbDisplay() {
    if (mPid > 0) {
      kill(mPid, SIGTERM);
      int status = 0;
      waitpid(mPid, &status, 0);
    }
  }
  XvfbDisplay(const XvfbDisplay&) = delete;
  XvfbDisplay& operator=(const XvfbDisplay&) = delete;

  /// Empty when Xvfb could not be started.
  const std::string& display() const { return mDisplay; }

 private:
  pid_t mPid = -1;
  std::string mDisplay;
};

}  // namespace flipscope::testing

/// Starts a private X server for this test, or skips it (fails it under FLIPSCOPE_REQUIRE_GL).
#define FLIPSCOPE_START_XVFB(name)                                                               \
  ::flipscope::testing::XvfbDisplay name;                                                        \
  if (name.display().empty()) {                                                                  \
    if (std::getenv("FLIPSCOPE_REQUIRE_GL")) FAIL() << "FLIPSCOPE_REQUIRE_GL is set, but Xvfb does not start"; \
    GTEST_SKIP() << "no Xvfb (Debian: xvfb)";                                                    \
  }
