// The readers and writers behind the registry (ParticleFormatRegistry.cpp), one .cpp (or
// sub-folder) each, and what they share. Private to flipscope::particles and its tests:
// callers use ParticleSource.h, ParticleWriter.h and ParticleFormatRegistry.h.
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <span>
#include <vector>

#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleSource.h"
#include "preprocess/particles/ParticleWriter.h"

namespace flipscope::detail {

/// Raw little-endian float32 xyz, 12 bytes a particle, no header (RawParticles.cpp).
std::unique_ptr<ParticleSource> openRawParticles(InputFile file, const ReadOptions& options);
std::unique_ptr<ParticleWriter> createRawWriter(const std::filesystem::path& path, const WriteOptions& options);

/// PLY, ascii or binary of either byte order (PlyParticles.cpp).
bool isPly(std::span<const std::byte> head);
std::unique_ptr<ParticleSource> openPlyParticles(InputFile file, const ReadOptions& options);
std::unique_ptr<ParticleWriter> createPlyWriter(const std::filesystem::path& path, const WriteOptions& options);

/// OpenVDB PointDataGrids. The reader (VdbPointsReader.cpp) decodes the file itself, with every
/// size checked; the writer (VdbPoints.cpp) uses OpenVDB. Only these two files include OpenVDB.
bool isVdb(std::span<const std::byte> head);
std::unique_ptr<ParticleSource> openVdbPoints(InputFile file, const ReadOptions& options);
std::unique_ptr<ParticleWriter> createVdbWriter(const std::filesystem::path& path, const WriteOptions& options);

/// Which of `available` ReadOptions asks for, as indices into `available`, in the order asked
/// (all of them for allAttributes). Throws FileError naming `file`, the missing attribute and
/// what the file holds.
std::vector<std::size_t> selectAttributes(const std::vector<AttributeDesc>& available, const ReadOptions& options,
                                          const std::filesystem::path& file);
/// Columns named and sized for `selected` attributes of `available` (values left empty).
std::vector<AttributeColumn> makeColumns(const std::vector<AttributeDesc>& available,
                                         const std::vector<std::size_t>& selected);
/// Gives a chunk's `columns` the names and arities of `expected` (the reader's makeColumns),
/// keeping their storage: a chunk may come from another source or be new.
void syncColumns(std::vector<AttributeColumn>& columns, const std::vector<AttributeColumn>& expected);

}  // namespace flipscope::detail
