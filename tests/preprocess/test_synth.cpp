// SynthFluid: determinism, counts, body density, coherence over frames, velocities.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <tuple>
#include <vector>

#include <glm/geometric.hpp>

#include "core/Error.h"
#include "preprocess/SynthFluid.h"

namespace flipscope {
namespace {

struct Frame {
  std::vector<glm::vec3> positions, velocities;
};

Frame readAll(SynthFluid& source, std::size_t chunkSize) {
  Frame frame;
  ParticleChunk chunk;
  while (source.read(chunk, chunkSize)) {
    EXPECT_LE(chunk.size(), chunkSize);
    EXPECT_EQ(chunk.velocities.size(), source.hasVelocity() ? chunk.size() : 0u);
    frame.positions.insert(frame.positions.end(), chunk.positions.begin(), chunk.positions.end());
    frame.velocities.insert(frame.velocities.end(), chunk.velocities.begin(), chunk.velocities.end());
  }
  EXPECT_EQ(chunk.size(), 0u);
  return frame;
}

Frame generate(SynthOptions options, std::size_t chunkSize = 1 << 16) {
  SynthFluid source(options);
  return readAll(source, chunkSize);
}

bool identical(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin());
}

SynthOptions options(std::uint64_t particles, std::uint64_t seed = 7, int frame = 3) {
  SynthOptions o;
  o.particles = particles;
  o.seed = seed;
  o.frame = frame;
  return o;
}

/// Difference of two positions of one particle, undoing the periodic wrap in x and z.
glm::dvec3 periodicDelta(glm::vec3 a, glm::vec3 b, const Box& domain) {
  glm::dvec3 d = glm::dvec3(b) - glm::dvec3(a), extent = domain.extent();
  d.x -= extent.x * std::round(d.x / extent.x);
  d.z -= extent.z * std::round(d.z / extent.z);
  return d;
}

TEST(SynthFluid, SameSeedGivesIdenticalParticlesAndOtherSeedsDiffer) {
  Frame a = generate(options(20'000, 7)), b = generate(options(20'000, 7)), c = generate(options(20'000, 8));
  EXPECT_TRUE(identical(a.positions, b.positions));
  EXPECT_TRUE(identical(a.velocities, b.velocities));
  ASSERT_EQ(a.positions.size(), c.positions.size());
  std::size_t differing = 0;
  for (std::size_t i = 0; i < a.positions.size(); ++i) differing += a.positions[i] != c.positions[i];
  EXPECT_GT(differing, a.positions.size() * 9 / 10);
}

TEST(SynthFluid, ChunkSizeDoesNotChangeTheStream) {
  Frame reference = generate(options(20'000), 1 << 16);
  for (std::size_t chunkSize : {std::size_t(1), std::size_t(997), std::size_t(4096), std::size_t(5000)}) {
    Frame f = generate(options(20'000), chunkSize);
    EXPECT_TRUE(identical(reference.positions, f.positions)) << "chunk " << chunkSize;
    EXPECT_TRUE(identical(reference.velocities, f.velocities)) << "chunk " << chunkSize;
  }
}

TEST(SynthFluid, RandomAccessMatchesTheStream) {
  SynthFluid source(options(30'000, 11));
  Frame stream = readAll(source, 1 << 16);
  ASSERT_EQ(stream.positions.size(), source.count());
  std::uint64_t h = 12345;
  for (int trial = 0; trial < 500; ++trial) {
    h = h * 6364136223846793005ull + 1442695040888963407ull;
    std::uint64_t i = (h >> 17) % source.count();
    glm::vec3 p, v;
    source.particle(i, p, &v);
    EXPECT_EQ(p, stream.positions[i]) << i;
    EXPECT_EQ(v, stream.velocities[i]) << i;
  }
}

TEST(SynthFluid, RewindRestartsTheStream) {
  SynthFluid source(options(10'000));
  ParticleChunk chunk;
  ASSERT_TRUE(source.read(chunk, 3000));
  std::vector<glm::vec3> first = chunk.positions;
  ASSERT_TRUE(source.read(chunk, 3000));
  EXPECT_FALSE(identical(first, chunk.positions));
  source.rewind();
  Frame all = readAll(source, 3000);
  ASSERT_EQ(all.positions.size(), source.count());
  EXPECT_TRUE(std::equal(first.begin(), first.end(), all.positions.begin()));
}

TEST(SynthFluid, VelocitiesAreOptional) {
  SynthOptions o = options(5'000);
  o.velocity = false;
  SynthFluid source(o);
  EXPECT_FALSE(source.hasVelocity());
  Frame f = readAll(source, 1000);
  EXPECT_TRUE(f.velocities.empty());
  EXPECT_TRUE(identical(f.positions, generate(options(5'000)).positions));
}

TEST(SynthFluid, CountIsExactAndWithinFivePercentOfTheTarget) {
  for (std::uint64_t target : {1'000ull, 1'234ull, 100'000ull, 2'000'000ull, 1'000'000'000ull}) {
    SynthFluid source(options(target));
    EXPECT_NEAR(double(source.count()), double(target), 0.05 * double(target)) << target;
    EXPECT_EQ(source.countHint(), source.count());
    EXPECT_EQ(source.bodyCount() + source.sheetCount() + source.sprayCount(), source.count());
    EXPECT_GT(source.sheetCount(), 0u);
    EXPECT_GT(source.sprayCount(), 0u);
    if (target <= 2'000'000) {
      EXPECT_EQ(generate(options(target)).positions.size(), source.count()) << target;
    }
  }
}

TEST(SynthFluid, BadOptionsAreRejectedByName) {
  auto message = [](SynthOptions o) {
    try {
      SynthFluid source(o);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message(options(999)).find("particles"), std::string::npos);
  SynthOptions o = options(1000);
  o.sprayFraction = 0.6;
  EXPECT_NE(message(o).find("fraction"), std::string::npos);
  o = options(1000);
  o.frameTime = 0;
  EXPECT_NE(message(o).find("frame time"), std::string::npos);
}

TEST(SynthFluid, AllParticlesFiniteAndInsideTheDomain) {
  for (double size : {1.0, 25.0}) {
    for (int frame : {0, 17, 240}) {
      SynthOptions o = options(50'000, 5, frame);
      o.size = size;
      SynthFluid source(o);
      Frame f = readAll(source, 1 << 16);
      Box domain = source.domain();
      for (std::size_t i = 0; i < f.positions.size(); ++i) {
        glm::vec3 p = f.positions[i], v = f.velocities[i];
        ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) << i;
        ASSERT_TRUE(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z)) << i;
        ASSERT_TRUE(domain.contains(glm::dvec3(p))) << "particle " << i << " frame " << frame << " size " << size;
      }
    }
  }
}

TEST(SynthFluid, BodyHasAboutEightParticlesPerInteriorCell) {
  for (std::uint64_t seed : {1, 2}) {
    SynthFluid source(options(100'000, seed, 5));
    Frame f = readAll(source, 1 << 16);
    const double cell = source.cellSize();
    const Box domain = source.domain();
    std::map<std::tuple<int, int, int>, int> cells;
    for (std::uint64_t i = 0; i < source.bodyCount(); ++i) {
      glm::dvec3 c = glm::floor(glm::dvec3(f.positions[i]) / cell);
      ++cells[{int(c.x), int(c.y), int(c.z)}];
    }
    // Interior: whole cells, at least one cell from the floor and two below the lowest trough.
    int nx = int(domain.extent().x / cell), nz = int(domain.extent().z / cell);
    int topInterior = int(0.2 / cell) - 3;
    ASSERT_GE(topInterior, 2);
    std::vector<int> occupancy;
    for (int x = 0; x < nx; ++x)
      for (int z = 0; z < nz; ++z)
        for (int y = 1; y < topInterior; ++y) {
          auto it = cells.find({x, y, z});
          occupancy.push_back(it == cells.end() ? 0 : it->second);
        }
    ASSERT_GT(occupancy.size(), 1000u);
    std::nth_element(occupancy.begin(), occupancy.begin() + occupancy.size() / 2, occupancy.end());
    int median = occupancy[occupancy.size() / 2];
    EXPECT_GE(median, 6);
    EXPECT_LE(median, 10);
  }
}

TEST(SynthFluid, ConsecutiveFramesDifferByMotionsSmallerThanACell) {
  SynthFluid now(options(100'000, 3, 40)), next(options(100'000, 3, 41));
  Frame a = readAll(now, 1 << 16), b = readAll(next, 1 << 16);
  ASSERT_EQ(a.positions.size(), b.positions.size());
  const Box domain = now.domain();
  const double cell = now.cellSize();
  // The same index is the same particle: body particles move less than a cell a frame.
  double sum = 0, largest = 0;
  for (std::uint64_t i = 0; i < now.bodyCount(); ++i) {
    double d = glm::length(periodicDelta(a.positions[i], b.positions[i], domain));
    sum += d;
    largest = std::max(largest, d);
  }
  double mean = sum / double(now.bodyCount());
  EXPECT_GT(mean, 0.02 * cell);
  EXPECT_LT(mean, 0.5 * cell);
  EXPECT_LT(largest, cell);
  // The surface: the highest body particle of each cell column rises or falls less than a cell.
  std::map<std::pair<int, int>, std::pair<float, float>> top;
  for (std::uint64_t i = 0; i < now.bodyCount(); ++i) {
    for (int k = 0; k < 2; ++k) {
      glm::vec3 p = (k ? b : a).positions[i];
      auto& t = top.try_emplace({int(p.x / cell), int(p.z / cell)}, -1.f, -1.f).first->second;
      (k ? t.second : t.first) = std::max(k ? t.second : t.first, p.y);
    }
  }
  double change = 0;
  for (auto& [column, heights] : top) change += std::abs(heights.second - heights.first);
  EXPECT_LT(change / double(top.size()), cell);
  EXPECT_GT(change / double(top.size()), 0.01 * cell);
}

TEST(SynthFluid, DisplacementOverAFrameMatchesTheVelocities) {
  for (double size : {1.0, 9.0}) {
    SynthOptions o = options(50'000, 9, 100);
    o.size = size;
    SynthFluid now(o);
    o.frame += 1;
    SynthFluid next(o);
    Frame a = readAll(now, 1 << 16), b = readAll(next, 1 << 16);
    const double dt = now.frameTime();
    const Box domain = now.domain();
    // Trapezoid rule: exact for ballistic spray and translating sheets, O(dt^3) for the waves.
    auto error = [&](std::uint64_t i) {
      glm::dvec3 predicted = 0.5 * dt * (glm::dvec3(a.velocities[i]) + glm::dvec3(b.velocities[i]));
      return glm::length(periodicDelta(a.positions[i], b.positions[i], domain) - predicted);
    };
    double bodyError = 0, bodyMotion = 0;
    for (std::uint64_t i = 0; i < now.bodyCount(); ++i) {
      bodyError += error(i);
      bodyMotion += glm::length(periodicDelta(a.positions[i], b.positions[i], domain));
    }
    EXPECT_LT(bodyError, 0.05 * bodyMotion) << "size " << size;
    const double tolerance = 1e-3 * now.cellSize();
    std::uint64_t sheetEnd = now.bodyCount() + now.sheetCount();
    for (std::uint64_t i = now.bodyCount(); i < sheetEnd; ++i) ASSERT_LT(error(i), tolerance) << "sheet " << i;
    // Droplets that landed and relaunched between the frames jump; the rest fly ballistically.
    std::uint64_t ballistic = 0;
    for (std::uint64_t i = sheetEnd; i < now.count(); ++i) ballistic += error(i) < tolerance;
    double relaunched = dt / now.shortestSprayLife();
    EXPECT_GT(double(ballistic), (0.95 - relaunched) * double(now.sprayCount())) << "size " << size;
    EXPECT_LT(double(ballistic), double(now.sprayCount()));
  }
}

}  // namespace
}  // namespace flipscope
