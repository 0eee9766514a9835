// PrefetchingSource: the inner source's chunks in its order, whatever the chunk size, over
// passes separated by rewinds; the inner source's errors reach the caller; and the next chunk
// is read before the caller asks for it.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "VectorSource.h"
#include "core/Error.h"
#include "preprocess/particles/PrefetchingSource.h"

namespace flipscope {
namespace {

std::vector<std::vector<glm::vec3>> chunksOf(ParticleSource& source, std::size_t size) {
  std::vector<std::vector<glm::vec3>> chunks;
  ParticleChunk chunk;
  while (source.read(chunk, size)) chunks.push_back(chunk.positions);
  EXPECT_TRUE(chunk.positions.empty());
  EXPECT_FALSE(source.read(chunk, size)) << "stays at its end";
  return chunks;
}

TEST(PrefetchingSource, GivesTheInnerSourcesChunksPassAfterPass) {
  const auto positions = testing::randomParticles(10007, 3);
  std::vector<glm::vec3> velocities(positions.size(), glm::vec3(1, 2, 3));
  testing::VectorSource plain(positions, velocities), inner(positions, velocities);
  PrefetchingSource ahead(inner);
  EXPECT_EQ(ahead.countHint(), plain.countHint());
  EXPECT_TRUE(ahead.hasVelocity());
  for (std::size_t size : {std::size_t(1000), std::size_t(1), std::size_t(4096), std::size_t(20000)}) {
    const auto expected = chunksOf(plain, size);
    EXPECT_EQ(chunksOf(ahead, size), expected) << "chunks of " << size;
    plain.rewind();
    ahead.rewind();
  }
  // A rewind in the middle of a pass starts over.
  ParticleChunk chunk;
  ASSERT_TRUE(ahead.read(chunk, 300));
  ASSERT_TRUE(ahead.read(chunk, 300));
  ahead.rewind();
  ASSERT_TRUE(ahead.read(chunk, 300));
  EXPECT_EQ(chunk.positions.front(), positions.front());
  EXPECT_EQ(chunk.velocities.size(), 300u);
}

/// Fails on its third read; each read takes `delay`.
class FailingSource : public testing::VectorSource {
 public:
  FailingSource(std::vector<glm::vec3> positions, std::chrono::milliseconds delay)
      : VectorSource(std::move(positions)), mDelay(delay) {}
  bool read(ParticleChunk& chunk, std::size_t maxParticles) override {
    std::this_thread::sleep_for(mDelay);
    if (++mReads == 3) throw FileError("broken.bin", "bad bytes at particle 200");
    return VectorSource::read(chunk, maxParticles);
  }
  std::atomic<int> mReads = 0;

 private:
  std::chrono::milliseconds mDelay;
};

TEST(PrefetchingSource, RandomAccessIsTheInnerSourcesAndKeepsTheChunkReadAhead) {
  const auto positions = testing::randomParticles(1000, 7);
  testing::VectorSource inner(positions);
  PrefetchingSource ahead(inner);
  const std::vector<std::uint64_t> some{3, 500, 999};
  std::vector<glm::vec3> picked;
  EXPECT_FALSE(ahead.readPositionsAt(some, picked)) << "the inner source declines";
  inner.seeks = true;
  ParticleChunk chunk;
  ASSERT_TRUE(ahead.read(chunk, 100));  // and the next chunk is in flight
  ASSERT_TRUE(ahead.readPositionsAt(some, picked));
  EXPECT_EQ(picked, (std::vector<glm::vec3>{positions[3], positions[500], positions[999]}));
  ASSERT_TRUE(ahead.readPositionRange(998, 2, picked));
  EXPECT_EQ(picked, (std::vector<glm::vec3>{positions[998], positions[999]}));
  ASSERT_TRUE(ahead.read(chunk, 100));
  EXPECT_EQ(chunk.positions.front(), positions[100]);
}

TEST(PrefetchingSource, TheInnerSourcesErrorReachesTheCaller) {
  FailingSource inner(testing::randomParticles(1000, 4), std::chrono::milliseconds(0));
  PrefetchingSource ahead(inner);
  ParticleChunk chunk;
  EXPECT_TRUE(ahead.read(chunk, 100));
  EXPECT_TRUE(ahead.read(chunk, 100));
  try {
    ahead.read(chunk, 100);
    FAIL() << "no error";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("broken.bin"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bad bytes at particle 200"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(ahead.read(chunk, 100)) << "ended after the error";
}

TEST(PrefetchingSource, ReadsTheNextChunkBeforeTheCallerAsksForIt) {
  FailingSource inner(testing::randomParticles(800, 5), std::chrono::milliseconds(0));
  inner.mReads = -100;  // never fails
  PrefetchingSource ahead(inner);
  ParticleChunk chunk;
  int chunks = 0;
  while (ahead.read(chunk, 100)) {
    ++chunks;
    // While the caller holds chunk k, the source's read of chunk k + 1 happens on its own.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (inner.mReads < -100 + chunks + 1 && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    EXPECT_EQ(inner.mReads, -100 + chunks + 1) << "after chunk " << chunks;
  }
  EXPECT_EQ(chunks, 8);
}

TEST(PrefetchingSource, AskingAnotherChunkSizeWithinAPassIsAProgrammingError) {
  testing::VectorSource inner(testing::randomParticles(1000, 6));
  PrefetchingSource ahead(inner);
  ParticleChunk chunk;
  ASSERT_TRUE(ahead.read(chunk, 100));
  EXPECT_ANY_THROW(ahead.read(chunk, 200));
}

}  // namespace
}  // namespace flipscope
