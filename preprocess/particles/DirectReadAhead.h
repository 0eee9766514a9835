// DirectReadAhead: a file read in order around the page cache. Two threads of its own read the
// file ahead of the reader in aligned pieces of 2 MiB with O_DIRECT, into a ring of buffers
// that the reader copies out of. For an input read once (ReadOptions::readOnceAheadBytes):
// convert's binning pass, where the file is not in the page cache already (InputFile decides,
// by PageCacheResidency).
//
// Why (issue 13, convert at disk speed; the development VM, 2026-12-06):
// - A buffered read of a cold file fills the page cache on the reader's cores: the 1.2 GB raw
//   frame of `bench preprocess --particles 100M`, read cold by dd in 16 MiB blocks, took 1.08 s
//   with 0.53 s of system time buffered, 0.95 s with 0.04 s direct. Binning wants that half core.
// - Direct reads of 1 to 2 MiB ran the disk fastest (dd: 0.76 to 0.82 s; 4 MiB 0.83 to 0.98 s,
//   16 MiB 1.06 to 1.32 s).
// - One reading thread left the disk idle between its reads while it waited for a core (both
//   binning); two keep a read in flight (given a ring of three pieces or more: --mem 96M up).
// - The frame converted in one read (spacing and domain given) in 1.33 to 1.49 s, against 1.52
//   to 1.55 s through the page cache, alternating runs; 16 KB of it left in the cache, not 1.2 GB.
// - Each piece is one huge page (AlignedBuffer): direct reads into 4 KiB pages took twice as
//   long (0.88 to 0.93 s for the file against 0.41 to 0.45 s), and the frame in one read 1.24 to
//   1.63 s against 0.74 to 0.89 s, alternating (2026-12-07): the virtio disk maps a buffer page
//   by page. The times above are of 4 KiB pages.
// The ring's copy costs what the page cache's copy did. Pages that are cached are read from the
// disk too: reading them through the cache would start the kernel's read-ahead from the marks
// it left in them (its windows were 8 to 16 MiB here), which then keeps ahead of the stream and
// reads the whole file into the cache after all.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <mutex>
#include <thread>
#include <vector>

#include "core/AlignedBuffer.h"

namespace flipscope {

/// Which pages of a file are in the page cache: mincore() over read-only mappings of the pages
/// asked about, never touched (so a file truncated meanwhile raises no SIGBUS, as touching them
/// would) and unmapped again.
class PageCacheResidency {
 public:
  /// `fd` (open for reading) must outlive this object.
  PageCacheResidency(int fd, std::uint64_t size) : mFd(fd), mSize(size) {}

  /// Whether every page of [offset, offset + bytes) (clamped to the file) is in the page cache;
  /// false where the file cannot be mapped.
  bool cached(std::uint64_t offset, std::uint64_t bytes) const;
  /// Whether `samples` pages spread evenly over [offset, offset + bytes), its first and last
  /// included, are all in the page cache: a file read through it before (by convert's spacing
  /// pass), told at a cost that does not grow with the file.
  bool sampledCached(std::uint64_t offset, std::uint64_t bytes, unsigned samples) const;

 private:
  int mFd;
  std::uint64_t mSize;
};

class DirectReadAhead {
 public:
  static constexpr std::size_t kPieceBytes = std::size_t(2) << 20;  ///< one read of a thread
  static constexpr std::size_t kReaders = 2;                        ///< threads, each with a read in flight

  /// Starts reading the file at `offset` on, `aheadBytes` ahead of the reader (at least two
  /// pieces): through `directFd`, opened with O_DIRECT, or through `cachedFd`, opened without,
  /// where the file system will not read it so (EINVAL). Both must outlive this object; `path`
  /// names the file in errors.
  DirectReadAhead(int directFd, int cachedFd, std::filesystem::path path, std::uint64_t fileSize,
                  std::uint64_t offset, std::size_t aheadBytes);
  ~DirectReadAhead();  ///< stops the threads (after their reads in flight)
  DirectReadAhead(const DirectReadAhead&) = delete;
  DirectReadAhead& operator=(const DirectReadAhead&) = delete;

  /// The offset of the next byte read() gives.
  std::uint64_t position() const { return mPosition; }
  /// Copies the next `bytes` into `data`; returns how many, fewer only at the end of the file.
  /// Throws FileError, naming the file, on an I/O error.
  std::size_t read(void* data, std::size_t bytes);

 private:
  /// A piece of the ring: buffer i of n holds the pieces numbered i, i + n, ...
  struct Piece {
    bool filled = false;       ///< by a thread, for the reader; else free, or being read
    std::uint64_t offset = 0;  ///< of its first byte in the file
    std::size_t bytes = 0;     ///< read; fewer than kPieceBytes only at the end of the file
    AlignedBuffer buffer;
  };
  void run();   ///< a thread: reads the next piece whose buffer is free, until the end or stop()
  void stop();  ///< stops and joins the threads (after their reads in flight)

  const int mDirectFd, mCachedFd;
  const std::filesystem::path mPath;
  const std::uint64_t mFileSize;
  const std::uint64_t mStart;          ///< the first piece's offset: a whole block
  std::uint64_t mPosition;             ///< reader side: of the next byte read() gives
  std::vector<Piece> mPieces;          ///< the ring
  std::mutex mMutex;
  std::condition_variable mChanged;
  std::uint64_t mNextRead = 0;         ///< the number of the next piece a thread reads
  std::uint64_t mNextCopy = 0;         ///< the number of the piece read() copies from
  std::uint64_t mEndPiece;             ///< the first piece past the end of the file (earlier once it is cut short)
  std::uint64_t mErrorPiece;           ///< the number of the first piece that failed (else no piece's)
  bool mStop = false;
  bool mDirectRefused = false;         ///< a direct read failed with EINVAL: all through the cache
  std::exception_ptr mError;           ///< of the earliest piece that failed, mErrorPiece
  std::vector<std::thread> mThreads;   ///< last: started once the members above exist
};

}  // namespace flipscope
