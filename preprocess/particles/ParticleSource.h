// ParticleSource: a stream of particles read in chunks, so that files larger than memory
// convert with bounded memory. Readers for each format implement it (VdbPointsReader,
// PlyReader, RawReader), and so does the synthetic generator (SynthFluid).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace flipscope {

/// One chunk of particles in world units. `velocities` is empty when the source has none,
/// otherwise it has the size of `positions`.
struct ParticleChunk {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> velocities;
  void clear() {
    positions.clear();
    velocities.clear();
  }
  std::size_t size() const { return positions.size(); }
};

/// What a file's own metadata says about its particle spacing (ParticleSpacing.h): `points`
/// particles fill `volume` world units^3 (OpenVDB points: the active voxels of the grids).
/// Hints of several sources add up (volumes and points).
struct SpacingHint {
  double volume = 0;
  std::uint64_t points = 0;
  std::string origin;  ///< for messages, e.g. "OpenVDB grid 'particles': 14554 points in 3431 voxels of 0.0625"
};

class ParticleSource {
 public:
  virtual ~ParticleSource() = default;
  /// What error messages call this source (usually the file path).
  virtual std::string name() const = 0;
  /// Whether chunks carry velocities (and want them: see ReadOptions::velocity).
  virtual bool hasVelocity() const = 0;
  /// Total particle count when known without reading the data (file headers), else nullopt.
  virtual std::optional<std::uint64_t> countHint() const = 0;
  /// Replaces `chunk` with the next at most `maxParticles` particles (maxParticles > 0).
  /// Returns false, with `chunk` empty, at the end. Throws FileError on malformed data.
  /// Values are passed on as stored: NaN/Inf are the caller's to count and skip.
  virtual bool read(ParticleChunk& chunk, std::size_t maxParticles) = 0;
  /// Starts over from the first particle (multi-pass conversion: bounds, then binning).
  virtual void rewind() = 0;
  /// The particle spacing as the file's metadata tells it without reading the particles, else
  /// nullopt (then estimateParticleSpacing() measures neighbour distances).
  virtual std::optional<SpacingHint> spacingHint() const { return std::nullopt; }
};

struct ReadOptions {
  /// VDB: names of the PointDataGrids to read; empty = every PointDataGrid in the file.
  std::vector<std::string> grids;
  /// Read velocities when the file has them (`vx vy vz` in PLY; in VDB the vec3s attribute `v`,
  /// else Blender Mantaflow's `particles_velocity*`).
  bool velocity = true;
};

/// Opens a particle file by its extension (case-insensitive): .vdb, .ply, .bin/.raw
/// (little-endian float32 xyz). Throws FileError for unknown extensions, missing files and bad
/// headers. Memory stays bounded by the chunk size, except for a VDB file's tree topology and
/// one leaf's attributes (delayed loading).
std::unique_ptr<ParticleSource> openParticleFile(const std::filesystem::path& path, const ReadOptions& options = {});

/// Reads several sources one after the other as one (e.g. the FLIP and the spray file of one
/// frame). hasVelocity() is true only if every part has velocities.
std::unique_ptr<ParticleSource> concatSources(std::vector<std::unique_ptr<ParticleSource>> parts);

}  // namespace flipscope
