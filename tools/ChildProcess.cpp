#include "tools/ChildProcess.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>

#include "core/Elapsed.h"
#include "core/Error.h"

extern char** environ;

namespace flipscope::tools {

ChildRun runFlipscopeChild(const std::vector<std::string>& arguments, const std::filesystem::path& log) {
  std::vector<std::string> strings{"/proc/self/exe"};
  strings.insert(strings.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (auto& s : strings) argv.push_back(s.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = 0;
  const auto start = std::chrono::steady_clock::now();
  const int spawned = posix_spawn(&pid, "/proc/self/exe", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ChildRun run;
  if (spawned != 0) return run;
  int status = 0;
  rusage usage{};
  while (::wait4(pid, &status, 0, &usage) < 0 && errno == EINTR) {
  }
  run.seconds = secondsSince(start);
  run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.peakBytes = std::uint64_t(usage.ru_maxrss) * 1024;
  if (std::FILE* out = std::fopen(log.c_str(), "r")) {
    char line[512];
    while (std::fgets(line, sizeof line, out)) std::sscanf(line, "peak memory %lf MiB", &run.reportedPeakMiB);
    std::fclose(out);
  }
  return run;
}

ChildRun runFlipscopeStage(const std::string& what, const std::vector<std::string>& arguments,
                           const std::filesystem::path& log) {
  const ChildRun run = runFlipscopeChild(arguments, log);
  if (run.exitCode != 0)
    throw InputError("bench: the " + what + " failed (exit code " + std::to_string(run.exitCode) +
                     "); its output is in " + log.string());
  return run;
}

}  // namespace flipscope::tools
