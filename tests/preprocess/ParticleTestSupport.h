// Helpers for the particle reader/writer tests: a temporary directory, seeded random
// particles, whole-file reads and writes, and FileError message checks.
#pragma once

#include <gtest/gtest.h>

#include <unistd.h>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "TestSupport.h"
#include "core/Error.h"
#include "preprocess/particles/ParticleFormatRegistry.h"
#include "preprocess/particles/ParticleSource.h"
#include "preprocess/particles/ParticleWriter.h"

namespace flipscope::testing {

/// `count` particles uniform in [-50, 50)^3 (velocities in [-3, 3)^3 when asked), seeded.
inline ParticleChunk randomParticles(std::size_t count, bool velocity, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> position(-50.f, 50.f), speed(-3.f, 3.f);
  ParticleChunk chunk;
  for (std::size_t i = 0; i < count; ++i) {
    chunk.positions.emplace_back(position(rng), position(rng), position(rng));
    if (velocity) chunk.velocities.emplace_back(speed(rng), speed(rng), speed(rng));
  }
  return chunk;
}

/// Bit-identical (NaN payloads included).
inline bool sameBits(const glm::vec3& a, const glm::vec3& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// Reads a whole source in chunks of `maxParticles`, checking each chunk's shape.
inline ParticleChunk readAll(ParticleSource& source, std::size_t maxParticles) {
  ParticleChunk all, chunk;
  while (source.read(chunk, maxParticles)) {
    EXPECT_GT(chunk.size(), 0u);
    EXPECT_LE(chunk.size(), maxParticles);
    EXPECT_EQ(chunk.velocities.size(), source.hasVelocity() ? chunk.size() : 0u);
    all.positions.insert(all.positions.end(), chunk.positions.begin(), chunk.positions.end());
    all.velocities.insert(all.velocities.end(), chunk.velocities.begin(), chunk.velocities.end());
  }
  EXPECT_EQ(chunk.size(), 0u);
  return all;
}

inline ParticleChunk readFile(const std::filesystem::path& path, std::size_t maxParticles = 1000,
                              const ReadOptions& options = {}) {
  auto source = openParticleFile(path, options);
  return readAll(*source, maxParticles);
}

/// Writes `particles` through createParticleWriter in chunks of `chunkSize`.
inline void writeFile(const std::filesystem::path& path, const ParticleChunk& particles, const WriteOptions& options,
                      std::size_t chunkSize = 333) {
  auto writer = createParticleWriter(path, options);
  for (std::size_t begin = 0; begin < particles.size(); begin += chunkSize) {
    std::size_t end = std::min(particles.size(), begin + chunkSize);
    ParticleChunk chunk;
    chunk.positions.assign(particles.positions.begin() + begin, particles.positions.begin() + end);
    if (options.velocity)
      chunk.velocities.assign(particles.velocities.begin() + begin, particles.velocities.begin() + end);
    writer->write(chunk);
  }
  writer->commit();
}

inline void writeBytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

inline std::string readBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// Expects `work` to throw FileError whose message contains every one of `parts`.
inline void expectFileError(const std::function<void()>& work, const std::vector<std::string>& parts) {
  try {
    work();
    ADD_FAILURE() << "no FileError thrown; expected one mentioning '" << parts.front() << "'";
  } catch (const FileError& e) {
    std::string message = e.what();
    EXPECT_LT(message.size(), 1000u) << "message not kept short: " << message.substr(0, 300);
    for (const auto& part : parts) EXPECT_NE(message.find(part), std::string::npos) << "message: " << message;
  }
}

/// Everything a source yields: positions, velocities and one value column per attribute.
struct Everything {
  ParticleChunk particles;
  std::vector<std::vector<float>> columns;
};

/// Reads `source` to its end in chunks of at most `chunkSize`, checking each chunk's shape.
inline Everything readEverything(ParticleSource& source, std::size_t chunkSize) {
  Everything all;
  ParticleChunk chunk;
  while (source.read(chunk, chunkSize)) {
    EXPECT_LE(chunk.size(), chunkSize);
    EXPECT_EQ(chunk.velocities.size(), source.hasVelocity() ? chunk.size() : 0u);
    all.particles.positions.insert(all.particles.positions.end(), chunk.positions.begin(), chunk.positions.end());
    all.particles.velocities.insert(all.particles.velocities.end(), chunk.velocities.begin(), chunk.velocities.end());
    all.columns.resize(chunk.attributes.size());
    for (std::size_t i = 0; i < chunk.attributes.size(); ++i) {
      EXPECT_EQ(chunk.attributes[i].values.size(), chunk.size() * std::size_t(chunk.attributes[i].arity));
      all.columns[i].insert(all.columns[i].end(), chunk.attributes[i].values.begin(), chunk.attributes[i].values.end());
    }
  }
  return all;
}

inline std::span<const std::byte> bytesOf(const std::string& text) {
  return std::as_bytes(std::span(text.data(), text.size()));
}

/// Read options that read every attribute of a file.
inline ReadOptions everyAttribute() {
  ReadOptions options;
  options.allAttributes = true;
  return options;
}

/// Whether `bytes`, as a file named `name`, reads to its end with every attribute; a refusal must
/// be a FileError naming the file. What it read goes to `out` when given.
inline bool readsCompletely(const std::string& name, const std::string& bytes, Everything* out = nullptr) {
  try {
    auto source = openParticleBytes(name, bytesOf(bytes), everyAttribute());
    Everything all = readEverything(*source, 64);
    if (out) *out = std::move(all);
    return true;
  } catch (const FileError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(name + ": ", 0), 0u) << e.what();
    return false;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a FileError: " << e.what();
    return false;
  }
}

}  // namespace flipscope::testing
