// InputFile: a read-only file read through a large buffer, for the streaming particle readers
// (raw, PLY), or bytes in memory read the same way (fuzz targets, tests). Tracks the byte
// offset for error messages. Not thread safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <span>
#include <string>
#include <utility>

namespace flipscope {

class InputFile {
 public:
  /// Opens `path` for reading. Throws FileError when it is missing or unreadable.
  explicit InputFile(std::filesystem::path path);
  /// Reads `bytes` (which must outlive this object) as if they were the file `name`.
  InputFile(std::filesystem::path name, std::span<const std::byte> bytes);
  ~InputFile();
  InputFile(InputFile&& other) noexcept;
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  const std::filesystem::path& path() const { return mPath; }
  /// File size in bytes at open time.
  std::uint64_t size() const { return mSize; }
  /// Byte offset of the next read.
  std::uint64_t offset() const { return mOffset; }
  void seek(std::uint64_t offset);
  /// Reads up to `bytes` bytes; returns how many were read (fewer only at the end of the file).
  /// Throws FileError on an I/O error.
  std::size_t read(void* data, std::size_t bytes);
  /// Reads one line without its "\n" (and "\r"). Returns false at the end of the file.
  /// Throws FileError for a line longer than `maxLength` bytes.
  bool readLine(std::string& line, std::size_t maxLength);
  /// Whether the line readLine() returned last ended with "\n" (false: the file ended inside it).
  bool lineTerminated() const { return mLineTerminated; }

 private:
  int get();  ///< next byte, or EOF

  std::filesystem::path mPath;
  std::FILE* mFile = nullptr;  ///< null when reading from memory
  std::span<const std::byte> mMemory;
  std::uint64_t mSize = 0;
  std::uint64_t mOffset = 0;
  bool mLineTerminated = false;
};

}  // namespace flipscope
