// PrefetchingSource: reads a source's next chunk on a thread of its own while the caller works
// on the current one, so that reading overlaps binning (Reichl et al. 2014 §3: the preprocess
// is "limited only by the disk"). The chunks, their order and their contents are the inner
// source's: a convert through it writes the same store.
//
// Contract: every read() of one pass asks for the same maxParticles (the chunk read ahead was
// read with it); rewind() starts a new pass, which may ask for another size. Errors of the inner
// source's reads reach the caller from the read() that would have returned the chunk. Memory:
// one chunk more than the caller's. The inner source is only touched by the prefetch thread
// while a read is in flight, and by rewind(), which waits for it first.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>

#include "preprocess/particles/ParticleSource.h"

namespace flipscope {

class PrefetchingSource final : public ParticleSource {
 public:
  /// `inner` must outlive this object.
  explicit PrefetchingSource(ParticleSource& inner);
  ~PrefetchingSource() override;  ///< waits for the read in flight
  PrefetchingSource(const PrefetchingSource&) = delete;
  PrefetchingSource& operator=(const PrefetchingSource&) = delete;

  std::string name() const override { return mInner.name(); }
  std::string format() const override { return mInner.format(); }
  std::vector<AttributeDesc> attributes() const override { return mInner.attributes(); }
  bool hasVelocity() const override { return mInner.hasVelocity(); }
  std::optional<std::uint64_t> countHint() const override { return mInner.countHint(); }
  std::optional<SpacingHint> spacingHint() const override { return mInner.spacingHint(); }
  std::optional<std::string> kindAttribute() const override { return mInner.kindAttribute(); }
  UpAxis upAxis() const override { return mInner.upAxis(); }
  bool read(ParticleChunk& chunk, std::size_t maxParticles) override;
  void rewind() override;
  /// The inner source's, once the read in flight (if any) is done; a chunk read ahead stays.
  bool readPositionsAt(std::span<const std::uint64_t> indices, std::vector<glm::vec3>& positions) override;
  /// The inner source's (thread safe, it leaves the reads where they are).
  bool readPositionRange(std::uint64_t first, std::size_t count, std::vector<glm::vec3>& positions) override {
    return mInner.readPositionRange(first, count, positions);
  }

 private:
  void prefetch();
  void waitForChunk(std::unique_lock<std::mutex>& lock);

  ParticleSource& mInner;
  std::mutex mMutex;
  std::condition_variable mChanged;
  bool mInFlight = false;  ///< the thread reads mAhead
  bool mReady = false;     ///< mAhead holds the next chunk (or mAheadEnd / mError)
  bool mStop = false;
  bool mStarted = false;  ///< this pass asked for a chunk (mChunkSize is its size)
  bool mEnded = false;    ///< the inner source said it is at its end
  std::size_t mChunkSize = 0;
  ParticleChunk mAhead;
  bool mAheadOk = false;
  std::exception_ptr mError;
  std::thread mThread;
};

}  // namespace flipscope
