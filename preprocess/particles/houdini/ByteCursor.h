// ByteCursor: reads an InputFile from any offset through a buffer of its own (InputFile::readAt),
// so that several cursors read one file at different places: the Houdini reader keeps one per
// point attribute, since Houdini stores attribute after attribute. Not thread safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "preprocess/particles/InputFile.h"

namespace flipscope::detail::houdini {

class ByteCursor {
 public:
  /// Reads `file` (which must outlive the cursor) from byte 0, `bufferBytes` at a time.
  ByteCursor(InputFile& file, std::size_t bufferBytes) : mFile(&file), mBufferBytes(bufferBytes) {}

  const std::filesystem::path& path() const { return mFile->path(); }
  std::uint64_t fileSize() const { return mFile->size(); }
  /// Byte offset of the next byte.
  std::uint64_t offset() const { return mBufferStart + mPos; }
  std::uint64_t remaining() const { return fileSize() - offset(); }
  bool atEnd() const { return offset() >= fileSize(); }

  /// Moves to `offset` (at most the file size).
  void seek(std::uint64_t offset) {
    if (offset >= mBufferStart && offset <= mBufferStart + mEnd) {
      mPos = std::size_t(offset - mBufferStart);
      return;
    }
    mBufferStart = offset;
    mPos = mEnd = 0;
  }

  /// Makes `n` bytes from the offset available at data(); false when the file ends first.
  bool ensure(std::size_t n) {
    if (mEnd - mPos >= n) return true;
    refill(n);
    return mEnd - mPos >= n;
  }
  /// The bytes from the offset that ensure() made available (available() of them).
  const std::byte* data() const { return mBuffer.data() + mPos; }
  std::size_t available() const { return mEnd - mPos; }
  void advance(std::size_t n) { mPos += n; }

  /// Skips `n` bytes; false (offset unchanged) when fewer are left.
  bool skip(std::uint64_t n) {
    if (n > remaining()) return false;
    seek(offset() + n);
    return true;
  }

  /// Copies `n` bytes (any number) to `out`; false when the file ends first. Large reads go
  /// from the file straight to `out`.
  bool read(void* out, std::size_t n) {
    auto* dst = static_cast<std::byte*>(out);
    const std::size_t buffered = std::min(n, available());
    std::memcpy(dst, data(), buffered);
    advance(buffered);
    dst += buffered;
    n -= buffered;
    if (n >= mBufferBytes) {
      if (n > remaining()) return false;
      const std::uint64_t at = offset();
      std::size_t done = 0;
      while (done < n) {
        const std::size_t got = mFile->readAt(at + done, dst + done, n - done);
        if (got == 0) return false;
        done += got;
      }
      seek(at + n);
      return true;
    }
    while (n > 0) {
      if (!ensure(std::min(n, mBufferBytes))) return false;
      const std::size_t k = std::min(n, available());
      std::memcpy(dst, data(), k);
      advance(k);
      dst += k;
      n -= k;
    }
    return true;
  }

 private:
  void refill(std::size_t n) {
    const std::uint64_t at = offset();
    const std::size_t keep = mEnd - mPos;
    if (keep && mPos) std::memmove(mBuffer.data(), mBuffer.data() + mPos, keep);
    mBufferStart = at;
    mPos = 0;
    mEnd = keep;
    // At most what is left of the file: small files need small buffers.
    const std::uint64_t left = fileSize() > at ? fileSize() - at : 0;
    const std::size_t want = std::max(n, std::size_t(std::min<std::uint64_t>(mBufferBytes, left)));
    if (mBuffer.size() < want) mBuffer.resize(want);
    while (mEnd < mBuffer.size() && mBufferStart + mEnd < fileSize()) {
      std::size_t got = mFile->readAt(mBufferStart + mEnd, mBuffer.data() + mEnd, mBuffer.size() - mEnd);
      if (got == 0) break;
      mEnd += got;
    }
  }

  InputFile* mFile;
  std::size_t mBufferBytes;
  std::vector<std::byte> mBuffer;
  std::uint64_t mBufferStart = 0;  ///< file offset of mBuffer[0]
  std::size_t mPos = 0;            ///< next byte in mBuffer
  std::size_t mEnd = 0;            ///< bytes of mBuffer that hold file data
};

}  // namespace flipscope::detail::houdini
