// DirectFile (see the header).
#include "preprocess/DirectFile.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>

#include "core/Error.h"

namespace flipscope::detail {

DirectFile::DirectFile(const std::filesystem::path& path, Mode mode) : mPath(path) {
  const int flags = mode == Mode::Create ? O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC : O_RDONLY | O_CLOEXEC;
  mFd = ::open(path.c_str(), flags | O_DIRECT, 0644);
  if (mFd < 0 && errno == EINVAL) mFd = ::open(path.c_str(), flags, 0644);  // tmpfs and others: no O_DIRECT
  if (mFd < 0)
    throw FileError(path,
                    std::string(mode == Mode::Create ? "cannot create spill file: " : "cannot reopen spill file: ") +
                        std::strerror(errno));
}

DirectFile::~DirectFile() {
  if (mFd >= 0) ::close(mFd);
}

void DirectFile::append(std::span<const std::byte> bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(mFd, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw FileError(mPath, std::string("spill write failed (disk full?): ") + std::strerror(n < 0 ? errno : ENOSPC));
    bytes = bytes.subspan(std::size_t(n));
  }
}

std::size_t DirectFile::read(std::span<std::byte> into) {
  std::size_t done = 0;
  while (done < into.size()) {
    const ssize_t n = ::read(mFd, into.data() + done, into.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw FileError(mPath, std::string("cannot read spill file: ") + std::strerror(errno));
    if (n == 0) break;
    done += std::size_t(n);
  }
  return done;
}

BackgroundAppender::BackgroundAppender(std::size_t bufferBytes, std::size_t maxQueued)
    : mBufferBytes(bufferBytes), mMaxQueued(std::max<std::size_t>(maxQueued, 1)), mThread([this] { run(); }) {}

BackgroundAppender::~BackgroundAppender() {
  {
    std::unique_lock lock(mMutex);
    mChanged.wait(lock, [&] { return mQueue.empty() && !mWriting; });
    mStop = true;
  }
  mChanged.notify_all();
  mThread.join();
}

AlignedBuffer BackgroundAppender::take() {
  std::lock_guard lock(mMutex);
  if (mFree.empty()) return AlignedBuffer(mBufferBytes);
  AlignedBuffer buffer = std::move(mFree.back());
  mFree.pop_back();
  return buffer;
}

void BackgroundAppender::append(DirectFile& file, AlignedBuffer buffer, std::size_t bytes) {
  {
    std::unique_lock lock(mMutex);
    mChanged.wait(lock, [&] { return mQueue.size() < mMaxQueued || mError; });
    throwError();
    mQueue.push_back({&file, std::move(buffer), bytes});
  }
  mChanged.notify_all();
}

void BackgroundAppender::drain() {
  std::unique_lock lock(mMutex);
  mChanged.wait(lock, [&] { return (mQueue.empty() && !mWriting) || mError; });
  throwError();
  mFree.clear();
}

void BackgroundAppender::throwError() {
  if (!mError) return;
  std::exception_ptr error = mError;
  mError = nullptr;
  mQueue.clear();  // what followed the failed block is not written either
  std::rethrow_exception(error);
}

void BackgroundAppender::run() {
  std::unique_lock lock(mMutex);
  for (;;) {
    mChanged.wait(lock, [&] { return !mQueue.empty() || mStop; });
    if (mQueue.empty()) return;  // stopping
    Job job = std::move(mQueue.front());
    mQueue.pop_front();
    mWriting = true;
    lock.unlock();
    std::exception_ptr error;
    try {
      job.file->append({job.buffer.data(), job.bytes});
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    mWriting = false;
    if (error && !mError) mError = error;
    mFree.push_back(std::move(job.buffer));
    mChanged.notify_all();
  }
}

}  // namespace flipscope::detail
