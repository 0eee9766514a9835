// StdioBuffer: a stdio stream's buffer of a chosen size. glibc's setvbuf(file, nullptr, _IOFBF,
// size) ignores `size` and buffers st_blksize bytes (4 KiB on most filesystems), so a larger
// buffer must be the caller's, alive until the stream is closed.
#pragma once

#include <cstddef>
#include <cstdio>
#include <memory>

namespace flipscope {

class StdioBuffer {
 public:
  /// Makes `file` (just opened: nothing read or written yet) fully buffered by `bytes` bytes of
  /// this object's. Close the stream before this object goes.
  void attach(std::FILE* file, std::size_t bytes) {
    mBytes = std::make_unique_for_overwrite<char[]>(bytes);
    std::setvbuf(file, mBytes.get(), _IOFBF, bytes);
  }

 private:
  std::unique_ptr<char[]> mBytes;
};

}  // namespace flipscope
