// The Streamer and its caches: results equal direct conversion, duplicates merge, stale work
// is cancelled, back-pressure holds, read-ahead fills the cache, and the cache never exceeds its
// budget, with concurrent requesters (run under ThreadSanitizer: tests/streaming/run-tsan.sh).
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <type_traits>
#include <thread>

#include "core/Error.h"
#include "streaming/BrickMipmap.h"
#include "streaming/Streamer.h"
#include "streaming/SyntheticBrickSource.h"

namespace flipscope {
namespace {

constexpr std::uint32_t kBrick = 32;
const glm::uvec3 kGrid(3, 3, 3);

StreamerOptions smallOptions() {
  StreamerOptions options;
  options.conversion = {kBrick, 2, AttributeReduction::Mean};
  options.mipDilation = 2;
  options.threads = 3;
  return options;
}

// What the Streamer must return for `key`: direct conversion of the source's neighbourhood.
ConvertedBrick expectedBrick(SyntheticBrickSource& source, const BrickKey& key, const StreamerOptions& options) {
  std::array<std::shared_ptr<const DecodedBrick>, 27> held;
  Neighbourhood<DecodedBrick> bricks{};
  for (int i = 0; i < 27; ++i) {
    glm::ivec3 c = glm::ivec3(key.coord) + glm::ivec3(i % 3 - 1, i / 3 % 3 - 1, i / 9 - 1);
    if (glm::all(glm::greaterThanEqual(c, glm::ivec3(0)))) held[i] = source.read({key.frame, glm::uvec3(c)});
    bricks[i] = held[i].get();
  }
  ConvertedBrick out;
  out.key = key;
  out.bits = convertBrick(bricks, options.conversion);
  out.mipmap = buildBrickMipmap(out.bits, options.mipDilation);
  return out;
}

std::vector<std::shared_ptr<const ConvertedBrick>> takeAll(Streamer& streamer) {
  streamer.waitIdle();
  return streamer.takeReady(1u << 20);
}

TEST(Streamer, DeliversEveryNonEmptyBrickLikeDirectConversion) {
  auto source = std::make_shared<SyntheticBrickSource>(kBrick, kGrid, 4, 0.3);
  StreamerOptions options = smallOptions();
  Streamer streamer(source, options);
  std::vector<glm::uvec3> coords = source->bricks(0);
  ASSERT_GT(coords.size(), 4u);
  ASSERT_LT(coords.size(), 27u);  // some bricks are above the surface
  EXPECT_EQ(streamer.request(coords), coords.size());
  auto ready = takeAll(streamer);
  EXPECT_EQ(ready.size(), coords.size());
  for (const auto& brick : ready) {
    ConvertedBrick expected = expectedBrick(*source, brick->key, options);
    EXPECT_EQ(brick->bits, expected.bits);
    EXPECT_EQ(brick->mipmap, expected.mipmap);
  }
  EXPECT_EQ(streamer.stats().failed, 0u) << streamer.lastError();
}

// A source whose reads throw `Error`: what a damaged frame file (FileError) or a bug
// (LogicError) looks like from a worker thread.
template <class Error>
class ThrowingSource final : public SyntheticBrickSource {
 public:
  using SyntheticBrickSource::SyntheticBrickSource;
  std::shared_ptr<const DecodedBrick> read(const BrickKey&) override {
    if constexpr (std::is_same_v<Error, FileError>) throw FileError("frame_0000.fsf", "brick read failed");
    else throw Error("brick read failed");
  }
};

template <class Error>
void expectFailureKeepsItsType() {
  auto source = std::make_shared<ThrowingSource<Error>>(kBrick, kGrid, 4, 0.3);
  Streamer streamer(source, smallOptions());
  EXPECT_NO_THROW(streamer.rethrowLastError());  // nothing failed yet
  streamer.request(source->bricks(0));
  takeAll(streamer);
  EXPECT_GT(streamer.stats().failed, 0u);
  EXPECT_NE(streamer.lastError().find("brick read failed"), std::string::npos);
  EXPECT_THROW(streamer.rethrowLastError(), Error);
}

TEST(Streamer, WorkerFailuresKeepTheirType) {
  expectFailureKeepsItsType<FileError>();  // exit 3 in the tools
  expectFailureKeepsItsType<LogicError>();  // exit 1: a bug stays a bug
}

TEST(Streamer, MergesDuplicateRequests) {
  auto source = std::make_shared<SyntheticBrickSource>(kBrick, kGrid, 4, 0.3);
  Streamer streamer(source, smallOptions());
  std::vector<glm::uvec3> coords = source->bricks(0);
  streamer.request(coords);
  EXPECT_EQ(streamer.request(coords), 0u);  // pending, in flight or ready: all merged
  auto ready = takeAll(streamer);
  EXPECT_EQ(ready.size(), coords.size());
  EXPECT_EQ(streamer.stats().merged, coords.size());
  EXPECT_EQ(streamer.stats().converted, coords.size());
}

TEST(Streamer, OrdersFrontToBack) {
  auto source = std::make_shared<SyntheticBrickSource>(kBrick, kGrid, 4, 0.3);
  StreamerOptions options = smallOptions();
  options.threads = 1;
  Streamer streamer(source, options);
  glm::dvec3 eye(3.5, -2.0, 1.0);
  streamer.setEye(eye);
  streamer.request(source->bricks(0));
  auto ready = takeAll(streamer);
  ASSERT_GT(ready.size(), 4u);
  // The single worker may take the first request before the rest arrive; after it, order holds.
  for (std::size_t i = 2; i < ready.size(); ++i) {
    auto distance = [&](const auto& b) { return glm::length(glm::dvec3(b->key.coord) + 0.5 - eye); };
    EXPECT_LE(distance(ready[i - 1]), distance(ready[i]) + 1e-9);
  }
}

TEST(Streamer, CancelsStaleRequestsWhenTheFrameChanges) {
  auto source = std::make_shared<SyntheticBrickSource>(kBrick, kGrid, 4, 0.3);
  StreamerOptions options = smallOptions();
  options.threads = 1;
  options.maxReady = 1;  // the worker stops after one brick: the rest stays pending
  Streamer streamer(source, options);
  std::vector<glm::uvec3> frame0 = source->bricks(0);
  streamer.request(frame0);
  streamer.waitIdle();
  streamer.setFrame(1);
  EXPECT_GE(streamer.stats().cancelled, frame0.size() - 2);
  EXPECT_TRUE(streamer.takeReady(100).empty());  // the frame-0 brick was dropped
  std::vector<glm::uvec3> frame1 = source->bricks(1);
  streamer.request(frame1);
  std::size_t received = 0;
  while (received < frame1.size()) {
    streamer.waitIdle();
    for (const auto& brick : streamer.takeReady(1)) {
      EXPECT_EQ(brick->key.frame, 1);
      ++received;
    }
  }
}

TEST(Streamer, BackPressureStopsWorkUntilTheConsumerTakes) {
  auto source = std::make_shared<SyntheticBrickSource>(kBrick, kGrid, 4, 0.3);
  StreamerOptions options = smallOptions();
  options.maxReady = 3;
  Streamer streamer(source, options);
  std::vector<glm::uvec3> coords = source->bricks(0);
  streamer.request(coords);
  streamer.waitIdle();
  // In-flight jobs may finish past the limit, one per worker at most.
  EXPECT_LE(streamer.stats().converted, 3u + options.threads);
  std::size_t received = 0;
  while (received < coords.size()) {
    streamer.waitIdle();
    received += streamer.takeReady(2).size();
  }
  EXPECT_EQ(received, coords.size());
}

TEST(Streamer, ReadAheadFillsTheCacheInThePlayingDirection) {
  auto source = std::make_shared<SyntheticBrickSource>(kBrick, kGrid, 6, 0.3);
  StreamerOptions options = smallOptions();
  options.readAheadFrames = 2;
  Streamer streamer(source, options);
  streamer.setFrame(3, -1);
  std::vector<glm::uvec3> coords = source->bricks(3);
  streamer.request(coords);
  takeAll(streamer);
  std::size_t checked = 0;
  for (glm::uvec3 c : coords) {
    if (!source->read({2, c})) continue;
    EXPECT_TRUE(streamer.cache().contains({2, c}));
    EXPECT_FALSE(streamer.cache().contains({4, c}));
    ++checked;
  }
  EXPECT_GT(checked, 0u) << "frame 2 shares no brick with frame 3: nothing was checked";
  streamer.setFrame(2, -1);
  streamer.request(coords);
  takeAll(streamer);
  StreamerStats stats = streamer.stats();
  EXPECT_GT(stats.deliveredFromCache, 0u);
  EXPECT_EQ(stats.failed, 0u);
}

TEST(Streamer, ConcurrentScrubbingWithEvictionStaysCorrectAndWithinBudget) {
  auto source = std::make_shared<SyntheticBrickSource>(kBrick, kGrid, 5, 0.3);
  StreamerOptions options = smallOptions();
  options.threads = 4;
  options.cacheBytes = 300 * 1024;  // a few bricks: constant eviction
  options.neighbourCacheBytes = 200 * 1024;
  options.compressCache = true;
  options.readAheadFrames = 1;
  Streamer streamer(source, options);
  std::atomic<bool> done{false};
  std::atomic<std::size_t> overBudget{0};
  std::thread monitor([&] {
    while (!done) overBudget += streamer.cache().bytes() > streamer.cache().budget();
  });
  std::thread consumer([&] {
    while (!done) {
      for (const auto& brick : streamer.takeReady(4)) EXPECT_EQ(brick->bits.brickSize, kBrick);
      std::this_thread::yield();
    }
  });
  std::vector<std::thread> requesters;
  for (int t = 0; t < 2; ++t)
    requesters.emplace_back([&, t] {
      for (int step = 0; step < 12; ++step) {
        int frame = (step + t) % 5;
        streamer.setFrame(frame, t == 0 ? 1 : -1);
        streamer.request(source->bricks(frame));
      }
    });
  for (auto& r : requesters) r.join();
  streamer.setFrame(2, 0);
  std::vector<glm::uvec3> last = source->bricks(2);
  streamer.request(last);
  streamer.waitIdle();
  done = true;
  consumer.join();
  monitor.join();
  EXPECT_EQ(overBudget.load(), 0u);
  EXPECT_GT(streamer.cache().stats().evictions, 0u);
  EXPECT_EQ(streamer.stats().failed, 0u) << streamer.lastError();
  // After the dust settles, the final frame's bricks come back right.
  streamer.request(last);
  std::size_t checked = 0;
  for (const auto& brick : takeAll(streamer)) {
    EXPECT_EQ(brick->key.frame, 2);
    EXPECT_EQ(brick->bits, expectedBrick(*source, brick->key, options).bits);
    ++checked;
  }
  EXPECT_GT(checked, 0u) << "nothing was delivered for the final frame";
}

TEST(ConvertedBrickCache, NeverAboveBudgetAndEvictsLeastRecentlyUsed) {
  auto source = std::make_shared<SyntheticBrickSource>(kBrick, kGrid, 3, 0.3);
  StreamerOptions options = smallOptions();
  std::vector<std::shared_ptr<const ConvertedBrick>> bricks;
  for (glm::uvec3 c : source->bricks(0))
    bricks.push_back(std::make_shared<ConvertedBrick>(expectedBrick(*source, {0, c}, options)));
  ASSERT_GE(bricks.size(), 4u);
  const std::size_t each = bricks[0]->bytes();
  ConvertedBrickCache cache(each * 3, false);
  for (const auto& b : bricks) {
    cache.insert(b);
    EXPECT_LE(cache.bytes(), cache.budget());
    cache.find(bricks[0]->key);  // keep the first one hot
  }
  EXPECT_TRUE(cache.contains(bricks[0]->key));
  EXPECT_FALSE(cache.contains(bricks[1]->key));
  EXPECT_TRUE(cache.contains(bricks.back()->key));
  EXPECT_GT(cache.stats().evictions, 0u);
}

TEST(ConvertedBrickCache, CompressedEntriesRoundTrip) {
  auto source = std::make_shared<SyntheticBrickSource>(kBrick, kGrid, 3, 0.3);
  StreamerOptions options = smallOptions();
  ConvertedBrickCache cache(1 << 24, true);
  std::vector<glm::uvec3> coords = source->bricks(1);
  for (glm::uvec3 c : coords) cache.insert(std::make_shared<ConvertedBrick>(expectedBrick(*source, {1, c}, options)));
  for (glm::uvec3 c : coords) {
    auto found = cache.find({1, c});
    ASSERT_NE(found, nullptr);
    ConvertedBrick expected = expectedBrick(*source, {1, c}, options);
    EXPECT_EQ(found->key, expected.key);
    EXPECT_EQ(found->bits, expected.bits);
    EXPECT_EQ(found->mipmap, expected.mipmap);
  }
  EXPECT_EQ(cache.find({0, coords[0]}), nullptr);
}

}  // namespace
}  // namespace flipscope
