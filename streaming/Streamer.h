// Streamer: converts requested bricks on a worker pool without blocking the caller (Reichl et
// al. 2014 §3.1, §3.3: "the request buffer is read to the CPU, and the requested bricks are
// converted (if not yet done) and sent to the GPU for use in the next frame").
//
//  - request() queues (current frame, brick) pairs; pending work is taken nearest to the eye
//    first (front-to-back, as the GPU renders), current frame before read-ahead;
//  - a brick already pending, in flight or ready is merged, not queued twice;
//  - setFrame() cancels pending work of frames outside the current frame and its read-ahead
//    window, and drops ready bricks of other frames;
//  - converted bricks go to the CPU cache (ConvertedBrickCache) and, for the current frame, to
//    the ready list that takeReady() drains; workers pause while the ready list is full
//    (back-pressure on a slow consumer);
//  - read-ahead: with a playing direction, the bricks requested for the current frame are
//    queued for the next `readAheadFrames` frames in that direction, into the cache only.
// Neighbour bricks' BrickCells (for the overlap border) are kept in an LRU of their own.
// Thread safety: every public member may be called from any thread.
#pragma once

#include <condition_variable>
#include <exception>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "streaming/BitBrick.h"
#include "streaming/BrickSource.h"
#include "streaming/ConvertedBrickCache.h"

namespace flipscope {

struct StreamerOptions {
  ConversionOptions conversion;
  std::uint32_t mipDilation = 0;  ///< see buildBrickMipmap; <= kMaxMipDilation
  unsigned threads = 2;
  std::size_t cacheBytes = std::size_t(1) << 30;  ///< converted bricks, all frames
  bool compressCache = false;
  std::size_t neighbourCacheBytes = std::size_t(256) << 20;  ///< BrickCells of recent bricks
  std::size_t maxReady = 1024;                               ///< ready bricks before workers pause
  int readAheadFrames = 0;
};

struct StreamerStats {
  std::uint64_t converted = 0;           ///< conversions done
  std::uint64_t merged = 0;              ///< requests already pending, in flight or ready
  std::uint64_t cancelled = 0;           ///< pending requests dropped by setFrame()
  std::uint64_t failed = 0;              ///< bricks whose source threw (the error is kept, see lastError)
  std::uint64_t delivered = 0;           ///< current-frame requests completed (ready, or empty bricks)
  std::uint64_t deliveredFromCache = 0;  ///< of those, served by the converted-brick cache
  double cacheHitRate() const { return delivered ? double(deliveredFromCache) / double(delivered) : 0.0; }
};

class Streamer {
 public:
  Streamer(std::shared_ptr<BrickSource> source, const StreamerOptions& options);
  ~Streamer();
  Streamer(const Streamer&) = delete;
  Streamer& operator=(const Streamer&) = delete;

  /// Makes `frame` current; direction (+1 playing forward, -1 backward, 0 paused) steers
  /// read-ahead. Cancels stale pending work.
  void setFrame(int frame, int direction = 0);
  int frame() const;
  /// Eye position in brick-grid units (brick (i,j,k) spans [i, i+1) x ...) for the ordering.
  void setEye(glm::dvec3 eyeInBricks);
  /// Queues bricks of the current frame; returns how many were new. Never blocks on work.
  std::size_t request(std::span<const glm::uvec3> coords);
  /// Up to `max` converted bricks of the current frame, in completion order. Never blocks.
  std::vector<std::shared_ptr<const ConvertedBrick>> takeReady(std::size_t max);
  /// Blocks until nothing is pending or in flight, or the ready list is full.
  void waitIdle();

  StreamerStats stats() const;
  /// The message of the last brick whose source threw ("" if none).
  std::string lastError() const;
  /// Rethrows the last brick failure as it was thrown on the worker, type included (a damaged
  /// file stays a FileError, a bug a LogicError); nothing if no brick failed.
  void rethrowLastError() const;
  const ConvertedBrickCache& cache() const { return mCache; }

 private:
  using BrickKeySet = std::unordered_set<BrickKey, BrickKeyHash>;
  struct Job {
    BrickKey key;
    bool readAhead;
  };
  void work();
  std::shared_ptr<const ConvertedBrick> convert(const BrickKey& key);
  std::shared_ptr<const BrickCells> cellsOf(const BrickKey& key);
  bool inWindow(int frame) const;                   // caller holds mMutex
  void queue(const BrickKey& key, bool readAhead);  // caller holds mMutex
  void queueReadAhead(glm::uvec3 coord);            // caller holds mMutex
  bool hasRunnable() const;                         // caller holds mMutex

  std::shared_ptr<BrickSource> mSource;
  StreamerOptions mOptions;
  ConvertedBrickCache mCache;
  LruCache<BrickKey, BrickCells, BrickKeyHash> mCells;

  mutable std::mutex mMutex;
  std::condition_variable mWorkAvailable;
  std::condition_variable mIdle;
  int mFrame = 0;
  int mDirection = 0;
  glm::dvec3 mEye{0};
  std::vector<Job> mPending;
  BrickKeySet mQueued;  ///< pending or in flight
  BrickKeySet mReadyKeys;
  std::vector<std::shared_ptr<const ConvertedBrick>> mReady;
  BrickKeySet mRequested;  ///< coords (frame 0) requested since the current frame was set
  BrickKeySet mHint;       ///< coords requested for the previous frame: read-ahead of the next ones
  std::size_t mInFlight = 0;
  bool mStopping = false;
  StreamerStats mStats;
  std::exception_ptr mLastError;
  std::vector<std::thread> mWorkers;
};

}  // namespace flipscope
