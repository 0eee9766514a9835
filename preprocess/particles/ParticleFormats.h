// The readers and writers behind the registry (ParticleFormatRegistry.cpp), one .cpp (or
// sub-folder) each, and what they share. Private to flipscope::particles and its tests:
// callers use ParticleSource.h, ParticleWriter.h and ParticleFormatRegistry.h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/Error.h"
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

/// VTK legacy (.vtk), ASCII or BINARY, POLYDATA and UNSTRUCTURED_GRID (VtkLegacyParticles.cpp).
bool isVtkLegacy(std::span<const std::byte> head);
std::unique_ptr<ParticleSource> openVtkLegacyParticles(InputFile file, const ReadOptions& options);
/// BINARY POLYDATA: POINTS float, POINT_DATA VECTORS velocity float (VtkLegacyWriter.cpp).
std::unique_ptr<ParticleWriter> createVtkLegacyWriter(const std::filesystem::path& path, const WriteOptions& options);
/// VTK XML UnstructuredGrid and PolyData (.vtu, .vtp): ascii, base64 and appended data, zlib
/// (VtuParticles.cpp).
bool isVtkXml(std::span<const std::byte> head);
std::unique_ptr<ParticleSource> openVtkXmlParticles(InputFile file, const ReadOptions& options);
/// Houdini geometry in its modern JSON forms (houdini/): binary JSON .bgeo (magic 0x7f "NSJb")
/// and ASCII JSON .geo, as points with their numeric point attributes.
bool isHoudiniJson(std::span<const std::byte> head);
std::unique_ptr<ParticleSource> openHoudiniJson(InputFile file, const ReadOptions& options);
/// Points only, P and v: .bgeo, .geo (ASCII), .bgeo.sc and .geo.sc (scf1); refuses .gz
/// (BgeoWriter.cpp).
std::unique_ptr<ParticleWriter> createBgeoWriter(const std::filesystem::path& path, const WriteOptions& options);

/// Houdini's "seekable compressed" container (.sc: "scf1", Blosc chunks, an index, "1fcs"),
/// decoded with random access (houdini/ScfContainer.cpp).
bool isScf(InputFile& file);
std::unique_ptr<ByteSource> decodeScf(InputFile file);
/// gzip container around any of them, concatenated members allowed (GzipContainer.cpp).
bool isGzip(InputFile& file);
std::unique_ptr<ByteSource> decodeGzip(InputFile file);

/// Houdini classic geometry, version 5: binary "BgeoV" and ASCII "PGEOMETRY"
/// (houdini/ClassicBgeo.cpp, houdini/ClassicBgeoAscii.cpp).
bool isClassicBgeo(std::span<const std::byte> head);
std::unique_ptr<ParticleSource> openClassicBgeo(InputFile file, const ReadOptions& options);

/// Krakatoa PRT 1.0 and 1.1, every channel type (PrtParticles.cpp).
bool isPrt(std::span<const std::byte> head);
std::unique_ptr<ParticleSource> openPrtParticles(InputFile file, const ReadOptions& options);
/// PRT 1.0: Position and Velocity float32[3] (PrtWriter.cpp).
std::unique_ptr<ParticleWriter> createPrtWriter(const std::filesystem::path& path, const WriteOptions& options);

/// RealFlow particle cache .bin, versions 1 to 12 (RealFlowParticles.cpp). By content only:
/// the name ".bin" means raw floats.
bool isRealFlowBin(std::span<const std::byte> head);
std::unique_ptr<ParticleSource> openRealFlowParticles(InputFile file, const ReadOptions& options);

/// Maya particle disk cache .pdb, little-endian, written by a 32- or 64-bit build (PdbParticles.cpp).
bool isPdb(std::span<const std::byte> head);
std::unique_ptr<ParticleSource> openPdbParticles(InputFile file, const ReadOptions& options);

/// `count` as kCountFieldDigits zero-padded decimal digits: what a writer whose header holds the
/// particle count before the particles (PLY's element vertex, legacy VTK's POINTS) writes at
/// commit() over the zeros it reserved there. Readers take the leading zeros as a decimal. A count
/// of more digits is a programmer error (LogicError).
inline constexpr std::size_t kCountFieldDigits = 15;
inline std::string countField(std::uint64_t count) {
  std::string digits = std::to_string(count);
  FLIPSCOPE_CHECK(digits.size() <= kCountFieldDigits, "count=" << count);
  return std::string(kCountFieldDigits - digits.size(), '0') + digits;
}

/// `text` with A-Z as a-z (names, keywords and extensions compare case-insensitively).
std::string asciiLower(std::string_view text);

/// The velocity among `attributes` of a format that does not name it (VTK, Maya PDB): the
/// 3-component one named velocity, velocities, vel or v (in that order of preference,
/// case-insensitively).
std::optional<std::size_t> velocityAttributeByName(const std::vector<AttributeDesc>& attributes);
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

/// Where the values of a chunk come from in a reader of float arrays (VTK legacy and XML):
/// stream 0 holds the positions, `velocityStream` the velocities (when `velocity`), and
/// columnStreams[i] the attribute `attributes[selected[i]]`.
struct FloatStreams {
  std::size_t count = 0;  ///< streams
  bool velocity = false;
  std::size_t velocityStream = 0;
  std::vector<std::size_t> columnStreams;
};
/// Fills `chunk` with the next `n` particles of `streams`: read(stream, n, out) reads n
/// particles' values of a stream (arity(stream) floats each). A stream used twice is read once
/// and copied. The chunk's arrays are resized, not cleared: the same size is not initialised again.
void fillFromFloatStreams(ParticleChunk& chunk, std::size_t n, const FloatStreams& streams,
                          const std::vector<AttributeDesc>& attributes, const std::vector<std::size_t>& selected,
                          const std::function<int(std::size_t)>& arity,
                          const std::function<void(std::size_t, std::size_t, float*)>& read);

}  // namespace flipscope::detail
