// readPositionRangesInParallel: every particle of a file read once, by ranges on several threads,
// with the range's first particle; sources that read only in order are left unread.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
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

// Binary PLY without and with velocities (records of 12 and 24 bytes), a count that is no
// multiple of the range.
TEST(PositionRanges, ReadEveryParticleOnceWithItsRangesFirstParticle) {
  TempDir dir("ranges");
  const std::size_t n = 3 * kPositionRangeParticles + 123;
  for (const bool velocity : {false, true}) {
    const ParticleChunk particles = randomParticles(n, velocity, velocity ? 8u : 7u);
    const auto path = dir / (velocity ? "v.ply" : "p.ply");
    testing::writeFile(path, particles, WriteOptions{});
    auto source = openParticleFile(path);
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
    // The next read() is where it was: at the first particle.
    ParticleChunk chunk;
    ASSERT_TRUE(source->read(chunk, 5));
    EXPECT_TRUE(sameBits(chunk.positions[0], particles.positions[0])) << path;
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
        *source, [&](std::span<const glm::vec3> positions, std::uint64_t) { visited += positions.size(); });
    EXPECT_EQ(read, source == &seeking);
    EXPECT_EQ(visited, read ? positions.size() : 0u);
    EXPECT_EQ(source->particlesInRanges, read ? positions.size() : 0u);
    EXPECT_EQ(source->particlesRead, 0u);
  }
}

}  // namespace
}  // namespace flipscope
