// DelayedBrickSource: another source's bricks, each read() waiting a fixed delay first: how the
// viewer behaves on storage slower than the machine it runs on (`view --read-delay-ms`), which
// its tests use to make brick conversion reliably slower than a displayed frame.
#pragma once

#include <chrono>
#include <memory>
#include <thread>

#include "streaming/BrickSource.h"

namespace flipscope {

class DelayedBrickSource : public BrickSource {
 public:
  DelayedBrickSource(std::shared_ptr<BrickSource> inner, std::chrono::milliseconds delay)
      : mInner(std::move(inner)), mDelay(delay) {}
  const StoreHeader& header() const override { return mInner->header(); }
  std::vector<int> frames() const override { return mInner->frames(); }
  bool hasFrame(int frame) const override { return mInner->hasFrame(frame); }
  std::shared_ptr<const FrameIndex> frame(int frame) const override { return mInner->frame(frame); }
  std::shared_ptr<const DecodedBrick> read(const BrickKey& key) override {
    std::this_thread::sleep_for(mDelay);
    return mInner->read(key);
  }
  bool carriesAttributes() const override { return mInner->carriesAttributes(); }
  std::string name() const override { return mInner->name(); }

 private:
  std::shared_ptr<BrickSource> mInner;
  std::chrono::milliseconds mDelay;
};

}  // namespace flipscope
