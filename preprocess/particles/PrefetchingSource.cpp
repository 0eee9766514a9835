// PrefetchingSource: one chunk read ahead on a thread of its own (see the header).
#include "preprocess/particles/PrefetchingSource.h"

#include <utility>

#include "core/Error.h"

namespace flipscope {

PrefetchingSource::PrefetchingSource(ParticleSource& inner) : mInner(inner) {
  mThread = std::thread([this] {
    std::unique_lock lock(mMutex);
    for (;;) {
      mChanged.wait(lock, [&] { return mStop || (mInFlight && !mReady); });
      if (mStop) return;
      const std::size_t size = mChunkSize;
      lock.unlock();
      bool ok = false;
      std::exception_ptr error;
      try {
        ok = mInner.read(mAhead, size);
      } catch (...) {
        error = std::current_exception();
      }
      lock.lock();
      mAheadOk = ok;
      mError = error;
      mReady = true;
      mChanged.notify_all();
    }
  });
}

PrefetchingSource::~PrefetchingSource() {
  {
    std::unique_lock lock(mMutex);
    if (mInFlight) waitForChunk(lock);
    mStop = true;
  }
  mChanged.notify_all();
  mThread.join();
}

void PrefetchingSource::prefetch() {
  mInFlight = true;
  mReady = false;
  mChanged.notify_all();
}

void PrefetchingSource::waitForChunk(std::unique_lock<std::mutex>& lock) {
  mChanged.wait(lock, [&] { return mReady; });
  mInFlight = false;
}

bool PrefetchingSource::read(ParticleChunk& chunk, std::size_t maxParticles) {
  FLIPSCOPE_CHECK(maxParticles > 0);
  std::unique_lock lock(mMutex);
  if (!mStarted) {
    mStarted = true;
    mChunkSize = maxParticles;
    if (!mEnded) prefetch();
  }
  FLIPSCOPE_CHECK(maxParticles == mChunkSize,
                  "a prefetching source reads chunks of one size a pass: " << maxParticles << " after " << mChunkSize);
  if (mEnded) {
    chunk.clear();
    return false;
  }
  waitForChunk(lock);
  if (mError) {
    mEnded = true;  // the inner source is in no state to read on
    std::rethrow_exception(std::exchange(mError, nullptr));
  }
  std::swap(chunk, mAhead);  // the caller's old chunk becomes the next buffer
  if (!mAheadOk) {
    mEnded = true;
    chunk.clear();
    return false;
  }
  prefetch();
  return true;
}

void PrefetchingSource::rewind() {
  std::unique_lock lock(mMutex);
  if (mInFlight) waitForChunk(lock);
  mError = nullptr;
  mInner.rewind();
  mStarted = false;
  mEnded = false;
}

bool PrefetchingSource::readPositionsAt(std::span<const std::uint64_t> indices, std::vector<glm::vec3>& positions) {
  std::unique_lock lock(mMutex);
  if (mInFlight) waitForChunk(lock);
  return mInner.readPositionsAt(indices, positions);
}

}  // namespace flipscope
