// Procedural FLIP-like caches. The body follows finite-depth Gerstner waves (Gerstner 1802;
// Tessendorf 2001, "Simulating Ocean Water", §3.1, with the dispersion relation
// omega^2 = g k tanh(k h)); jitter comes from a counter-based hash (SplitMix64, Steele et al.
// 2014), so every particle is a pure function of (seed, index, time).
#include "preprocess/SynthFluid.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include <tbb/parallel_for.h>

#include "core/Error.h"
#include "preprocess/Convert.h"

namespace flipscope {

namespace {

constexpr double kGravity = 9.81;
constexpr double kPi = std::numbers::pi;
constexpr double kNominalWidth = 1.0;   // internal m, x and z
constexpr double kNominalDepth = 0.2;   // internal m, mean water depth
constexpr double kNominalHeight = 0.5;  // internal m, top of the box
constexpr double kCurlRadius = 0.04;    // internal m
constexpr double kCurlAngle = 1.2 * kPi;
constexpr double kSprayMinRise = 0.6;  // m/s, vertical launch speed range
constexpr double kSprayMaxRise = 1.5;
constexpr double kJitter = 0.25;            // body jitter, in lattice spacings either side
constexpr std::size_t kSerialBelow = 4096;  // chunks smaller than this are generated serially

// Hash streams, so that the body, sheets, spray and waves draw independent numbers.
enum Stream : std::uint64_t { kWaveStream = 1, kBodyStream, kSheetStream, kSprayStream, kLaunchStream };

struct WaveShape {
  int nx, nz;  // periods across the box
  double amplitude;
};
// Steepness sum(k A) stays below 0.7, so the Gerstner map never folds (and y stays > 0).
constexpr WaveShape kWaveShapes[] = {{2, 0, 0.025}, {3, 2, 0.010}, {1, 3, 0.006}};

std::uint64_t mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

std::uint64_t hash(std::uint64_t seed, Stream stream, std::uint64_t index, std::uint64_t extra = 0) {
  return mix(mix(mix(seed ^ (stream * 0xd1b54a32d192ed03ull)) ^ index) ^ extra);
}

/// Uniform in [0, 1) from 53 bits.
double unit(std::uint64_t h) { return double(h >> 11) * 0x1.0p-53; }
/// Three uniforms in [0, 1) from 21 bits each.
glm::dvec3 unit3(std::uint64_t h) {
  constexpr double kScale = 0x1.0p-21;
  return {double(h & 0x1fffff) * kScale, double((h >> 21) & 0x1fffff) * kScale, double((h >> 42) & 0x1fffff) * kScale};
}

std::uint64_t roundPositive(double v) { return std::uint64_t(std::max(1.0, std::round(v))); }

}  // namespace

SynthFluid::SynthFluid(const SynthOptions& options) : mOptions(options) {
  auto fail = [](const std::string& what) { throw InputError("synth: " + what); };
  if (options.particles < 1000) fail("particles must be at least 1000, got " + std::to_string(options.particles));
  if (!(options.frameTime > 0) || !std::isfinite(options.frameTime)) fail("frame time must be positive");
  if (!(options.size > 0) || !std::isfinite(options.size)) fail("size must be positive");
  if (!(options.sheetFraction >= 0) || !(options.sprayFraction >= 0) ||
      !(options.sheetFraction + options.sprayFraction <= 0.5))
    fail("sheet and spray fractions must be >= 0 and sum to at most 0.5");
  mTimeScale = 1 / std::sqrt(options.size);

  // Body lattice: nx and ny from the nominal box, nz absorbs the rounding (error <= 1/(2 nz)).
  const double target = double(options.particles);
  const double sheetTarget = target * options.sheetFraction;
  mSprayCount = std::uint64_t(std::llround(target * options.sprayFraction));
  const double bodyTarget = target - sheetTarget - double(mSprayCount);
  mSpacing = std::cbrt(kNominalWidth * kNominalDepth * kNominalWidth / bodyTarget);
  mNx = roundPositive(kNominalWidth / mSpacing);
  mNy = roundPositive(kNominalDepth / mSpacing);
  mNz = roundPositive(bodyTarget / double(mNx * mNy));
  mBodyCount = mNx * mNy * mNz;
  mLengthX = double(mNx) * mSpacing;
  mLengthZ = double(mNz) * mSpacing;
  mDepth = double(mNy) * mSpacing;
  mHeight = kNominalHeight;

  for (std::size_t i = 0; i < std::size(kWaveShapes); ++i) {
    const WaveShape& shape = kWaveShapes[i];
    Wave w;
    double zSign = (hash(options.seed, kWaveStream, i, 1) & 1) ? 1.0 : -1.0;
    w.kx = 2 * kPi * shape.nx / mLengthX;
    w.kz = zSign * 2 * kPi * shape.nz / mLengthZ;
    double k = std::hypot(w.kx, w.kz);
    w.amplitude = shape.amplitude;
    w.omega = std::sqrt(kGravity * k * std::tanh(k * mDepth));
    w.phase = 2 * kPi * unit(hash(options.seed, kWaveStream, i));
    w.invSinhKh = 1 / std::sinh(k * mDepth);
    mWaves.push_back(w);
  }
  // cosh/sinh(k Y) / sinh(k h) at each lattice layer (O(count^(1/3)) memory).
  for (std::uint64_t iy = 0; iy < mNy; ++iy) {
    double y = (double(iy) + 0.5) * mSpacing;
    for (const Wave& w : mWaves) {
      double k = std::hypot(w.kx, w.kz);
      mLayerCosh.push_back(std::cosh(k * y) * w.invSinhKh);
      mLayerSinh.push_back(std::sinh(k * y) * w.invSinhKh);
    }
  }

  // Sheets: a curl of arc length R * angle along each crest of wave 0, two layers; the in-sheet
  // spacing follows from the particle share (finer than the lattice for large counts).
  mCrests = std::uint64_t(kWaveShapes[0].nx);
  mCurlRadius = kCurlRadius;
  if (sheetTarget >= 1) {
    double arc = mCurlRadius * kCurlAngle;
    double spacing = std::sqrt(2 * double(mCrests) * mLengthZ * arc / sheetTarget);
    mSheetU = roundPositive(mLengthZ / spacing);
    mSheetV = roundPositive(sheetTarget / double(2 * mCrests * mSheetU));
    mSheetCount = 2 * mCrests * mSheetU * mSheetV;
  }
}

std::string SynthFluid::name() const {
  std::ostringstream os;
  os << "synth(seed " << mOptions.seed << ", frame " << mOptions.frame << ")";
  return os.str();
}

Box SynthFluid::domain() const {
  Box box;
  box.min = glm::dvec3(0);
  box.max = glm::dvec3(mLengthX, mHeight, mLengthZ) * mOptions.size;
  return box;
}

double SynthFluid::shortestSprayLife() const { return 2 * kSprayMinRise / kGravity / mTimeScale; }

glm::dvec3 SynthFluid::wrap(glm::dvec3 p) const {
  p.x -= mLengthX * std::floor(p.x / mLengthX);
  p.z -= mLengthZ * std::floor(p.z / mLengthZ);
  return p;
}

double SynthFluid::crestX(std::uint64_t crest, double t) const {
  const Wave& w = mWaves[0];
  return (w.omega * t - w.phase + 2 * kPi * double(crest)) / w.kx;
}

double SynthFluid::surfaceHeight(double x, double z, double t, std::size_t firstWave, double dxdt, double* dydt) const {
  double y = mDepth;
  double rate = 0;
  for (std::size_t i = firstWave; i < mWaves.size(); ++i) {
    const Wave& w = mWaves[i];
    double theta = w.kx * x + w.kz * z - w.omega * t + w.phase;
    y += w.amplitude * std::cos(theta);
    rate -= w.amplitude * std::sin(theta) * (w.kx * dxdt - w.omega);
  }
  if (dydt) *dydt = rate;
  return y;
}

void SynthFluid::columnPhases(std::uint64_t column, double t, std::vector<double>& sinCos) const {
  double x = (double(column % mNx) + 0.5) * mSpacing;
  double z = (double(column / mNx) + 0.5) * mSpacing;
  sinCos.resize(2 * mWaves.size());
  for (std::size_t i = 0; i < mWaves.size(); ++i) {
    const Wave& w = mWaves[i];
    double theta = w.kx * x + w.kz * z - w.omega * t + w.phase;
    sinCos[2 * i] = std::sin(theta);
    sinCos[2 * i + 1] = std::cos(theta);
  }
}

// Gerstner: x = X - sum d A C(Y) sin(theta), y = Y + sum A S(Y) cos(theta), theta = k.X - w t + phi.
SynthFluid::Sample SynthFluid::bodyParticle(std::uint64_t index, const std::vector<double>& sinCos) const {
  std::uint64_t column = index / mNy, iy = index % mNy;
  glm::dvec3 rest((double(column % mNx) + 0.5) * mSpacing, (double(iy) + 0.5) * mSpacing,
                  (double(column / mNx) + 0.5) * mSpacing);
  Sample s{rest, glm::dvec3(0)};
  const std::size_t waves = mWaves.size();
  for (std::size_t i = 0; i < waves; ++i) {
    const Wave& w = mWaves[i];
    double k = std::hypot(w.kx, w.kz);
    double c = mLayerCosh[iy * waves + i] * w.amplitude, sn = mLayerSinh[iy * waves + i] * w.amplitude;
    double sinT = sinCos[2 * i], cosT = sinCos[2 * i + 1];
    glm::dvec3 dir(w.kx / k, 0, w.kz / k);
    s.position += -dir * (c * sinT) + glm::dvec3(0, sn * cosT, 0);
    s.velocity += dir * (c * w.omega * cosT) + glm::dvec3(0, sn * w.omega * sinT, 0);
  }
  glm::dvec3 jitter = (unit3(hash(mOptions.seed, kBodyStream, index)) - 0.5) * (2 * kJitter * mSpacing);
  s.position = wrap(s.position + jitter);
  return s;
}

// Sheet particle: ((crest * U + u) * V + v) * 2 + layer. A circular lip of radius R(z) rises
// from the crest, curls forward and down; the layers sit at R -+ spacing/2. It rides the crest
// at the phase speed of wave 0 and the surface height of the other waves.
SynthFluid::Sample SynthFluid::sheetParticle(std::uint64_t index, double t) const {
  std::uint64_t layer = index % 2, v = (index / 2) % mSheetV, u = (index / 2 / mSheetV) % mSheetU;
  std::uint64_t crest = index / 2 / mSheetV / mSheetU;
  glm::dvec3 j = unit3(hash(mOptions.seed, kSheetStream, index / 2)) - 0.5;
  double z = (double(u) + 0.5 + 0.5 * j.x) / double(mSheetU) * mLengthZ;
  double angle = (double(v) + 0.5 + 0.5 * j.y) / double(mSheetV) * kCurlAngle;
  const Wave& main = mWaves[0];
  double speed = main.omega / main.kx;
  double x0 = crestX(crest, t);
  double rise = 0;
  double y0 = surfaceHeight(x0, z, t, 1, speed, &rise) + main.amplitude;
  double centre = mCurlRadius * (1 + 0.3 * std::sin(2 * kPi * z / mLengthZ + main.phase));
  double radius = centre + (layer ? 0.5 : -0.5) * mSpacing;
  // Circle centred at (x0 + R, y0): angle 0 is the crest, angle pi the front of the lip.
  glm::dvec3 p(x0 + centre - radius * std::cos(angle), y0 + radius * std::sin(angle), z);
  return {wrap(p), glm::dvec3(speed, rise, 0)};
}

// Droplet d: vertical launch speed and phase fixed per droplet; each flight (cycle c) starts
// from a crest point of wave 0 drawn from (d, c) and lands back at launch height after 2 vy / g.
SynthFluid::Sample SynthFluid::sprayParticle(std::uint64_t index, double t) const {
  std::uint64_t h = hash(mOptions.seed, kSprayStream, index);
  double rise = kSprayMinRise + (kSprayMaxRise - kSprayMinRise) * unit(h);
  double life = 2 * rise / kGravity;
  double cycles = t / life + double(h & 0x7ff) / 2048.0;
  double cycle = std::floor(cycles);
  double age = (cycles - cycle) * life;
  std::uint64_t launchHash = hash(mOptions.seed, kLaunchStream, index, std::uint64_t(std::int64_t(cycle)));
  glm::dvec3 launch = unit3(launchHash), spread = unit3(mix(launchHash));
  const Wave& main = mWaves[0];
  double speed = main.omega / main.kx;
  double t0 = t - age;
  std::uint64_t crest = std::min(mCrests - 1, std::uint64_t(launch.x * double(mCrests)));
  double x0 = crestX(crest, t0), z0 = launch.y * mLengthZ;
  double y0 = surfaceHeight(x0, z0, t0, 0, 0, nullptr);
  glm::dvec3 v0(speed * (0.6 + 0.6 * spread.x), rise, 0.3 * (spread.y - 0.5));
  glm::dvec3 p = glm::dvec3(x0, y0, z0) + v0 * age + glm::dvec3(0, -0.5 * kGravity * age * age, 0);
  return {wrap(p), v0 - glm::dvec3(0, kGravity * age, 0)};
}

void SynthFluid::emit(const Sample& s, glm::vec3& position, glm::vec3* velocity) const {
  position = glm::vec3(s.position * mOptions.size);
  if (velocity) *velocity = glm::vec3(s.velocity * (mOptions.size * mTimeScale));
}

SynthFluid::Sample SynthFluid::sample(std::uint64_t index, double t, ColumnCache& cache) const {
  if (index < mBodyCount) {
    // Consecutive body particles share a column: its wave phases are computed once.
    if (index / mNy != cache.column) {
      cache.column = index / mNy;
      columnPhases(cache.column, t, cache.sinCos);
    }
    return bodyParticle(index, cache.sinCos);
  }
  if (index < mBodyCount + mSheetCount) return sheetParticle(index - mBodyCount, t);
  return sprayParticle(index - mBodyCount - mSheetCount, t);
}

void SynthFluid::particle(std::uint64_t index, glm::vec3& position, glm::vec3* velocity) const {
  FLIPSCOPE_CHECK(index < count(), "index=" << index << " count=" << count());
  ColumnCache cache;
  emit(sample(index, time() * mTimeScale, cache), position, velocity);
}

bool SynthFluid::read(ParticleChunk& chunk, std::size_t maxParticles) {
  FLIPSCOPE_CHECK(maxParticles > 0, "maxParticles=" << maxParticles);
  std::uint64_t n = std::min<std::uint64_t>(maxParticles, count() - mNext);
  chunk.positions.resize(n);
  chunk.velocities.resize(mOptions.velocity ? n : 0);
  if (n == 0) return false;
  const std::uint64_t first = mNext;
  const double t = time() * mTimeScale;
  auto generate = [&](std::uint64_t begin, std::uint64_t end) {
    ColumnCache cache;
    for (std::uint64_t i = begin; i < end; ++i)
      emit(sample(first + i, t, cache), chunk.positions[i], mOptions.velocity ? &chunk.velocities[i] : nullptr);
  };
  if (n < kSerialBelow) {
    generate(0, n);
  } else {
    tbb::parallel_for(tbb::blocked_range<std::uint64_t>(0, n, kSerialBelow),
                      [&](const tbb::blocked_range<std::uint64_t>& r) { generate(r.begin(), r.end()); });
  }
  mNext += n;
  return true;
}

BrickStore convertSynthFrames(SynthOptions options, int frames, const std::filesystem::path& storeDir,
                              Progress* progress) {
  options.frame = 0;
  const SynthFluid first(options);
  ConvertOptions convert;
  convert.cellSize = first.cellSize();
  convert.domain = first.domain();
  convert.particleSpacing = first.cellSize() / 2;  // the body lattice
  convert.progress = Progress::Mode::Silent;
  std::filesystem::remove_all(storeDir);
  BrickStore store =
      BrickStore::createOrAppend(storeDir, makeStoreHeader(*convert.domain, convert, AttributeKind::Speed));
  for (int f = 0; f < frames; ++f) {
    options.frame = f;
    SynthFluid fluid(options);
    convertFrame(fluid, store, f, convert, progress);
  }
  return store;
}

}  // namespace flipscope
