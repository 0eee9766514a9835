// DirectReadAhead and PageCacheResidency (see the header).
#include "preprocess/particles/DirectReadAhead.h"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <exception>
#include <string>
#include <system_error>
#include <vector>

#include "core/Error.h"

namespace flipscope {
namespace {

constexpr std::uint64_t kPage = 4096;

}  // namespace

bool PageCacheResidency::sampledCached(std::uint64_t offset, std::uint64_t bytes, unsigned samples) const {
  const std::uint64_t end = std::min(mSize, offset + bytes);
  if (offset >= end) return true;
  const std::uint64_t first = offset / kPage, pages = (end - 1) / kPage + 1 - first;
  for (unsigned i = 0; i < samples; ++i) {
    const std::uint64_t page = first + (samples > 1 ? (pages - 1) * i / (samples - 1) : 0);
    if (!cached(page * kPage, 1)) return false;
  }
  return true;
}

bool PageCacheResidency::cached(std::uint64_t offset, std::uint64_t bytes) const {
  const std::uint64_t end = std::min(mSize, offset + bytes);
  if (offset >= end) return true;
  constexpr std::uint64_t kBatch = 1 << 14;  // pages a mapping (64 MiB)
  std::vector<unsigned char> flags;
  for (std::uint64_t page = offset / kPage, last = (end - 1) / kPage; page <= last; page += kBatch) {
    const std::uint64_t pages = std::min(kBatch, last + 1 - page);
    void* map = ::mmap(nullptr, pages * kPage, PROT_READ, MAP_SHARED, mFd, off_t(page * kPage));
    if (map == MAP_FAILED) return false;
    flags.resize(pages);
    const bool asked = ::mincore(map, pages * kPage, flags.data()) == 0;
    ::munmap(map, pages * kPage);
    if (!asked || std::any_of(flags.begin(), flags.end(), [](unsigned char f) { return !(f & 1); })) return false;
  }
  return true;
}

DirectReadAhead::DirectReadAhead(int directFd, int cachedFd, std::filesystem::path path, std::uint64_t fileSize,
                                 std::uint64_t offset, std::size_t aheadBytes)
    : mDirectFd(directFd),
      mCachedFd(cachedFd),
      mPath(std::move(path)),
      mFileSize(fileSize),
      mStart(offset / kDirectBlock * kDirectBlock),
      mPosition(offset),
      mPieces(std::max<std::size_t>(aheadBytes / kPieceBytes, 2)),
      mEndPiece(fileSize > mStart ? (fileSize - mStart + kPieceBytes - 1) / kPieceBytes : 0),
      mErrorPiece(~std::uint64_t(0)) {
  for (Piece& piece : mPieces) piece.buffer = AlignedBuffer(kPieceBytes);
  try {
    for (std::size_t i = 0; i < kReaders; ++i) mThreads.emplace_back([this] { run(); });
  } catch (...) {
    stop();  // the threads started
    throw;
  }
}

DirectReadAhead::~DirectReadAhead() { stop(); }

void DirectReadAhead::stop() {
  {
    std::lock_guard lock(mMutex);
    mStop = true;
  }
  mChanged.notify_all();
  for (auto& thread : mThreads) thread.join();
}

void DirectReadAhead::run() {
  for (;;) {
    std::uint64_t number;
    bool direct;
    {
      std::unique_lock lock(mMutex);
      // The next piece, once its buffer is free: copied out of, or never used.
      mChanged.wait(lock, [&] {
        return mStop || mNextRead >= std::min(mEndPiece, mErrorPiece) || mNextRead < mNextCopy + mPieces.size();
      });
      if (mStop || mNextRead >= std::min(mEndPiece, mErrorPiece)) return;
      number = mNextRead++;
      direct = !mDirectRefused;
    }
    Piece& piece = mPieces[number % mPieces.size()];
    const std::uint64_t offset = mStart + number * kPieceBytes;
    const std::size_t want = std::size_t(std::min<std::uint64_t>(kPieceBytes, mFileSize - offset));
    std::size_t done = 0;
    std::exception_ptr error;
    try {
      while (done < want) {
        // Direct reads start at whole blocks and ask for whole blocks (the file's last piece for
        // its last block's rest): what follows a read that ended inside a block (the file ends
        // there, or was truncated since) goes through the cache.
        const bool aligned = direct && done % kDirectBlock == 0;
        const std::size_t ask = aligned ? (want - done + kDirectBlock - 1) / kDirectBlock * kDirectBlock : want - done;
        const ssize_t n = ::pread(aligned ? mDirectFd : mCachedFd, piece.buffer.data() + done, ask, off_t(offset + done));
        if (n < 0 && errno == EINTR) continue;
        if (n < 0 && errno == EINVAL && aligned) {  // a file system that opens O_DIRECT but will not read it so
          direct = false;
          const std::lock_guard lock(mMutex);
          mDirectRefused = true;
          continue;
        }
        if (n < 0)
          throw FileError(mPath, "read failed at byte " + std::to_string(offset + done) + ": " +
                                     std::system_category().message(errno));
        if (n == 0) break;
        done += std::min(std::size_t(n), want - done);
      }
    } catch (...) {
      error = std::current_exception();
    }
    const std::lock_guard lock(mMutex);
    piece.offset = offset;
    piece.bytes = done;
    piece.filled = true;
    if (error && number < mErrorPiece) {
      mErrorPiece = number;
      mError = error;
    }
    mChanged.notify_all();
  }
}

std::size_t DirectReadAhead::read(void* data, std::size_t bytes) {
  auto* out = static_cast<std::byte*>(data);
  std::size_t done = 0;
  while (done < bytes && mNextCopy < mEndPiece) {
    Piece& piece = mPieces[mNextCopy % mPieces.size()];
    {
      std::unique_lock lock(mMutex);
      mChanged.wait(lock, [&] { return piece.filled; });
      if (mNextCopy == mErrorPiece) std::rethrow_exception(mError);
    }
    // The piece is the reader's until it is given back: no lock to copy out of it.
    const std::uint64_t pieceEnd = piece.offset + piece.bytes;
    if (mPosition < pieceEnd) {
      const std::size_t n = std::size_t(std::min<std::uint64_t>(bytes - done, pieceEnd - mPosition));
      std::memcpy(out + done, piece.buffer.data() + (mPosition - piece.offset), n);
      done += n;
      mPosition += n;
    }
    if (mPosition < pieceEnd) break;  // `bytes` given
    const bool last = piece.bytes < kPieceBytes;  // the file ends here (or was truncated since it was opened)
    {
      std::lock_guard lock(mMutex);
      piece.filled = false;
      ++mNextCopy;
      if (last) mEndPiece = mNextCopy;
    }
    mChanged.notify_all();
  }
  return done;
}

}  // namespace flipscope
