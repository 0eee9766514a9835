// The particle file formats behind openParticleFile() and createParticleWriter(), one .cpp
// each (RawParticles, PlyParticles, VdbPointsReader and VdbPoints). Private to
// flipscope::preprocess: callers use ParticleSource.h and ParticleWriter.h (the fuzz targets
// use openParticleBytes).
#pragma once

#include <filesystem>
#include <memory>
#include <span>

#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleSource.h"
#include "preprocess/particles/ParticleWriter.h"

namespace flipscope::detail {

/// Raw little-endian float32 xyz, 12 bytes a particle, no header (RawParticles.cpp).
std::unique_ptr<ParticleSource> openRawParticles(InputFile file);
std::unique_ptr<ParticleWriter> createRawWriter(const std::filesystem::path& path);

/// PLY, ascii or binary of either byte order (PlyParticles.cpp).
std::unique_ptr<ParticleSource> openPlyParticles(InputFile file, const ReadOptions& options);
std::unique_ptr<ParticleWriter> createPlyWriter(const std::filesystem::path& path, const WriteOptions& options);

/// OpenVDB PointDataGrids. The reader (VdbPointsReader.cpp) decodes the file itself, with every
/// size checked; the writer (VdbPoints.cpp) uses OpenVDB. Only these two files include OpenVDB.
std::unique_ptr<ParticleSource> openVdbPoints(const std::filesystem::path& path, const ReadOptions& options);
/// The same reader over `bytes` in memory (which must outlive the source), named `name`.
std::unique_ptr<ParticleSource> openVdbPointsBytes(const std::filesystem::path& name, std::span<const std::byte> bytes,
                                                   const ReadOptions& options);
std::unique_ptr<ParticleWriter> createVdbWriter(const std::filesystem::path& path, const WriteOptions& options);

/// Any particle format from bytes in memory, chosen by the extension of `name`, which also
/// names the source in messages (fuzz targets and tests). `bytes` must outlive the source.
std::unique_ptr<ParticleSource> openParticleBytes(const std::filesystem::path& name, std::span<const std::byte> bytes,
                                                  const ReadOptions& options = {});

}  // namespace flipscope::detail
