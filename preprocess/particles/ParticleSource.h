// ParticleSource: a stream of particles read in chunks, so that files larger than memory
// convert with bounded memory. Readers for each format implement it (VdbPointsReader,
// PlyReader, RawReader), and so does the synthetic generator (SynthFluid).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "core/UpAxis.h"

namespace flipscope {

/// The type of one component of an attribute, as the file stores it.
enum class ValueType : std::uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float16, Float32, Float64 };
/// "int8", "uint8", ..., "float16", "float32", "float64".
std::string_view valueTypeName(ValueType type);
/// Int8 .. UInt64.
constexpr bool isIntegerType(ValueType type) { return type <= ValueType::UInt64; }

/// A per-particle attribute that a file holds besides the positions (velocity included), as
/// its header declares it: what `flipscope inspect` lists and `convert --attribute` chooses.
struct AttributeDesc {
  std::string name;  ///< as the file names it: "v", "pscale", "Cd", "Velocity", "id"
  ValueType type = ValueType::Float32;
  int arity = 1;  ///< components per particle (3 for a vector)
  bool operator==(const AttributeDesc&) const = default;
};

/// The values of one attribute for the particles of a chunk: `arity` components a particle,
/// converted to float, particle after particle (values.size() == chunk.size() * arity).
struct AttributeColumn {
  std::string name;
  int arity = 1;
  std::vector<float> values;
};

/// One chunk of particles in world units. `velocities` is empty when the source has none,
/// otherwise it has the size of `positions`. `attributes` holds the columns ReadOptions asked
/// for, in the order asked (ReadOptions::attributes, or attributes() for allAttributes).
struct ParticleChunk {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> velocities;
  std::vector<AttributeColumn> attributes;
  void clear() {
    positions.clear();
    velocities.clear();
    for (auto& column : attributes) column.values.clear();
  }
  /// clear(), then `n` positions (and velocities, where `withVelocities`) of unspecified value,
  /// for a reader that overwrites them all. A chunk read into again (the same size each time)
  /// is not zero-filled again: std::vector's resize fills only what it grows by (a 100 M
  /// particle raw frame's positions zero-filled chunk by chunk cost 4 % of its convert).
  void resizeForOverwrite(std::size_t n, bool withVelocities) {
    positions.resize(n);
    velocities.resize(withVelocities ? n : 0);
    for (auto& column : attributes) column.values.clear();
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
  /// The format and its version as the file states it, for `inspect` (e.g. "Houdini binary
  /// JSON geometry (.bgeo), Houdini 18.5.408").
  virtual std::string format() const = 0;
  /// Every per-particle attribute besides the positions, from the header (no data is read).
  virtual std::vector<AttributeDesc> attributes() const { return {}; }
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
  /// Random access, for sampling a frame without reading it whole (ParticleSpacing.h): the
  /// positions of the particles numbered `indices` (ascending, each < countHint()) into
  /// `positions` (resized to match), leaving the next read() where it was. Returns false,
  /// reading nothing, unless the source seeks to a particle cheaply (fixed-size records in an
  /// uncompressed file: raw, binary PLY); callers then read the source in order. Throws
  /// FileError like read().
  virtual bool readPositionsAt(std::span<const std::uint64_t> indices, std::vector<glm::vec3>& positions) {
    (void)indices, (void)positions;
    return false;
  }
  /// Random access by range, for reading a frame on several threads at once (PositionRanges.h:
  /// the spacing estimate's neighbour pass and convert's bounds pass):
  /// the positions of particles [first, first + count) (within countHint()) into `positions`
  /// (resized to match), leaving the next read() where it was. Thread safe: calls may overlap
  /// each other and one read() or readPositionsAt(). Returns false, reading nothing, unless the
  /// source seeks to a particle cheaply (as readPositionsAt); a source that reads ranges does
  /// so for count 0 too. Throws FileError like read().
  virtual bool readPositionRange(std::uint64_t first, std::size_t count, std::vector<glm::vec3>& positions) {
    (void)first, (void)count, (void)positions;
    return false;
  }
  /// The particle spacing as the file's metadata tells it without reading the particles, else
  /// nullopt (then estimateParticleSpacing() measures neighbour distances).
  virtual std::optional<SpacingHint> spacingHint() const { return std::nullopt; }
  /// The attribute of attributes() that holds each particle's type by the file's own
  /// conventions (Mantaflow's type flags, preprocess/store/ParticleKind.h), else nullopt: Blender
  /// Mantaflow's integer `U` of a points grid named `particles_secondary`. Of one file: a
  /// concatenation of sources has none.
  virtual std::optional<std::string> kindAttribute() const { return std::nullopt; }
  /// The up axis the file's conventions imply, else Unknown: +z for Blender's fluid caches
  /// (points grids named `particles`, `particles_secondary`), +y for Houdini, RealFlow and Maya.
  /// What convert records in the store unless given `--up`. Of one file, like kindAttribute.
  virtual UpAxis upAxis() const { return UpAxis::Unknown; }
};

struct ReadOptions {
  /// VDB: names of the PointDataGrids to read; empty = every PointDataGrid in the file.
  std::vector<std::string> grids;
  /// Read velocities when the file has them (`vx vy vz` in PLY; in VDB the vec3s attribute `v`,
  /// else Blender Mantaflow's `particles_velocity*`; Houdini `v`, Krakatoa `Velocity`, ...).
  bool velocity = true;
  /// Attributes to read into ParticleChunk::attributes, by name. Opening a source throws
  /// FileError, naming the file and listing what it holds, when one is not in attributes().
  std::vector<std::string> attributes;
  /// Read every attribute of attributes() instead (`inspect`).
  bool allAttributes = false;
  /// Where not 0, the file is read once, in order (convert's binning pass): what is not in the
  /// page cache is read around it, not into it, with this many bytes read ahead (InputFile).
  std::size_t readOnceAheadBytes = 0;
};

/// Opens a particle file of any format of the registry (ParticleFormatRegistry.h), recognised
/// by its content (magic bytes, compressed containers opened first), its name as a fallback.
/// Throws FileError for unknown formats, missing files and bad headers. Memory stays bounded
/// by the chunk size, except where a format's reader says otherwise.
std::unique_ptr<ParticleSource> openParticleFile(const std::filesystem::path& path, const ReadOptions& options = {});

/// Reads several sources one after the other as one (e.g. the FLIP and the spray file of one
/// frame). hasVelocity() is true only if every part has velocities.
std::unique_ptr<ParticleSource> concatSources(std::vector<std::unique_ptr<ParticleSource>> parts);

}  // namespace flipscope
