// An in-memory ParticleSource for tests.
#pragma once

#include <atomic>
#include <random>
#include <stdexcept>

#include <glm/common.hpp>

#include "preprocess/particles/ParticleSource.h"

namespace flipscope::testing {

class VectorSource : public ParticleSource {
 public:
  VectorSource(std::vector<glm::vec3> positions, std::vector<glm::vec3> velocities = {})
      : mPositions(std::move(positions)), mVelocities(std::move(velocities)) {}
  std::string name() const override { return "memory"; }
  std::string format() const override { return "particles in memory"; }
  bool hasVelocity() const override { return !mVelocities.empty(); }
  std::optional<std::uint64_t> countHint() const override {
    if (!hintsCount) return std::nullopt;
    return wrongCount.value_or(mPositions.size());
  }
  bool hintsCount = true;  ///< whether countHint() gives the count
  std::optional<std::uint64_t> wrongCount;  ///< what countHint() gives instead (a header that lies)
  bool read(ParticleChunk& chunk, std::size_t maxParticles) override {
    chunk.clear();
    const std::size_t n = std::min(maxParticles, mPositions.size() - mNext);
    chunk.positions.assign(mPositions.begin() + mNext, mPositions.begin() + mNext + n);
    if (!mVelocities.empty()) chunk.velocities.assign(mVelocities.begin() + mNext, mVelocities.begin() + mNext + n);
    mNext += n;
    particlesRead += n;
    return n > 0;
  }
  void rewind() override { mNext = 0; }
  bool seeks = false;  ///< whether readPositionsAt() and readPositionRange() read (else they decline, like a decoder)
  std::uint64_t particlesRead = 0;                  ///< by read()
  std::atomic<std::uint64_t> particlesInRanges{0};  ///< by readPositionRange()
  bool readPositionsAt(std::span<const std::uint64_t> indices, std::vector<glm::vec3>& positions) override {
    if (!seeks) return false;
    positions.clear();
    for (std::uint64_t i : indices) positions.push_back(mPositions.at(i));
    return true;
  }
  bool readPositionRange(std::uint64_t first, std::size_t count, std::vector<glm::vec3>& positions) override {
    if (!seeks) return false;
    if (first + count > mPositions.size()) throw std::out_of_range("range beyond the particles");
    positions.assign(mPositions.begin() + std::ptrdiff_t(first), mPositions.begin() + std::ptrdiff_t(first + count));
    particlesInRanges += count;
    return true;
  }

 private:
  std::vector<glm::vec3> mPositions, mVelocities;
  std::size_t mNext = 0;
};

/// Clustered random particles: a few dense blobs plus sparse spray, in [0, extent)^3.
inline std::vector<glm::vec3> randomParticles(std::size_t n, std::uint32_t seed, float extent = 10.0f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uniform(0.0f, extent);
  std::normal_distribution<float> normal(0.0f, extent * 0.05f);
  std::vector<glm::vec3> centres;
  for (int i = 0; i < 4; ++i) centres.push_back({uniform(rng), uniform(rng), uniform(rng)});
  std::vector<glm::vec3> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (i % 5 == 0) {
      out[i] = {uniform(rng), uniform(rng), uniform(rng)};
    } else {
      glm::vec3 c = centres[i % centres.size()];
      out[i] = glm::clamp(c + glm::vec3(normal(rng), normal(rng), normal(rng)), glm::vec3(0), glm::vec3(extent * 0.999f));
    }
  }
  return out;
}

}  // namespace flipscope::testing
