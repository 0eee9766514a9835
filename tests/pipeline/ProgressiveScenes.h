// Progressive rendering test helpers: a brick source whose reads wait at a gate the test opens,
// so a test controls when conversion finishes, and a loop that advances a frame to the end.
#pragma once

#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>

#include "pipeline/FramePipeline.h"
#include "streaming/SyntheticBrickSource.h"

namespace flipscope::testing {

/// SyntheticBrickSource whose read() blocks while the gate is closed (open by default).
class GatedBrickSource : public BrickSource {
 public:
  GatedBrickSource() : mInner(32, glm::uvec3(4, 4, 2), 3, 0.3) {}
  const StoreHeader& header() const override { return mInner.header(); }
  std::vector<int> frames() const override { return mInner.frames(); }
  bool hasFrame(int frame) const override { return mInner.hasFrame(frame); }
  std::shared_ptr<const FrameIndex> frame(int frame) const override { return mInner.frame(frame); }
  std::string name() const override { return "gated " + mInner.name(); }
  std::shared_ptr<const DecodedBrick> read(const BrickKey& key) override {
    std::unique_lock lock(mMutex);
    mOpened.wait(lock, [&] { return mOpen; });
    lock.unlock();
    return mInner.read(key);
  }
  void setOpen(bool open) {
    {
      std::lock_guard lock(mMutex);
      mOpen = open;
    }
    mOpened.notify_all();
  }
  /// A camera looking down at the tank's water from above one side.
  static Camera camera() {
    Camera c;
    c.eye = glm::dvec3(0.9, -0.9, 0.9);
    c.target = glm::dvec3(0, 0, 0.2);
    c.up = glm::dvec3(0, 0, 1);
    c.fovYDegrees = 45;
    return c;
  }
  static RenderSettings settings() {
    RenderSettings s;
    s.width = 96;
    s.height = 64;
    s.radius = 1.5f;
    s.threads = 2;
    return s;
  }

 private:
  SyntheticBrickSource mInner;
  std::mutex mMutex;
  std::condition_variable mOpened;
  bool mOpen = true;
};

/// Advances the begun frame until it finishes; returns the calls made. A slice that changed
/// nothing (its bricks still converting) is followed by a millisecond's sleep, and the limit is
/// one of time, not of calls: under the sanitizers, on a loaded machine, conversion is slow and
/// a bound on calls gave up on a frame that was still streaming. Not finishing is a failure.
inline int advanceToEnd(FramePipeline& pipeline, std::chrono::seconds limit = std::chrono::seconds(300)) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  int calls = 0;
  while (!pipeline.finished() && std::chrono::steady_clock::now() < deadline) {
    if (!pipeline.advance(5.0).changed) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ++calls;
  }
  EXPECT_TRUE(pipeline.finished()) << "the frame did not finish in " << limit.count() << " s (" << calls << " slices)";
  return calls;
}

}  // namespace flipscope::testing
