// CacheConversion: `flipscope view` on particle files (not a store) converts them into a cache
// store in the background, and the viewer shows the frames as they are listed. The convert runs
// as a child process (`flipscope convert INPUTS -o CACHE`), so closing the window stops it
// cleanly: SIGTERM, which convert answers by removing its temporaries (see README,
// "Reliability"), and the store keeps the frames it had committed.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

namespace flipscope::viewer {

/// The cache store for `inputs`: `cacheDir` when given, else beside the first input, named after
/// it without its frame number pattern and extension ("fluid_####.vdb" -> "fluid.store").
std::filesystem::path cacheStorePath(const std::vector<std::string>& inputs, const std::filesystem::path& cacheDir);

class CacheConversion {
 public:
  /// Starts `program convert INPUTS... -o STORE extraArgs...`, its output going to
  /// STORE/../<store name>.convert.log. Throws InputError when it cannot be started.
  CacheConversion(const std::filesystem::path& program, const std::vector<std::string>& inputs,
                  const std::filesystem::path& store, const std::vector<std::string>& extraArgs = {});
  /// Stops a convert still running (SIGTERM, then waits for it).
  ~CacheConversion();
  CacheConversion(const CacheConversion&) = delete;
  CacheConversion& operator=(const CacheConversion&) = delete;

  /// Whether the convert is still running (reaps it when it has ended). Never blocks.
  bool running();
  /// Its exit code once ended (-1 while running; 128 + n when killed by signal n).
  int exitCode() const { return mExitCode; }
  /// The last non-empty line the convert printed (its progress or its error).
  std::string lastLine() const;
  const std::filesystem::path& logPath() const { return mLog; }
  const std::filesystem::path& store() const { return mStore; }

 private:
  std::filesystem::path mStore;
  std::filesystem::path mLog;
  pid_t mPid = -1;
  int mExitCode = -1;
};

}  // namespace flipscope::viewer
