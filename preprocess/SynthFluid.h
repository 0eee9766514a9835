// SynthFluid: a procedural FLIP-like particle cache, our scale-test data (1 k to 1 G particles
// a frame). One frame is a pure function of (options, particle index), so it streams chunk by
// chunk with memory independent of the particle count, and is bit-identical for any chunk size
// and thread count. Three parts, in this index order:
//  - body: a jittered lattice (spacing cellSize()/2, so 8 particles per cell) displaced by a sum
//    of travelling finite-depth Gerstner waves (Gerstner 1802; Tessendorf 2001, "Simulating
//    Ocean Water", §3.1) whose phases come from the seed;
//  - sheets: a curling lip, two particles thick, riding each crest of the main wave;
//  - spray: droplets on ballistic arcs launched from crest points, respawned when they land.
// A particle index names the same particle in every frame: frames f and f+1 differ by the
// motion over frameTime seconds, and velocities are the analytic time derivatives.
// Units: metres and seconds, +y up, gravity 9.81 m/s^2 (Froude-scaled with `size`).
// Thread safety: const members are thread safe; read()/rewind() are not.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/Box.h"
#include "core/Progress.h"
#include "preprocess/particles/ParticleSource.h"
#include "preprocess/store/BrickStore.h"

namespace flipscope {

struct SynthOptions {
  std::uint64_t particles = 1'000'000;  ///< target particles a frame (>= 1000); count() is within 5 %
  int frame = 0;                        ///< time = frame * frameTime
  std::uint64_t seed = 1;
  double frameTime = 1.0 / 24;  ///< seconds between frames (> 0)
  double size = 1.0;            ///< horizontal extent of the box in metres, about (> 0)
  double sheetFraction = 0.05;  ///< share of the particles in crest sheets
  double sprayFraction = 0.05;  ///< share of the particles in spray droplets (body gets the rest, >= 50 %)
  bool velocity = true;         ///< chunks carry velocities (m/s)
};

class SynthFluid : public ParticleSource {
 public:
  /// Throws InputError for options out of range (the message names the option).
  explicit SynthFluid(const SynthOptions& options);

  std::string name() const override;
  std::string format() const override { return "flipscope synthetic fluid"; }
  bool hasVelocity() const override { return mOptions.velocity; }
  std::optional<std::uint64_t> countHint() const override { return count(); }
  bool read(ParticleChunk& chunk, std::size_t maxParticles) override;
  void rewind() override { mNext = 0; }

  /// Exact particles a frame (the same for every frame): bodyCount + sheetCount + sprayCount.
  std::uint64_t count() const { return mBodyCount + mSheetCount + mSprayCount; }
  /// Indices [0, bodyCount) are body, then sheetCount sheet particles, then spray.
  std::uint64_t bodyCount() const { return mBodyCount; }
  std::uint64_t sheetCount() const { return mSheetCount; }
  std::uint64_t sprayCount() const { return mSprayCount; }
  /// Simulation cell size (world units): the body lattice spacing is cellSize()/2, so
  /// `convert --cell-size cellSize()` sees about 8 particles per cell in the body.
  double cellSize() const { return 2 * mSpacing * mOptions.size; }
  /// Every particle of every frame lies inside (x and z wrap periodically).
  Box domain() const;
  double frameTime() const { return mOptions.frameTime; }
  /// Seconds since frame 0.
  double time() const { return mOptions.frame * mOptions.frameTime; }
  /// Shortest life of a spray droplet in seconds (the longest gap between two respawns).
  double shortestSprayLife() const;

  /// Particle `index` (< count()); `velocity` may be null.
  void particle(std::uint64_t index, glm::vec3& position, glm::vec3* velocity) const;

 private:
  // Internal units: a box about 1 m wide (Froude scaling to `size` happens on output).
  struct Wave {
    double kx, kz;     // wave vector (rad/m)
    double amplitude;  // m
    double omega;      // rad/s, finite-depth dispersion
    double phase;      // rad, from the seed
    double invSinhKh;  // 1 / sinh(|k| depth)
  };
  struct Sample {
    glm::dvec3 position;
    glm::dvec3 velocity;
  };
  struct ColumnCache {
    std::uint64_t column = ~std::uint64_t(0);
    std::vector<double> sinCos;
  };

  Sample sample(std::uint64_t index, double t, ColumnCache& cache) const;
  Sample bodyParticle(std::uint64_t index, const std::vector<double>& columnSinCos) const;
  void columnPhases(std::uint64_t column, double t, std::vector<double>& sinCos) const;
  Sample sheetParticle(std::uint64_t index, double t) const;
  Sample sprayParticle(std::uint64_t index, double t) const;
  double crestX(std::uint64_t crest, double t) const;
  /// Surface height (first order, Eulerian) and its time derivative along a path moving at dx/dt.
  double surfaceHeight(double x, double z, double t, std::size_t firstWave, double dxdt, double* dydt) const;
  glm::dvec3 wrap(glm::dvec3 p) const;
  void emit(const Sample& s, glm::vec3& position, glm::vec3* velocity) const;

  SynthOptions mOptions;
  double mTimeScale;  // internal seconds per output second (Froude: 1/sqrt(size))
  double mSpacing;    // lattice spacing (internal m)
  std::uint64_t mNx = 0, mNy = 0, mNz = 0;
  double mLengthX = 0, mLengthZ = 0, mDepth = 0, mHeight = 0;
  std::vector<Wave> mWaves;
  std::vector<double> mLayerCosh, mLayerSinh;  // per body layer and wave: cosh/sinh(kY)/sinh(kh)
  std::uint64_t mCrests = 0, mSheetU = 0, mSheetV = 0;
  double mCurlRadius = 0;  // internal m
  std::uint64_t mBodyCount = 0, mSheetCount = 0, mSprayCount = 0;
  std::uint64_t mNext = 0;
};

/// Bins frames [0, frames) of the synth fluid of `options` (options.frame is ignored) into a new
/// store at `storeDir` (what was there is replaced): the first frame's domain and cell size, the
/// body lattice (cellSize() / 2) as the particle spacing, the speed as the attribute. What `demo`
/// and `bench view` render. `progress`, when given, counts the particles.
BrickStore convertSynthFrames(SynthOptions options, int frames, const std::filesystem::path& storeDir,
                              Progress* progress = nullptr);

}  // namespace flipscope
