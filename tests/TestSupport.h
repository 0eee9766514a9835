// Helpers every test suite shares: scratch directories, running the flipscope binary, and the
// counts the sanitizer runs lower through the environment.
#pragma once

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace flipscope::testing {

/// The positive count the environment variable `name` holds, else `usual` (unset, zero,
/// negative or not a number). tests/run-asan.sh lowers a few repetitions this way.
inline long positiveCountFromEnvironment(const char* name, long usual) {
  const char* text = std::getenv(name);
  const long asked = text ? std::atol(text) : 0;
  return asked > 0 ? asked : usual;
}

/// Drops `path`'s pages from the page cache (written back first), as a file read cold from
/// disk. Whether they left it: not on tmpfs, whose pages are the file. Asked with mincore() over
/// a mapping never touched.
inline bool dropFromPageCache(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  ::fdatasync(fd);
  ::posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED);
  const std::size_t size = std::filesystem::file_size(path), page = 4096, pages = (size + page - 1) / page;
  bool dropped = false;
  if (void* map = size ? ::mmap(nullptr, size, PROT_READ, MAP_SHARED, fd, 0) : MAP_FAILED; map != MAP_FAILED) {
    std::vector<unsigned char> flags(pages);
    dropped = ::mincore(map, size, flags.data()) == 0;
    for (unsigned char f : flags) dropped = dropped && !(f & 1);
    ::munmap(map, size);
  }
  ::close(fd);
  return dropped;
}

/// A fresh directory under the system temporary directory, removed with its content.
class TempDir {
 public:
  explicit TempDir(const std::string& tag) {
    static int counter = 0;
    mPath = std::filesystem::temp_directory_path() /
            ("flipscope-" + tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    std::filesystem::remove_all(mPath);
    std::filesystem::create_directories(mPath);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(mPath, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return mPath; }
  std::filesystem::path operator/(const std::string& name) const { return mPath / name; }

 private:
  std::filesystem::path mPath;
};

/// A file of the Mantaflow sample (FLIPSCOPE_DATA_DIR/mantaflow-dam64): `folder` "data" holds the
/// FLIP particles, "particles" the spray, foam and bubbles.
inline std::filesystem::path mantaflowFile(const std::string& folder, const std::string& name) {
  return std::filesystem::path(FLIPSCOPE_DATA_DIR) / "mantaflow-dam64" / folder / name;
}

struct CommandRun {
  int exitCode;
  std::string output;  ///< stdout and stderr together
};

/// How long one flipscope run of a test may take before `timeout` stops it (exit 124; KILL 10 s
/// later): a hung command fails its test instead of hanging the suite.
inline constexpr int kCommandTimeoutSeconds = 240;

/// Runs `flipscope <arguments>` (a shell fragment) in `directory` (or the current one).
inline CommandRun runFlipscope(const std::string& arguments, const std::filesystem::path& directory = {}) {
  std::string command = "timeout -k 10 " + std::to_string(kCommandTimeoutSeconds) + " '" FLIPSCOPE_BINARY "' " +
                        arguments + " 2>&1";
  if (!directory.empty()) command = "cd '" + directory.string() + "' && " + command;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return {-1, "popen failed"};
  std::string output;
  std::array<char, 4096> buffer;
  while (std::size_t n = std::fread(buffer.data(), 1, buffer.size(), pipe)) output.append(buffer.data(), n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

/// Sets an environment variable, for the commands a test runs, while it lives.
class ScopedEnvironment {
 public:
  ScopedEnvironment(const char* name, const std::string& value) : mName(name) {
    if (const char* old = std::getenv(name)) mOld = old;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnvironment() {
    if (mOld)
      ::setenv(mName, mOld->c_str(), 1);
    else
      ::unsetenv(mName);
  }
  ScopedEnvironment(const ScopedEnvironment&) = delete;
  ScopedEnvironment& operator=(const ScopedEnvironment&) = delete;

 private:
  const char* mName;
  std::optional<std::string> mOld;
};

}  // namespace flipscope::testing
