// PointSpanSource: a ParticleSource over positions held in memory (no velocities), for callers
// that have the points already: the spacing estimate over points, benchmarks' analytic scenes.
// The points must outlive the source.
#pragma once

#include <algorithm>
#include <cstddef>
#include <span>
#include <string>
#include <utility>

#include <glm/vec3.hpp>

#include "preprocess/particles/ParticleSource.h"

namespace flipscope {

class PointSpanSource final : public ParticleSource {
 public:
  explicit PointSpanSource(std::span<const glm::vec3> points, std::string name = "points in memory")
      : mPoints(points), mName(std::move(name)) {}
  std::string name() const override { return mName; }
  std::string format() const override { return "particles in memory"; }
  bool hasVelocity() const override { return false; }
  std::optional<std::uint64_t> countHint() const override { return mPoints.size(); }
  bool read(ParticleChunk& chunk, std::size_t maxParticles) override {
    chunk.clear();
    const std::size_t n = std::min(maxParticles, mPoints.size() - mNext);
    chunk.positions.assign(mPoints.begin() + std::ptrdiff_t(mNext), mPoints.begin() + std::ptrdiff_t(mNext + n));
    mNext += n;
    return n > 0;
  }
  void rewind() override { mNext = 0; }

 private:
  std::span<const glm::vec3> mPoints;
  std::string mName;
  std::size_t mNext = 0;
};

}  // namespace flipscope
