// InputFile: a read-only byte stream for the particle readers, read through a 1 MiB buffer
// (large reads go around it), from a file, from bytes in memory (fuzz targets, tests) or from a
// decoder layered over another InputFile (gzip, Houdini's scf1 container: see ByteSource).
// Tracks the byte offset for error messages. Not thread safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/UninitializedVector.h"

namespace flipscope {

/// Where an InputFile's bytes come from. Implementations: a file (pread), memory, and the
/// decoders of compressed containers, which present the decoded bytes.
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  /// Total size in bytes (a decoder: of the decoded stream, known when it is constructed).
  virtual std::uint64_t size() const = 0;
  /// Reads up to `bytes` bytes at `offset` into `data`; returns how many were read (fewer only
  /// at the end). Reads that follow each other are the fast path; a decoder may have to
  /// decode again from its start, or from the last index point, to go back. Throws FileError
  /// on I/O errors and on damaged compressed data.
  virtual std::size_t readAt(std::uint64_t offset, void* data, std::size_t bytes) = 0;
  /// Whether readAt costs the same at any offset (a file, memory); a decoder's does not. Such
  /// a source's readAt may be called from two threads at once.
  virtual bool randomAccess() const { return false; }
  /// A hint that the ranges of `bytes` bytes at `offsets` will be read soon: a file asks the
  /// kernel for all of them at once, so that an uncached disk serves them in parallel.
  virtual void willRead(std::span<const std::uint64_t> offsets, std::size_t bytes) { (void)offsets, (void)bytes; }
  /// Reads the `bytes` bytes at `offset` into `data` where all of them can be had without waiting
  /// for a disk (a file's pages in the page cache: one system call, no announcement first) and
  /// returns true; else false, `data` undefined, for readAt to read them. Sources that cannot
  /// tell return false. Thread safe where readAt is.
  virtual bool readIfCached(std::uint64_t offset, void* data, std::size_t bytes) {
    (void)offset, (void)data, (void)bytes;
    return false;
  }
};

class InputFile {
 public:
  /// Opens `path` for reading. Throws FileError when it is missing, a directory or unreadable.
  /// `readOnceAheadBytes`, where not 0: the file is read once, in order, and its large reads go
  /// around the page cache where its pages are not in it, with that many bytes read ahead
  /// (DirectReadAhead.h); else every read goes through the page cache.
  explicit InputFile(std::filesystem::path path, std::size_t readOnceAheadBytes = 0);
  /// Reads `bytes` (which must outlive this object) as if they were the file `name`.
  InputFile(std::filesystem::path name, std::span<const std::byte> bytes);
  /// Reads what `source` presents, named `name` in messages (e.g. "shot.0001.bgeo.sc").
  InputFile(std::filesystem::path name, std::unique_ptr<ByteSource> source);
  ~InputFile();
  InputFile(InputFile&& other) noexcept;
  InputFile& operator=(InputFile&& other) noexcept;
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  const std::filesystem::path& path() const { return mPath; }
  /// Size in bytes at open time (of the decoded bytes, for a decoder).
  std::uint64_t size() const { return mSize; }
  /// Byte offset of the next read.
  std::uint64_t offset() const { return mOffset; }
  /// Throws FileError past the end.
  void seek(std::uint64_t offset);
  /// Reads of at least this many bytes go around the buffer: what the buffer holds of one is
  /// copied, the rest read from the source straight into `data`.
  static constexpr std::size_t kLargeReadBytes = std::size_t(1) << 20;

  /// Reads up to `bytes` bytes; returns how many were read (fewer only at the end of the file).
  /// Throws FileError on an I/O error.
  std::size_t read(void* data, std::size_t bytes);
  /// Reads exactly `bytes` bytes, or throws FileError saying that the file ends inside `what`.
  void readExact(void* data, std::size_t bytes, const char* what);
  /// Reads one line without its "\n" (and "\r"). Returns false at the end of the file.
  /// Throws FileError for a line longer than `maxLength` bytes.
  bool readLine(std::string& line, std::size_t maxLength);
  /// Whether the line readLine() returned last ended with "\n" (false: the file ended inside it).
  bool lineTerminated() const { return mLineTerminated; }
  /// Whether random access is cheap: ByteSource::randomAccess. Then readAt and readScattered may
  /// be called from several threads at once.
  bool randomAccess() const { return mSource->randomAccess(); }
  /// Unbuffered random access (readers that seek, e.g. OpenVDB's pages): ByteSource::readAt.
  std::size_t readAt(std::uint64_t offset, void* data, std::size_t bytes) { return mSource->readAt(offset, data, bytes); }
  /// Reads `bytes` bytes at each of `offsets` (ascending) into `data`, one range after the other,
  /// without moving the offset: records sampled from across the file without reading it whole.
  /// Returns false, reading nothing, where that is no cheaper than reading the file whole (a
  /// decoder: ByteSource::randomAccess). Throws FileError for a range past the end.
  bool readScattered(std::span<const std::uint64_t> offsets, std::size_t bytes, std::byte* data);
  /// Up to `bytes` bytes from the start of the file, without moving the offset (format
  /// detection by magic bytes).
  std::vector<std::byte> peekHead(std::size_t bytes);

 private:
  bool fill();  ///< refills the buffer at mOffset; false at the end

  std::filesystem::path mPath;
  std::unique_ptr<ByteSource> mSource;
  std::uint64_t mSize = 0;
  std::uint64_t mOffset = 0;
  UninitializedVector<std::byte> mBuffer;  ///< bytes [mBufferStart, mBufferStart + mBuffer.size()) of the source
  std::uint64_t mBufferStart = 0;
  bool mFilled = false;  ///< the buffer was filled once (the first fill is short)
  bool mLineTerminated = false;
};

}  // namespace flipscope
