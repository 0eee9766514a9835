// The particle file formats behind openParticleFile() and createParticleWriter(), one .cpp
// each (RawParticles, PlyParticles, VdbPoints). Private to flipscope::preprocess: callers use
// ParticleSource.h and ParticleWriter.h.
#pragma once

#include <filesystem>
#include <memory>

#include "preprocess/ParticleSource.h"
#include "preprocess/ParticleWriter.h"

namespace flipscope::detail {

/// Raw little-endian float32 xyz, 12 bytes a particle, no header (RawParticles.cpp).
std::unique_ptr<ParticleSource> openRawParticles(const std::filesystem::path& path);
std::unique_ptr<ParticleWriter> createRawWriter(const std::filesystem::path& path);

/// PLY, ascii or binary of either byte order (PlyParticles.cpp).
std::unique_ptr<ParticleSource> openPlyParticles(const std::filesystem::path& path, const ReadOptions& options);
std::unique_ptr<ParticleWriter> createPlyWriter(const std::filesystem::path& path, const WriteOptions& options);

/// OpenVDB PointDataGrids (VdbPoints.cpp, the only file that includes OpenVDB).
std::unique_ptr<ParticleSource> openVdbPoints(const std::filesystem::path& path, const ReadOptions& options);
std::unique_ptr<ParticleWriter> createVdbWriter(const std::filesystem::path& path, const WriteOptions& options);

}  // namespace flipscope::detail
