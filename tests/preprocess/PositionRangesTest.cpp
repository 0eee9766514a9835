// readPositionRangesInParallel: every particle of a file read once, by ranges on several threads,
// with the range's first particle; sources that read only in order are left unread.
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

#include "ParticleTestSupport.h"
#include "VectorSource.h"
#include "preprocess/PositionRanges.h"
#include "preprocess/particles/ParticleFormatRegistry.h"

namespace flipscope {
namespace {

using testing::randomParticles;
using testing::sameBits;
using testing::TempDir;
using testing::VectorSource;

// Both readers that read ranges: binary PLY without and with velocities (records of 12 and 24
// bytes) and raw floats; a count that is no multiple of the range.
TEST(PositionRanges, ReadEveryParticleOnceWithItsRangesFirstParticle) {
  TempDir dir("ranges");
  const std::size_t n = 3 * kPositionRangeParticles + 123;
  for (const char* name : {"p.ply", "v.ply", "r.raw"}) {
    const bool velocity = std::string(name) == "v.ply";
    const ParticleChunk particles = randomParticles(n, velocity, velocity ? 8u : 7u);
    const auto path = dir / name;
    testing::writeFile(path, particles, WriteOptions{});
    auto source = openParticleFile(path);
    ParticleChunk chunk;
    ASSERT_TRUE(source->read(chunk, 5));  // the ranges leave the next read() at particle 5
    std::vector<glm::vec3> seen(n, glm::vec3(std::numeric_limits<float>::quiet_NaN()));
    std::vector<int> visits(4, 0);
    std::mutex mutex;
    Progress progress("ranges", n, "particles", Progress::Mode::Silent);
    const bool read = readPositionRangesInParallel(
        *source,
        [&](std::span<const glm::vec3> positions, std::uint64_t first) {
          ASSERT_EQ(first % kPositionRangeParticles, 0u);
          ASSERT_EQ(positions.size(), std::min<std::uint64_t>(kPositionRangeParticles, n - first));
          std::lock_guard lock(mutex);
          ++visits[first / kPositionRangeParticles];
          std::copy(positions.begin(), positions.end(), seen.begin() + std::ptrdiff_t(first));
        },
        &progress);
    ASSERT_TRUE(read) << path;
    EXPECT_EQ(visits, std::vector<int>(4, 1)) << path;
    EXPECT_EQ(progress.done(), n) << path;
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < n; ++i) wrong += !sameBits(seen[i], particles.positions[i]);
    EXPECT_EQ(wrong, 0u) << path;
    ASSERT_TRUE(source->read(chunk, 5));
    EXPECT_TRUE(sameBits(chunk.positions[0], particles.positions[5])) << path;
  }
}

TEST(PositionRanges, ASourceThatReadsOnlyInOrderOrHasNoCountIsNotRead) {
  const std::vector<glm::vec3> positions = testing::randomParticles(1000, 9u);
  VectorSource inOrder(positions);
  VectorSource uncounted(positions);
  uncounted.seeks = true;
  uncounted.hintsCount = false;
  VectorSource seeking(positions);
  seeking.seeks = true;
  for (VectorSource* source : {&inOrder, &uncounted, &seeking}) {
    std::atomic<std::uint64_t> visited{0};
    const bool read = readPositionRangesInParallel(
        *source, [&](std::span<const glm::vec3> range, std::uint64_t) { visited += range.size(); });
    EXPECT_EQ(read, source == &seeking);
    EXPECT_EQ(visited, read ? positions.size() : 0u);
    EXPECT_EQ(source->particlesInRanges, read ? positions.size() : 0u);
    EXPECT_EQ(source->particlesRead, 0u);
  }
}

// A visit that runs parallel work of its own (as finiteBounds does) finds its range's positions
// unchanged when that work is done: the thread that waits for it takes no other range meanwhile.
// Eight threads, and nested tasks slow enough to be stolen, so that a waiting thread would (it
// did, in most runs, before readPositionRangesInParallel isolated its ranges).
TEST(PositionRanges, ARangeStaysAsReadWhileItsVisitRunsParallelWork) {
  const std::size_t ranges = 24, n = ranges * kPositionRangeParticles;
  std::vector<glm::vec3> positions(n);
  for (std::size_t i = 0; i < n; ++i) positions[i] = glm::vec3(float(i), float(i % 7), -float(i));
  VectorSource source(positions);
  source.seeks = true;
  std::atomic<int> changed{0}, visits{0};
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 8);
  tbb::task_arena arena(8);
  for (int round = 0; round < 4; ++round)
    arena.execute([&] {
      ASSERT_TRUE(readPositionRangesInParallel(source, [&](std::span<const glm::vec3> range, std::uint64_t first) {
        tbb::parallel_for(0, 8, [](int) { std::this_thread::sleep_for(std::chrono::milliseconds(2)); });
        const bool same = range.front() == positions[first] && range.back() == positions[first + range.size() - 1] &&
                          std::equal(range.begin(), range.end(), positions.begin() + std::ptrdiff_t(first));
        changed += !same;
        ++visits;
      }));
    });
  EXPECT_EQ(visits, 4 * int(ranges));
  EXPECT_EQ(changed, 0);
}

TEST(PositionRanges, AnEmptyFileHasNoRange) {
  TempDir dir("ranges-empty");
  testing::writeFile(dir / "e.ply", ParticleChunk{}, WriteOptions{});
  auto source = openParticleFile(dir / "e.ply");
  int visits = 0;
  EXPECT_TRUE(readPositionRangesInParallel(*source, [&](std::span<const glm::vec3>, std::uint64_t) { ++visits; }));
  EXPECT_EQ(visits, 0);
}

}  // namespace
}  // namespace flipscope
