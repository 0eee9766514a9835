// Runs this flipscope binary again as a child process, for the benchmarks that measure a stage
// on its own: its wall time, exit code and peak memory, with its output in a log file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace flipscope::tools {

struct ChildRun {
  int exitCode = -1;            ///< -1: not started, or ended by a signal
  double seconds = 0;           ///< wall time from spawn to exit
  std::uint64_t peakBytes = 0;  ///< the child's peak resident set (wait4's ru_maxrss)
  /// The peak the child printed itself ("peak memory N MiB", as convert does), else 0.
  double reportedPeakMiB = 0;
};

/// Runs `flipscope <arguments>` (this binary, /proc/self/exe), stdout and stderr into `log`,
/// and waits for it.
ChildRun runFlipscopeChild(const std::vector<std::string>& arguments, const std::filesystem::path& log);

/// runFlipscopeChild() for a stage of a benchmark that cannot go on without it: throws
/// InputError naming the stage (`what`), its exit code and `log` when it does not exit with 0.
ChildRun runFlipscopeStage(const std::string& what, const std::vector<std::string>& arguments,
                           const std::filesystem::path& log);

}  // namespace flipscope::tools
