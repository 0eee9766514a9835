// SpillFile: an unnamed temporary file for a writer's bytes that must follow bytes not yet
// written (e.g. the velocities, stored after every position, while the particles arrive in
// chunks): written as the chunks come, then copied once, in order, into the output. It lives
// in the output's directory (the output's file system, which has room for the output) and has
// no name there (O_TMPFILE, or a name removed as soon as the file is open), so nothing is left
// behind however the process ends. Buffered (1 MiB); not thread safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <span>

#include "core/StdioBuffer.h"

namespace flipscope::detail {

class SpillFile {
 public:
  /// A new, empty spill in `directory` ("" = the current directory). Throws OutputError.
  explicit SpillFile(const std::filesystem::path& directory);
  ~SpillFile();
  SpillFile(const SpillFile&) = delete;
  SpillFile& operator=(const SpillFile&) = delete;

  void write(const void* data, std::size_t bytes);
  std::uint64_t size() const { return mSize; }
  /// Passes the bytes written, in order, to `consume` in pieces of at most 1 MiB. Throws
  /// OutputError when they cannot be read back. Writing may continue afterwards (appends).
  void readBack(const std::function<void(std::span<const std::byte>)>& consume);

 private:
  static constexpr std::size_t kBufferBytes = std::size_t(1) << 20;  ///< written and read back at a time
  std::filesystem::path mDirectory;  ///< for messages
  StdioBuffer mBuffer{kBufferBytes};  ///< mFile's
  std::FILE* mFile = nullptr;
  std::uint64_t mSize = 0;
};

}  // namespace flipscope::detail
