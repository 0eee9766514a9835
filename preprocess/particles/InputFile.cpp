#include "preprocess/particles/InputFile.h"

#include <fcntl.h>
#include <sys/uio.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

#include "core/Error.h"
#include "preprocess/particles/DirectReadAhead.h"

namespace flipscope {
namespace {

constexpr std::size_t kBufferBytes = InputFile::kLargeReadBytes;
/// The first fill's: a header, or a file's magic, is read without a megabyte of fresh memory
/// (on the development VM, whose first touch of fresh pages runs at 0.4 GB/s, 2.6 ms an open;
/// a convert opens its input three or four times).
constexpr std::size_t kFirstFillBytes = std::size_t(64) << 10;

class FileByteSource final : public ByteSource {
 public:
  FileByteSource(const std::filesystem::path& path, std::size_t readOnceAheadBytes)
      : mPath(path), mReadOnceAheadBytes(readOnceAheadBytes) {
    std::error_code ec;
    auto status = std::filesystem::status(path, ec);
    if (!std::filesystem::exists(status)) throw FileError(path, "no such file");
    if (std::filesystem::is_directory(status)) throw FileError(path, "is a directory, expected a particle file");
    if (!std::filesystem::is_regular_file(status))
      throw FileError(path, "is not a regular file (a device, pipe or socket), expected a particle file");
    mFd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (mFd < 0) throw FileError(path, std::string("cannot open: ") + std::strerror(errno));
    mSize = std::filesystem::file_size(path, ec);
    if (ec) {
      ::close(mFd);
      throw FileError(path, "cannot read the file size: " + ec.message());
    }
    ::posix_fadvise(mFd, 0, 0, POSIX_FADV_SEQUENTIAL);
    if (readOnceAheadBytes > 0 && mSize > 0) {
      mDirectFd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_DIRECT);  // fails where the file system has none
      if (mDirectFd >= 0) mResidency.emplace(mFd, mSize);
    }
  }
  ~FileByteSource() override {
    mStream.reset();  // its threads read from both descriptors
    if (mDirectFd >= 0) ::close(mDirectFd);
    ::close(mFd);
  }
  std::uint64_t size() const override { return mSize; }
  std::size_t readAt(std::uint64_t offset, void* data, std::size_t bytes) override {
    if (mDirectFd >= 0 && (bytes >= kReadAheadTrigger || offset == mStreamPosition.load(std::memory_order_relaxed)))
      if (const auto n = readAround(offset, data, bytes)) return *n;
    readAhead(offset, bytes);
    std::size_t done = 0;
    while (done < bytes) {
      ssize_t n = ::pread(mFd, static_cast<char*>(data) + done, bytes - done, off_t(offset + done));
      if (n < 0 && errno == EINTR) continue;
      if (n < 0)
        throw FileError(mPath, "read failed at byte " + std::to_string(offset + done) + ": " + std::strerror(errno));
      if (n == 0) break;
      done += std::size_t(n);
    }
    mReadEnd.store(offset + done, std::memory_order_relaxed);
    return done;
  }
  bool randomAccess() const override { return true; }
  void willRead(std::span<const std::uint64_t> offsets, std::size_t bytes) override {
    for (std::uint64_t offset : offsets) ::posix_fadvise(mFd, off_t(offset), off_t(bytes), POSIX_FADV_WILLNEED);
  }
  bool readIfCached(std::uint64_t offset, void* data, std::size_t bytes) override {
    // RWF_NOWAIT: EAGAIN (or a short read) where a page is not in the cache; EOPNOTSUPP where the
    // kernel or the file system has no such read, and then never again. Either way readAt reads it.
    if (!mNoWaitReads.load(std::memory_order_relaxed)) return false;
    iovec range{data, bytes};
    const ssize_t n = ::preadv2(mFd, &range, 1, off_t(offset), RWF_NOWAIT);
    if (n < 0 && (errno == EOPNOTSUPP || errno == EINVAL || errno == ENOSYS))
      mNoWaitReads.store(false, std::memory_order_relaxed);
    return n == ssize_t(bytes);
  }

 private:
  /// A read of a file read once: from the stream around the page cache (DirectReadAhead) that
  /// the last read left off, whatever its size, or a large one from a new stream where it starts
  /// the file or continues the last read, and the rest of the file is not in the cache
  /// (kResidencySamples of its pages say). Nothing where it is read through the cache: reads
  /// that jump about (a VDB's grids), and a file found in the cache (a file read before, by
  /// convert's spacing pass: from then on). The stream ends, its ring freed, at the end of the
  /// file.
  std::optional<std::size_t> readAround(std::uint64_t offset, void* data, std::size_t bytes) {
    const std::lock_guard lock(mStreamMutex);
    if (!mStream || mStream->position() != offset) {
      mStream.reset();
      mStreamPosition.store(kNoStream, std::memory_order_relaxed);
      if (mFoundCached || bytes < kReadAheadTrigger ||
          (offset != 0 && offset != mReadEnd.load(std::memory_order_relaxed)))
        return std::nullopt;
      mFoundCached = mResidency->sampledCached(offset, mSize - std::min(mSize, offset), kResidencySamples);
      if (mFoundCached) return std::nullopt;
      mStream = std::make_unique<DirectReadAhead>(mDirectFd, mFd, mPath, mSize, offset, mReadOnceAheadBytes);
    }
    const std::size_t n = mStream->read(data, bytes);
    mReadEnd.store(offset + n, std::memory_order_relaxed);
    const bool ended = n < bytes || mStream->position() >= mSize;
    if (ended) mStream.reset();
    mStreamPosition.store(ended ? kNoStream : mStream->position(), std::memory_order_relaxed);
    return n;
  }

  /// Deep read-ahead of a sequential reader: a large read (at least kReadAheadTrigger) that
  /// continues the last one asks the kernel (POSIX_FADV_WILLNEED) for the next kReadAheadBytes
  /// beyond it, in steps of a quarter of that. A reader that asks a cold disk for a few MB at a
  /// time otherwise waits on each read, the kernel's own read-ahead being a few hundred KB: a
  /// 100 M particle raw frame converted from disk in one read (spacing and domain given) took
  /// 2.13 to 2.77 s without, 1.61 to 1.77 s with (O_DIRECT read of the file: 0.6 to 0.9 s;
  /// 2026-12-06). Reads that jump about (a VDB's grids, the spacing sample) ask nothing more.
  /// Thread safe, as readAt: readers on several threads at once (readScattered, the position
  /// ranges) make no sequence, and at worst ask for a range twice.
  void readAhead(std::uint64_t offset, std::size_t bytes) {
    if (bytes < kReadAheadTrigger || offset != mReadEnd.load(std::memory_order_relaxed)) return;
    const std::uint64_t end = offset + bytes, want = std::min(mSize, end + kReadAheadBytes);
    const std::uint64_t from = std::max(mAheadEnd.load(std::memory_order_relaxed), end);
    if (want < from + kReadAheadBytes / 4) return;
    ::posix_fadvise(mFd, off_t(from), off_t(want - from), POSIX_FADV_WILLNEED);
    mAheadEnd.store(want, std::memory_order_relaxed);
  }

  static constexpr std::size_t kReadAheadTrigger = std::size_t(1) << 20;
  static constexpr unsigned kResidencySamples = 64;
  static constexpr std::uint64_t kNoStream = ~std::uint64_t(0);
  static constexpr std::uint64_t kReadAheadBytes = std::uint64_t(64) << 20;
  std::filesystem::path mPath;
  int mFd = -1;
  std::uint64_t mSize = 0;
  std::atomic<std::uint64_t> mReadEnd{0};   ///< where the last read ended
  std::atomic<std::uint64_t> mAheadEnd{0};  ///< how far the read-ahead was asked for
  std::atomic<bool> mNoWaitReads{true};     ///< preadv2(RWF_NOWAIT) works here (readIfCached)
  std::size_t mReadOnceAheadBytes;          ///< 0: the file may be read again
  int mDirectFd = -1;                       ///< opened with O_DIRECT: a file read once
  std::optional<PageCacheResidency> mResidency;  ///< with mDirectFd
  std::mutex mStreamMutex;
  std::unique_ptr<DirectReadAhead> mStream;               ///< the large reads in order of a file read once
  std::atomic<std::uint64_t> mStreamPosition{kNoStream};  ///< mStream's, for readAt without the lock
  bool mFoundCached = false;                              ///< read through the cache from then on
};

class MemoryByteSource final : public ByteSource {
 public:
  explicit MemoryByteSource(std::span<const std::byte> bytes) : mBytes(bytes) {}
  std::uint64_t size() const override { return mBytes.size(); }
  std::size_t readAt(std::uint64_t offset, void* data, std::size_t bytes) override {
    if (offset >= mBytes.size()) return 0;
    std::size_t n = std::min<std::size_t>(bytes, std::size_t(mBytes.size() - offset));
    if (n) std::memcpy(data, mBytes.data() + offset, n);
    return n;
  }
  bool randomAccess() const override { return true; }

 private:
  std::span<const std::byte> mBytes;
};

}  // namespace

InputFile::InputFile(std::filesystem::path path, std::size_t readOnceAheadBytes)
    : InputFile(path, std::make_unique<FileByteSource>(path, readOnceAheadBytes)) {}

InputFile::InputFile(std::filesystem::path name, std::span<const std::byte> bytes)
    : InputFile(std::move(name), std::make_unique<MemoryByteSource>(bytes)) {}

InputFile::InputFile(std::filesystem::path name, std::unique_ptr<ByteSource> source)
    : mPath(std::move(name)), mSource(std::move(source)), mSize(mSource->size()) {}

InputFile::InputFile(InputFile&& other) noexcept = default;
InputFile& InputFile::operator=(InputFile&& other) noexcept = default;
InputFile::~InputFile() = default;

void InputFile::seek(std::uint64_t offset) {
  if (offset > mSize) throw FileError(mPath, "cannot seek to byte " + std::to_string(offset) + ": past the end");
  mOffset = offset;
}

bool InputFile::fill() {
  if (mOffset >= mBufferStart && mOffset < mBufferStart + mBuffer.size()) return true;
  if (mOffset >= mSize) return false;
  mBuffer.resize(mFilled ? kBufferBytes : kFirstFillBytes);  // uninitialized: readAt writes it
  mFilled = true;
  mBufferStart = mOffset;
  try {
    mBuffer.resize(mSource->readAt(mOffset, mBuffer.data(), mBuffer.size()));
  } catch (...) {
    mBuffer.clear();  // nothing read is held: a read after the error asks the source again
    throw;
  }
  return !mBuffer.empty();
}

std::size_t InputFile::read(void* data, std::size_t bytes) {
  auto* out = static_cast<std::byte*>(data);
  std::size_t done = 0;
  // A large read goes around the buffer whole, not only where what is left of it is large: a
  // reader of 1 MiB batches whose first batch starts inside the buffer would otherwise have every
  // batch read into the buffer and copied out again, the two megabytes twice the second-level
  // cache. The kernel's copies of the 20 M particle PLY (480 MB) took 0.28 s of CPU so, 0.07 s
  // around the buffer (`perf record` of its convert, 2026-12-07).
  const bool large = bytes >= kLargeReadBytes;
  while (done < bytes) {
    if (large && !(mOffset >= mBufferStart && mOffset < mBufferStart + mBuffer.size())) {
      std::size_t n = mSource->readAt(mOffset, out + done, bytes - done);
      mOffset += n;
      done += n;
      break;
    }
    if (!fill()) break;
    std::size_t at = std::size_t(mOffset - mBufferStart);
    std::size_t n = std::min(bytes - done, mBuffer.size() - at);
    std::memcpy(out + done, mBuffer.data() + at, n);
    mOffset += n;
    done += n;
  }
  return done;
}

void InputFile::readExact(void* data, std::size_t bytes, const char* what) {
  std::uint64_t at = mOffset;
  if (read(data, bytes) != bytes)
    throw FileError(mPath, std::string("truncated: the file ends inside ") + what + " (" + std::to_string(bytes) +
                               " bytes at byte " + std::to_string(at) + ", file size " + std::to_string(mSize) + ")");
}

bool InputFile::readScattered(std::span<const std::uint64_t> offsets, std::size_t bytes, std::byte* data) {
  if (!mSource->randomAccess()) return false;
  // Each thread reads what is in the page cache at once (readIfCached), then announces the rest
  // (a system call each, about as long as a read of a cached range) and reads it: a cached file
  // costs one system call a range, not two (the 5000 ranges of the particle spacing's sample of
  // the 20 M particle PLY took 19 ms with an announcement each, 11 to 12 ms so).
  const auto readRanges = [&](std::size_t begin, std::size_t end) {
    std::vector<std::uint64_t> missed;
    std::vector<std::size_t> missedIndex;
    for (std::size_t i = begin; i < end; ++i)
      if (!mSource->readIfCached(offsets[i], data + i * bytes, bytes)) {
        missed.push_back(offsets[i]);
        missedIndex.push_back(i);
      }
    mSource->willRead(missed, bytes);
    for (const std::size_t i : missedIndex)
      if (mSource->readAt(offsets[i], data + i * bytes, bytes) != bytes)
        throw FileError(mPath, "file ends before byte " + std::to_string(offsets[i] + bytes) +
                                   " (was it truncated while being read?)");
  };
  // Many small reads: two threads, since most of a read's time is the system call's own.
  constexpr std::size_t kOneThread = 1024;
  if (offsets.size() < kOneThread) {
    readRanges(0, offsets.size());
    return true;
  }
  const std::size_t half = offsets.size() / 2;
  std::exception_ptr error;
  std::thread second([&] {
    try {
      readRanges(half, offsets.size());
    } catch (...) {
      error = std::current_exception();
    }
  });
  try {
    readRanges(0, half);
  } catch (...) {
    second.join();
    throw;
  }
  second.join();
  if (error) std::rethrow_exception(error);
  return true;
}

std::vector<std::byte> InputFile::peekHead(std::size_t bytes) {
  std::vector<std::byte> head(std::min<std::uint64_t>(bytes, mSize));
  head.resize(mSource->readAt(0, head.data(), head.size()));
  return head;
}

bool InputFile::readLine(std::string& line, std::size_t maxLength) {
  line.clear();
  mLineTerminated = false;
  for (;;) {
    if (!fill()) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      return !line.empty();
    }
    const std::size_t at = std::size_t(mOffset - mBufferStart);
    const auto* begin = reinterpret_cast<const char*>(mBuffer.data()) + at;
    const auto* end = reinterpret_cast<const char*>(mBuffer.data()) + mBuffer.size();
    const auto* newline = static_cast<const char*>(std::memchr(begin, '\n', std::size_t(end - begin)));
    const auto* stop = newline ? newline : end;
    if (line.size() + std::size_t(stop - begin) > maxLength)
      throw FileError(mPath, "line at byte " + std::to_string(mOffset - line.size()) + " is longer than " +
                                 std::to_string(maxLength) + " bytes");
    line.append(begin, stop);
    mOffset += std::uint64_t(stop - begin);
    if (newline) {
      ++mOffset;
      break;
    }
  }
  mLineTerminated = true;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return true;
}

}  // namespace flipscope
