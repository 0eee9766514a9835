// The fuzz targets' bodies, shared by the libFuzzer binaries (<Name>Fuzz.cpp, built with
// FLIPSCOPE_FUZZ=ON) and the ordinary test that replays the seed corpus and every crasher ever
// found (FuzzRegressionTest.cpp). Each takes one input and returns whether the reader accepted
// it; a refusal is a FileError (or an InputError for a camera that parses but is unusable). Any
// other exception escapes: libFuzzer reports it as a crash, and so does the regression test.
//
// Inputs:
//   vdb_points, ply, raw    a particle file (read completely, at most kMaxParticles)
//   vtk, vtu                the same, with every attribute
//   bgeo, bgeo_sc           a Houdini .bgeo or .geo (by content), and one in the scf1 container
//   classic_bgeo, prt,      a particle file, read with every attribute: Houdini classic
//   realflow_bin, pdb,      geometry, Krakatoa PRT, RealFlow .bin, Maya .pdb, and any of them
//   gzip                    gzipped
//   store_header            store.fsh (parsed as is, then again with its checksum made right)
//   frame_index             u32 n, store.fsh (n bytes), then a frame file; the index is read as
//                           is and again with its checksum made right, then every brick decoded
//   brick_payload           u32 particles, u32 cells, u8 flags (bit 0: attribute, bits 1-2:
//                           brick size 32 / 64 / 128, bit 3: the rest is the raw payload, which
//                           the target compresses; else it is the zstd payload; bit 4: a kind
//                           per cell; bit 5: attribute values as versions 3 to 6 code them,
//                           AttributeCoding::Values, else as deltas), then the payload
//   camera                  camera JSON
#pragma once

#include <sys/mman.h>
#include <unistd.h>
#include <zstd.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/Error.h"
#include "core/Hash.h"
#include "preprocess/store/BrickStore.h"
#include "preprocess/store/FrameFile.h"
#include "preprocess/particles/ParticleFormatRegistry.h"
#include "raycast/Camera.h"

namespace flipscope::fuzz {

enum class Result { Accepted, Refused };

/// Particles read from one input at most: a tiny file may claim billions of uniform points.
inline constexpr std::size_t kMaxParticles = 1 << 20;

struct Target {
  const char* name;  ///< the corpus folder: tests/fuzz/corpus/<name>, tests/fuzz/regressions/<name>
  Result (*run)(std::span<const std::byte>);
};

/// Reads `source` as readParticles does; checks the chunks' shapes against what it promised.
inline void readChunks(ParticleSource& source) {
  ParticleChunk chunk;
  std::size_t total = 0;
  for (int pass = 0; pass < 2; ++pass) {  // a second pass after rewind(), a few chunks long
    while (total < kMaxParticles && source.read(chunk, 1000)) {
      total += chunk.size();
      if (chunk.velocities.size() != (source.hasVelocity() ? chunk.size() : 0))
        throw LogicError("chunk velocities do not match hasVelocity()");
      for (const auto& column : chunk.attributes)
        if (column.arity < 1 || column.values.size() != chunk.size() * std::size_t(column.arity))
          throw LogicError("attribute column '" + column.name + "' does not match the chunk");
      if (pass == 1 && total > 3000) break;
    }
    source.rewind();
  }
  // Random access, where the source offers it, at both ends of the count it claims.
  if (const auto count = source.countHint(); count && *count > 0) {
    std::vector<glm::vec3> positions;
    const std::vector<std::uint64_t> some{0, *count / 2, *count - 1};
    if (source.readPositionsAt(some, positions) && positions.size() != some.size())
      throw LogicError("readPositionsAt gave another count");
    const std::uint64_t n = std::min<std::uint64_t>(*count, 1000);
    if (source.readPositionRange(*count - n, n, positions) && positions.size() != n)
      throw LogicError("readPositionRange gave another count");
  }
}

/// Reads a file completely (at most kMaxParticles), then again with every attribute it lists
/// (a file may list attributes it refuses to decode: that read's FileError is fine).
inline Result readParticles(const char* name, std::span<const std::byte> input) {
  try {
    auto source = openParticleBytes(name, input);
    (void)source->countHint();
    (void)source->spacingHint();
    readChunks(*source);
    const std::size_t listed = source->attributes().size();
    try {
      ReadOptions all;
      all.allAttributes = true;
      auto every = openParticleBytes(name, input, all);
      if (every->attributes().size() != listed) throw LogicError("attributes() depends on what is read");
      readChunks(*every);
    } catch (const FileError&) {
    }
    return Result::Accepted;
  } catch (const FileError&) {
    return Result::Refused;
  }
}

inline Result vdbPoints(std::span<const std::byte> input) { return readParticles("fuzz.vdb", input); }
inline Result ply(std::span<const std::byte> input) { return readParticles("fuzz.ply", input); }
inline Result raw(std::span<const std::byte> input) { return readParticles("fuzz.bin", input); }
inline Result vtk(std::span<const std::byte> input) { return readParticles("fuzz.vtk", input); }
inline Result vtu(std::span<const std::byte> input) { return readParticles("fuzz.vtu", input); }
inline Result bgeo(std::span<const std::byte> input) { return readParticles("fuzz.bgeo", input); }
inline Result bgeoSc(std::span<const std::byte> input) { return readParticles("fuzz.bgeo.sc", input); }
inline Result classicBgeo(std::span<const std::byte> input) { return readParticles("fuzz.bgeo", input); }
inline Result prt(std::span<const std::byte> input) { return readParticles("fuzz.prt", input); }
inline Result realFlowBin(std::span<const std::byte> input) { return readParticles("fuzz.bin", input); }
inline Result pdb(std::span<const std::byte> input) { return readParticles("fuzz.pdb", input); }
inline Result gzip(std::span<const std::byte> input) { return readParticles("fuzz.gz", input); }

/// Overwrites the last 8 bytes with the checksum of the bytes before them.
inline void fixTrailingChecksum(std::vector<std::byte>& bytes) {
  if (bytes.size() < 8) return;
  const std::uint64_t sum = checksum64(std::span<const std::byte>(bytes).first(bytes.size() - 8));
  std::memcpy(bytes.data() + bytes.size() - 8, &sum, 8);
}

inline Result storeHeader(std::span<const std::byte> input) {
  Result result = Result::Refused;
  std::vector<std::byte> fixed(input.begin(), input.end());
  fixTrailingChecksum(fixed);
  for (auto bytes : {input, std::span<const std::byte>(fixed)}) {
    try {
      std::vector<int> frames;
      parseStoreHeader(bytes, "store.fsh", &frames);
      result = Result::Accepted;
    } catch (const FileError&) {
    }
  }
  return result;
}

/// The frame file's index checksum (the 8 bytes before the footer magic, over the octree, the
/// table and the footer before it) made right, found through the footer's octree offset.
inline void fixIndexChecksum(std::vector<std::byte>& bytes) {
  if (bytes.size() < kFrameFooterBytes + 8) return;
  std::uint32_t version = 0;  // 24 bytes before the end in every version
  std::memcpy(&version, bytes.data() + bytes.size() - 24, 4);
  const std::uint64_t footerBytes = frameFooterBytes(version);
  if (bytes.size() < footerBytes + 8) return;
  std::uint64_t octreeOffset = 0;
  std::memcpy(&octreeOffset, bytes.data() + bytes.size() - footerBytes, 8);
  if (octreeOffset > bytes.size() - 16) return;
  const std::uint64_t sum = checksum64(bytes.data() + octreeOffset, bytes.size() - 16 - octreeOffset);
  std::memcpy(bytes.data() + bytes.size() - 16, &sum, 8);
}

/// A memory file with a path (readFrameIndex reads a path), rewritten for each input.
class MemoryFile {
 public:
  MemoryFile() : mFd(::memfd_create("flipscope-fuzz", MFD_CLOEXEC)) {
    if (mFd < 0) throw LogicError("memfd_create failed");
    mPath = "/proc/self/fd/" + std::to_string(mFd);
  }
  ~MemoryFile() { ::close(mFd); }
  MemoryFile(const MemoryFile&) = delete;
  MemoryFile& operator=(const MemoryFile&) = delete;
  const std::filesystem::path& write(std::span<const std::byte> bytes) {
    if (::ftruncate(mFd, 0) != 0 || ::pwrite(mFd, bytes.data(), bytes.size(), 0) != ssize_t(bytes.size()))
      throw LogicError("writing the memory file failed");
    return mPath;
  }

 private:
  int mFd;
  std::filesystem::path mPath;
};

inline Result frameIndex(std::span<const std::byte> input) {
  if (input.size() < 4) return Result::Refused;
  std::uint32_t headerBytes = 0;
  std::memcpy(&headerBytes, input.data(), 4);
  input = input.subspan(4);
  if (headerBytes > input.size()) return Result::Refused;
  StoreHeader header;
  try {
    std::vector<std::byte> fixed(input.begin(), input.begin() + headerBytes);
    fixTrailingChecksum(fixed);
    header = parseStoreHeader(fixed, "store.fsh");
  } catch (const FileError&) {
    return Result::Refused;
  }
  static MemoryFile file;
  const auto frame = input.subspan(headerBytes);
  std::vector<std::byte> fixed(frame.begin(), frame.end());
  fixIndexChecksum(fixed);
  Result result = Result::Refused;
  for (auto bytes : {frame, std::span<const std::byte>(fixed)}) {
    try {
      const FrameIndex index = readFrameIndex(file.write(bytes), header);
      result = Result::Accepted;
      for (std::uint32_t i = 0; i < index.bricks.size(); ++i) {  // the payloads, unchecked by their checksums
        const BrickRecord& b = index.bricks[i];
        try {
          decodeBrick(bytes.subspan(b.offset, b.bytes), "frame", i, b, header.cellsPerBrick(),
                      header.attribute != AttributeKind::None, header.particleKinds, attributeCodingOf(header.version));
        } catch (const FileError&) {
        }
      }
    } catch (const FileError&) {
    }
  }
  return result;
}

inline Result brickPayload(std::span<const std::byte> input) {
  constexpr std::size_t kHeader = 9;
  if (input.size() < kHeader) return Result::Refused;
  BrickRecord record;
  std::memcpy(&record.particles, input.data(), 4);
  std::memcpy(&record.cells, input.data() + 4, 4);
  const auto flags = std::uint8_t(input[8]);
  const bool attribute = flags & 1;
  const bool kinds = flags & 16;
  const AttributeCoding coding = flags & 32 ? AttributeCoding::Values : AttributeCoding::CellDeltas;
  const std::uint32_t brickSize = 32u << std::min((flags >> 1) & 3, 2);
  std::span<const std::byte> payload = input.subspan(kHeader);
  std::vector<std::byte> compressed;
  if (flags & 8) {
    compressed.resize(ZSTD_compressBound(payload.size()));
    const std::size_t n = ZSTD_compress(compressed.data(), compressed.size(), payload.data(), payload.size(), 1);
    if (ZSTD_isError(n)) throw LogicError("zstd compression failed");
    compressed.resize(n);
    payload = compressed;
  }
  record.bytes = std::uint32_t(payload.size());
  // Without the attributes (a render that shows none) the streams before them decode alone.
  std::optional<DecodedBrick> streams;
  try {
    streams =
        decodeBrick(payload, "brick", 0, record, brickSize * brickSize * brickSize, attribute, kinds, coding, false);
    if (streams->particleCount() != record.particles || streams->cells.size() != record.cells ||
        !streams->attributes.empty())
      throw LogicError("decodeBrick without attributes accepted a brick that does not match its record");
  } catch (const FileError&) {
  }
  try {
    const DecodedBrick brick =
        decodeBrick(payload, "brick", 0, record, brickSize * brickSize * brickSize, attribute, kinds, coding);
    if (brick.particleCount() != record.particles || brick.cells.size() != record.cells)
      throw LogicError("decodeBrick accepted a brick that does not match its record");
    if (!streams || streams->cells != brick.cells || streams->counts != brick.counts || streams->kinds != brick.kinds)
      throw LogicError("a brick decodes differently without its attributes");
    // What decodes must encode to the same brick.
    const DecodedBrick again = decodeBrick(encodeBrick(brick, 1, coding), "brick", 0, record,
                                           brickSize * brickSize * brickSize, attribute, kinds, coding);
    if (again.cells != brick.cells || again.counts != brick.counts || again.attributes != brick.attributes ||
        again.kinds != brick.kinds)
      throw LogicError("encodeBrick(decodeBrick(payload)) decodes differently");
    return Result::Accepted;
  } catch (const FileError&) {
    return Result::Refused;
  }
}

inline Result camera(std::span<const std::byte> input) {
  try {
    parseCameraJson(std::string_view(reinterpret_cast<const char*>(input.data()), input.size()), "camera.json");
    return Result::Accepted;
  } catch (const InputError&) {  // FileError, or validate()'s InputError
    return Result::Refused;
  }
}

inline constexpr Target kTargets[] = {
    {"vdb_points", vdbPoints},
    {"ply", ply},
    {"raw", raw},
    {"vtk", vtk},
    {"vtu", vtu},
    {"bgeo", bgeo},
    {"bgeo_sc", bgeoSc},
    {"classic_bgeo", classicBgeo},
    {"prt", prt},
    {"realflow_bin", realFlowBin},
    {"pdb", pdb},
    {"gzip", gzip},
    {"store_header", storeHeader},
    {"frame_index", frameIndex},
    {"brick_payload", brickPayload},
    {"camera", camera},
};

}  // namespace flipscope::fuzz
