// AtomicFile: write a file under a temporary name, then fsync and rename it into place, so a
// reader never sees a half-written file: after a crash the destination holds either the old
// content or the new, complete one. An AtomicFile destroyed without commit() removes its
// temporary file. Not thread safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <span>
#include <vector>

namespace flipscope {

class AtomicFile {
 public:
  /// Creates `<dir>/.<name>.tmp-<pid>-<n>` beside `destination`. Throws FileError.
  explicit AtomicFile(std::filesystem::path destination);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  void write(const void* data, std::size_t bytes);
  void write(std::span<const std::byte> bytes) { write(bytes.data(), bytes.size()); }
  /// Overwrites `bytes` bytes at `offset` (already written: offset + bytes <= offset()), e.g. a
  /// header field known only at the end; later writes append again.
  void writeAt(std::uint64_t offset, const void* data, std::size_t bytes);
  /// Bytes written so far.
  std::uint64_t offset() const { return mOffset; }
  /// Flushes, fsyncs, renames over the destination and fsyncs the directory. Throws FileError.
  void commit();

  const std::filesystem::path& destination() const { return mDestination; }
  const std::filesystem::path& temporaryPath() const { return mTemporary; }

 private:
  std::filesystem::path mDestination;
  std::filesystem::path mTemporary;
  std::FILE* mFile = nullptr;
  std::uint64_t mOffset = 0;
};

/// Writes `bytes` to `destination` atomically.
void writeFileAtomically(const std::filesystem::path& destination, std::span<const std::byte> bytes);

/// Reads a whole file. Throws FileError when it cannot be opened or read.
std::vector<std::byte> readFile(const std::filesystem::path& path);

/// fsyncs a directory so that a rename inside it is durable.
void syncDirectory(const std::filesystem::path& dir);

}  // namespace flipscope
