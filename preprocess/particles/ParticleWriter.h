// ParticleWriter: writes particles to a file in chunks, atomically (temporary file, then
// rename on commit()). Formats by extension (ParticleFormatRegistry.cpp):
//   .bin/.raw  little-endian float32 xyz, positions only
//   .ply       binary little endian by default; x y z [vx vy vz] as float
//   .vdb       OpenVDB PointDataGrid named "particles", with a "v" attribute for velocities
//   .bgeo .geo Houdini binary / ASCII JSON geometry, points only: P [and v], fpreal32
//   .bgeo.sc .geo.sc  the same inside Houdini's scf1 container (Blosc LZ4, 1 MiB chunks)
//   .prt       Krakatoa PRT 1.0: Position [and Velocity] float32[3], zlib records
//   .vtk       VTK legacy BINARY POLYDATA: POINTS float [and POINT_DATA VECTORS velocity float]
// Raw, PLY, PRT and the others stream with constant memory; where velocities follow every
// position in the file (Houdini, VTK) they wait in an unnamed temporary file beside the output
// (12 bytes a particle) until commit(). VDB builds its grid in memory on commit(), so it
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
