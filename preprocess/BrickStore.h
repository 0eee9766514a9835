// BrickStore: the on-disk output of the preprocess (Reichl et al. 2014 §3, Fig. 2: "spatial
// particle binning, which is the only required preprocess"). Everything downstream reads
// bricks from here, never the original particle files.
//
// A store is a directory:
//   store.fsh               StoreHeader: format version, domain, cell size, brick size, particle spacing
//   frame_NNNNNN.fsf        one file per frame: brick payloads, then octree, brick table, footer
// Every file is written atomically (AtomicFile), so an interrupted convert leaves either no
// frame file or a complete one; frames are appended by writing new frame files.
//
// Frame file layout (little endian, offsets in bytes):
//   [payload 0][payload 1]...           each brick's payload: zstd frame of an encoded brick
//   [octree nodes][brick table]         OctreeNode[nodeCount], BrickRecord[brickCount]
//   [footer]                            FrameFooter, last kFrameFooterBytes bytes of the file
// The footer holds the checksum of the octree, the table and itself; every BrickRecord holds
// the checksum of its compressed payload, so any brick reads and verifies alone.
//
// Bricks are ordered by the Morton code of their brick coordinates; the octree is built over
// that order (see PresenceOctree.h). Thread safety: a BrickStore is immutable after open() and
// readBrick() may be called from any number of threads.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "preprocess/PresenceOctree.h"

namespace flipscope {

/// 2: StoreHeader::particleSpacing. Stores of other versions are refused (convert again).
inline constexpr std::uint32_t kStoreVersion = 2;
inline constexpr char kStoreHeaderName[] = "store.fsh";

/// The per-particle attribute a store carries, quantized to 16 bits over [min, max] of the frame.
enum class AttributeKind : std::uint32_t { None = 0, Speed = 1 };
const char* attributeName(AttributeKind kind);

/// Store-wide constants. World position of cell (i,j,k) centre:
/// origin + (ijk + 0.5) * cellSize. Brick b covers cells [b*brickSize, (b+1)*brickSize).
struct StoreHeader {
  std::uint32_t version = kStoreVersion;
  std::uint32_t brickSize = 64;       ///< cells per brick edge: 32, 64 or 128
  double cellSize = 0;                ///< world units
  glm::dvec3 origin{0};               ///< world position of the domain's min corner
  glm::uvec3 brickGrid{0};            ///< bricks per axis (each < kMortonAxisLimit)
  AttributeKind attribute = AttributeKind::None;
  /// World units: the particle spacing convert measured (ParticleSpacing.h), the cube root of
  /// the volume per particle; 0 = unknown. Not part of the domain: appending keeps the store's.
  double particleSpacing = 0;

  glm::dvec3 domainMax() const { return origin + glm::dvec3(brickGrid) * double(brickSize) * cellSize; }
  std::uint32_t cellsPerBrick() const { return brickSize * brickSize * brickSize; }
};

/// One non-empty brick of a frame (40 bytes on disk).
struct BrickRecord {
  glm::u32vec3 coord{0};       ///< brick coordinates in the brick grid
  std::uint32_t particles = 0; ///< particles binned into the brick
  std::uint32_t cells = 0;     ///< occupied cells
  std::uint32_t bytes = 0;     ///< compressed payload size
  std::uint64_t offset = 0;    ///< payload offset in the frame file
  std::uint64_t checksum = 0;  ///< checksum64 of the compressed payload
};
static_assert(sizeof(BrickRecord) == 40);

/// Per-frame totals, stored in the frame footer.
struct FrameStats {
  std::uint64_t particles = 0;        ///< binned into bricks
  std::uint64_t skippedInvalid = 0;   ///< NaN or Inf coordinates
  std::uint64_t skippedOutside = 0;   ///< outside the store's domain
  float attributeMin = 0;             ///< attribute value of quantized 0
  float attributeMax = 0;             ///< attribute value of quantized 65535
};

/// A frame's index: everything but the payloads. Immutable once loaded.
struct FrameIndex {
  int frame = 0;
  std::filesystem::path file;
  std::uint64_t fileBytes = 0;
  FrameStats stats;
  std::vector<BrickRecord> bricks;  ///< Morton order of coord
  PresenceOctree octree;
};

/// A brick's particles quantized to cells. Cells are linear indices inside the brick,
/// x + brickSize * (y + brickSize * z), strictly ascending. counts[i] >= 1 particles fell into
/// cells[i]. attributes (empty if the store has none) has one 16-bit value per particle,
/// grouped by cell in the order of `cells`, ascending within a cell.
struct DecodedBrick {
  std::vector<std::uint32_t> cells;
  std::vector<std::uint32_t> counts;
  std::vector<std::uint16_t> attributes;
  std::uint64_t particleCount() const;
};

/// Payload codec (exposed for tests and the streaming benchmark).
std::vector<std::byte> encodeBrick(const DecodedBrick& brick, int zstdLevel);
/// Throws FileError naming `file` and `brickIndex` on any malformation; checks `expected`
/// particle and cell counts and that every cell index is < cellsPerBrick.
DecodedBrick decodeBrick(std::span<const std::byte> payload, const std::filesystem::path& file, std::uint32_t brickIndex,
                         const BrickRecord& expected, std::uint32_t cellsPerBrick, bool hasAttribute);

class BrickStore {
 public:
  /// Opens an existing store; reads and verifies the header and lists the frame files.
  /// Frame indices load lazily. Throws FileError.
  static BrickStore open(const std::filesystem::path& dir);
  /// Creates a new store directory with `header`, or, if one exists, checks that its header
  /// matches (same brick size, cell size, origin, grid, attribute) and opens it for appending.
  static BrickStore createOrAppend(const std::filesystem::path& dir, const StoreHeader& header);
  static bool exists(const std::filesystem::path& dir);

  const std::filesystem::path& directory() const { return mDir; }
  const StoreHeader& header() const { return mHeader; }
  /// Frame numbers present, ascending.
  std::vector<int> frames() const;
  bool hasFrame(int frame) const;
  std::filesystem::path framePath(int frame) const;
  /// Loads (once, then cached) and verifies a frame's footer, octree and table.
  std::shared_ptr<const FrameIndex> frame(int frame) const;
  /// Reads, verifies and decodes one brick. Thread safe.
  DecodedBrick readBrick(const FrameIndex& frame, std::uint32_t brickIndex) const;
  /// Reads one brick's compressed payload and verifies its checksum. Thread safe.
  std::vector<std::byte> readPayload(const FrameIndex& frame, std::uint32_t brickIndex) const;

  /// Called by FrameWriter after committing a frame file.
  void addFrame(int frame);

 private:
  struct Shared;
  std::filesystem::path mDir;
  StoreHeader mHeader;
  std::shared_ptr<Shared> mShared;
};

/// Parses a frame file completely in memory-bounded steps (footer, octree, table).
/// Throws FileError naming the file and the field on any truncation or corruption.
FrameIndex readFrameIndex(const std::filesystem::path& file, const StoreHeader& header);

std::vector<std::byte> serializeStoreHeader(const StoreHeader& header);
StoreHeader parseStoreHeader(std::span<const std::byte> bytes, const std::filesystem::path& file);

}  // namespace flipscope
