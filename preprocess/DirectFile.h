// DirectFile: a scratch file written and read in aligned blocks with O_DIRECT where the file
// system takes it (else through the page cache), for out-of-core binning's spill files.
//
// Why not the page cache: spill files are written once, read once and removed, so caching them
// gains nothing, and each page they take is fresh memory. On the virtual machines we measured
// (the development machine, 2026-12-03), copying 4 GB of spill records into fresh page-cache
// folios was a third of a 500 M particle convert; a direct write of 1 MiB blocks runs at the
// disk's speed from our own, already touched, buffers.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <exception>
#include <filesystem>
#include <memory>
#include <mutex>
#include <span>
#include <thread>
#include <vector>

#include "core/AlignedBuffer.h"

namespace flipscope::detail {

class DirectFile {
 public:
  enum class Mode { Create, Read };
  /// Creates (truncating) or opens `path`. Throws FileError naming it.
  DirectFile(const std::filesystem::path& path, Mode mode);
  ~DirectFile();
  DirectFile(const DirectFile&) = delete;
  DirectFile& operator=(const DirectFile&) = delete;

  /// Appends `bytes` (a multiple of kDirectBlock, from an AlignedBuffer). Throws FileError
  /// (disk full, I/O error).
  void append(std::span<const std::byte> bytes);
  /// Reads the next bytes into `into` (a multiple of kDirectBlock long, from an AlignedBuffer);
  /// returns how many were read: fewer only at the end of the file.
  std::size_t read(std::span<std::byte> into);

 private:
  std::filesystem::path mPath;
  int mFd = -1;
};

/// Appends blocks to DirectFiles on a thread of its own, so that the caller goes on computing
/// while the disk writes, with at most `maxQueued` blocks waiting. Buffers come from take() and
/// go back to its pool once written. A write error comes back from the next call.
class BackgroundAppender {
 public:
  BackgroundAppender(std::size_t bufferBytes, std::size_t maxQueued);
  ~BackgroundAppender();  ///< waits for the blocks queued (their errors are dropped)
  BackgroundAppender(const BackgroundAppender&) = delete;
  BackgroundAppender& operator=(const BackgroundAppender&) = delete;

  /// A buffer of bufferBytes: one written before, or a new one.
  AlignedBuffer take();
  /// Queues buffer's first `bytes` (a multiple of kDirectBlock) to be appended to `file`, which
  /// must outlive the write (drain()). Waits while maxQueued blocks are queued.
  void append(DirectFile& file, AlignedBuffer buffer, std::size_t bytes);
  /// Waits until every queued block is written and frees the buffers of the pool; throws the
  /// first write error.
  void drain();

 private:
  struct Job {
    DirectFile* file;
    AlignedBuffer buffer;
    std::size_t bytes;
  };
  void run();
  void throwError();  ///< with mMutex held

  std::size_t mBufferBytes, mMaxQueued;
  std::mutex mMutex;
  std::condition_variable mChanged;
  std::deque<Job> mQueue;
  bool mWriting = false;  ///< a job taken from the queue is being written
  bool mStop = false;
  std::exception_ptr mError;
  std::vector<AlignedBuffer> mFree;
  std::thread mThread;  ///< last: started once the members above exist
};

}  // namespace flipscope::detail
