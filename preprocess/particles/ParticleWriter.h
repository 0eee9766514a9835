// ParticleWriter: writes particles to a file in chunks, atomically (temporary file, then
// rename on commit()). Formats by extension: .bin/.raw (little-endian float32 xyz, positions
// only), .ply (binary little endian by default; x y z [vx vy vz] as float), .vdb (OpenVDB
// PointDataGrid named "particles", with a "v" attribute when velocities are written).
// Raw and PLY stream with constant memory; VDB builds its grid in memory on commit(), so it
// holds the frame (12 bytes a particle, 24 with velocities, plus OpenVDB's index grid while
// building) and rejects non-finite positions (InputError). Its voxel size, when not given, is
// chosen by OpenVDB's computeVoxelSize for about 8 points a voxel.
#pragma once

#include <filesystem>
#include <memory>

#include "preprocess/particles/ParticleSource.h"

namespace flipscope {

enum class PlyEncoding { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct WriteOptions {
  bool velocity = false;  ///< write velocities (ignored by raw); chunks must then carry them
  PlyEncoding plyEncoding = PlyEncoding::BinaryLittleEndian;
  float vdbVoxelSize = 0;  ///< VDB: voxel size of the point grid; 0 = from the particle bounds
};

class ParticleWriter {
 public:
  virtual ~ParticleWriter() = default;
  virtual void write(const ParticleChunk& chunk) = 0;
  /// Finishes the file and renames it into place. Without commit() nothing is left behind.
  virtual void commit() = 0;
};

/// Throws FileError for an unknown extension or an unwritable path.
std::unique_ptr<ParticleWriter> createParticleWriter(const std::filesystem::path& path,
                                                     const WriteOptions& options = {});

}  // namespace flipscope
