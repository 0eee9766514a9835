// StdioBuffer: a stdio stream's buffer of a chosen size. glibc's setvbuf(file, nullptr, _IOFBF,
// size) ignores `size` and buffers st_blksize bytes (4 KiB on most filesystems), so a larger
// buffer must be the caller's, alive until the stream is closed.
#pragma once

#include <cstddef>
#include <cstdio>
#include <memory>

#include "core/Error.h"

namespace flipscope {

class StdioBuffer {
 public:
  /// Allocates the buffer (before the stream is opened: an allocation that fails then leaves
  /// nothing open).
  explicit StdioBuffer(std::size_t bytes) : mBytes(std::make_unique_for_overwrite<char[]>(bytes)), mSize(bytes) {}

  /// Makes `file` (just opened: nothing read or written yet) fully buffered by this object's
  /// bytes; where setvbuf refuses, the stream keeps its own buffer. Once only. Close the stream
  /// before this object goes.
  void attach(std::FILE* file) {
    FLIPSCOPE_CHECK(!mAttached, "a stdio buffer serves one stream");
    mAttached = true;
    std::setvbuf(file, mBytes.get(), _IOFBF, mSize);
  }

 private:
  std::unique_ptr<char[]> mBytes;
  std::size_t mSize;
  bool mAttached = false;
};

}  // namespace flipscope
