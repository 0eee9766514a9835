// Asynchronous brick conversion on request (Reichl et al. 2014 §3.1, §3.3): a worker pool fed
// front to back, with duplicate merging, cancellation on frame changes, back-pressure, a CPU
// cache of converted bricks and read-ahead along the playing direction.
#include "streaming/Streamer.h"

#include <algorithm>
#include <cstdlib>
#include <tuple>

#include "core/Error.h"
#include "streaming/BrickMipmap.h"

namespace flipscope {

Streamer::Streamer(std::shared_ptr<BrickSource> source, const StreamerOptions& options)
    : mSource(std::move(source)),
      mOptions(options),
      mCache(options.cacheBytes, options.compressCache),
      mCells(options.neighbourCacheBytes) {
  validate(options.conversion);
  if (options.mipDilation > kMaxMipDilation)
    throw InputError("streaming: mip dilation must be at most " + std::to_string(kMaxMipDilation) + " cells, got " +
                     std::to_string(options.mipDilation));
  FLIPSCOPE_CHECK(mSource->brickSize() == options.conversion.brickSize,
                  "source bricks " << mSource->brickSize() << " vs conversion " << options.conversion.brickSize);
  unsigned threads = std::max(1u, options.threads);
  for (unsigned i = 0; i < threads; ++i) mWorkers.emplace_back([this] { work(); });
}

Streamer::~Streamer() {
  {
    std::lock_guard lock(mMutex);
    mStopping = true;
  }
  mWorkAvailable.notify_all();
  for (std::thread& worker : mWorkers) worker.join();
}

bool Streamer::inWindow(int frame) const {
  if (frame == mFrame) return true;
  int ahead = (frame - mFrame) * mDirection;
  return mDirection != 0 && ahead > 0 && ahead <= mOptions.readAheadFrames;
}

bool Streamer::hasRunnable() const { return !mPending.empty() && mReady.size() < mOptions.maxReady; }

void Streamer::queue(const BrickKey& key, bool readAhead) {
  mPending.push_back({key, readAhead});
  mQueued.insert(key);
}

void Streamer::queueReadAhead(glm::uvec3 coord) {
  for (int d = 1; d <= mOptions.readAheadFrames && mDirection != 0; ++d) {
    BrickKey key{mFrame + d * mDirection, coord};
    if (key.frame < 0 || mQueued.count(key) || mCache.contains(key)) continue;
    queue(key, true);
  }
}

void Streamer::setFrame(int frame, int direction) {
  {
    std::lock_guard lock(mMutex);
    if (frame == mFrame && direction == mDirection) return;
    if (frame != mFrame) {
      mFrame = frame;
      std::erase_if(mReady, [&](const auto& brick) { return brick->key.frame != frame; });
      mReadyKeys.clear();
      for (const auto& brick : mReady) mReadyKeys.insert(brick->key);
      if (!mRequested.empty()) mHint = std::move(mRequested);
      mRequested.clear();
    }
    mDirection = direction;
    std::size_t before = mPending.size();
    std::erase_if(mPending, [&](const Job& job) {
      if (inWindow(job.key.frame)) return false;
      mQueued.erase(job.key);
      return true;
    });
    mStats.cancelled += before - mPending.size();
    for (const BrickKey& hint : mHint) queueReadAhead(hint.coord);
  }
  mWorkAvailable.notify_all();
}

int Streamer::frame() const {
  std::lock_guard lock(mMutex);
  return mFrame;
}

void Streamer::setEye(glm::dvec3 eyeInBricks) {
  std::lock_guard lock(mMutex);
  mEye = eyeInBricks;
}

std::size_t Streamer::request(std::span<const glm::uvec3> coords) {
  std::size_t added = 0;
  {
    std::lock_guard lock(mMutex);
    for (glm::uvec3 coord : coords) {
      mRequested.insert({0, coord});
      BrickKey key{mFrame, coord};
      if (mReadyKeys.count(key) || mQueued.count(key)) {
        ++mStats.merged;
        for (Job& job : mPending)
          if (job.key == key) job.readAhead = false;  // now wanted for display
      } else {
        queue(key, false);
        ++added;
      }
      queueReadAhead(coord);
    }
  }
  mWorkAvailable.notify_all();
  return added;
}

std::vector<std::shared_ptr<const ConvertedBrick>> Streamer::takeReady(std::size_t max) {
  std::vector<std::shared_ptr<const ConvertedBrick>> out;
  {
    std::lock_guard lock(mMutex);
    std::size_t n = std::min(max, mReady.size());
    out.assign(mReady.begin(), mReady.begin() + std::ptrdiff_t(n));
    mReady.erase(mReady.begin(), mReady.begin() + std::ptrdiff_t(n));
    for (const auto& brick : out) mReadyKeys.erase(brick->key);
  }
  mWorkAvailable.notify_all();
  return out;
}

void Streamer::waitIdle() {
  std::unique_lock lock(mMutex);
  mIdle.wait(lock, [&] { return mInFlight == 0 && !hasRunnable(); });
}

StreamerStats Streamer::stats() const {
  std::lock_guard lock(mMutex);
  return mStats;
}

std::string Streamer::lastError() const {
  try {
    rethrowLastError();
  } catch (const std::exception& e) {
    return e.what();
  } catch (...) {
    return "an exception that is not a std::exception";
  }
  return "";
}

void Streamer::rethrowLastError() const {
  std::exception_ptr error;
  {
    std::lock_guard lock(mMutex);
    error = mLastError;
  }
  if (error) std::rethrow_exception(error);
}

std::shared_ptr<const BrickCells> Streamer::cellsOf(const BrickKey& key) {
  if (auto found = mCells.find(key)) return *found;
  std::shared_ptr<const DecodedBrick> brick = mSource->read(key);
  std::shared_ptr<const BrickCells> cells;
  if (brick)
    cells = std::make_shared<const BrickCells>(makeBrickCells(*brick, mOptions.conversion));
  mCells.insert(key, cells, cells ? cells->bytes() : sizeof(BrickKey));
  return cells;
}

std::shared_ptr<const ConvertedBrick> Streamer::convert(const BrickKey& key) {
  std::array<std::shared_ptr<const BrickCells>, 27> held;
  Neighbourhood<BrickCells> cells{};
  held[kCentre] = cellsOf(key);
  if (!held[kCentre]) return nullptr;  // an empty brick: nothing to render
  for (int i = 0; i < 27; ++i) {
    if (i != kCentre && mOptions.conversion.overlap > 0) {
      glm::ivec3 offset(i % 3 - 1, i / 3 % 3 - 1, i / 9 - 1);
      glm::ivec3 coord = glm::ivec3(key.coord) + offset;
      if (coord.x >= 0 && coord.y >= 0 && coord.z >= 0) held[i] = cellsOf({key.frame, glm::uvec3(coord)});
    }
    cells[i] = held[i].get();
  }
  auto brick = std::make_shared<ConvertedBrick>();
  brick->key = key;
  brick->bits = convertBrick(cells, mOptions.conversion);
  if (mOptions.conversion.foamKinds) brick->foamKinds = convertFoamKinds(cells, mOptions.conversion);
  brick->mipmap = buildBrickMipmap(brick->bits, mOptions.mipDilation);
  return brick;
}

void Streamer::work() {
  for (;;) {
    Job job;
    {
      std::unique_lock lock(mMutex);
      mWorkAvailable.wait(lock, [&] { return mStopping || hasRunnable(); });
      if (mStopping) return;
      // Front to back: current frame first, then nearest read-ahead frame, then nearest to the eye.
      auto priority = [&](const Job& j) {
        glm::dvec3 centre = glm::dvec3(j.key.coord) + 0.5 - mEye;
        return std::tuple(j.readAhead, std::abs(j.key.frame - mFrame), glm::dot(centre, centre));
      };
      auto best = std::min_element(mPending.begin(), mPending.end(),
                                   [&](const Job& a, const Job& b) { return priority(a) < priority(b); });
      job = *best;
      *best = mPending.back();
      mPending.pop_back();
      ++mInFlight;
    }
    std::shared_ptr<const ConvertedBrick> brick;
    bool fromCache = false, failed = false;
    std::exception_ptr error;
    try {
      brick = mCache.find(job.key);
      fromCache = brick != nullptr;
      if (!brick) {
        brick = convert(job.key);
        if (brick) mCache.insert(brick);
      }
    } catch (...) {
      failed = true;
      error = std::current_exception();
    }
    {
      std::lock_guard lock(mMutex);
      --mInFlight;
      mQueued.erase(job.key);
      if (failed) {
        ++mStats.failed;
        mLastError = error;
      }
      if (!fromCache && brick) ++mStats.converted;
      bool wanted = job.key.frame == mFrame && mRequested.count({0, job.key.coord});
      if (wanted && !failed) {
        ++mStats.delivered;
        mStats.deliveredFromCache += fromCache;
        if (brick && !mReadyKeys.count(job.key)) {
          mReady.push_back(brick);
          mReadyKeys.insert(job.key);
        }
      }
    }
    mIdle.notify_all();
  }
}

}  // namespace flipscope
