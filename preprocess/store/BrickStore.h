// BrickStore: the on-disk output of the preprocess (Reichl et al. 2014 §3, Fig. 2: "spatial
// particle binning, which is the only required preprocess"). Everything downstream reads
// bricks from here, never the original particle files.
//
// A store is a directory:
//   store.fsh               StoreHeader: format version, domain, cell size, brick size, particle
//                           spacing, the store's random 128-bit id, the per-particle attribute
//                           (its kind and name) and its range over the frames, whether bricks
//                           carry particle kinds (version 5), the scene's up axis (version 6),
//                           and the frame table
//   frame_NNNNNN.fsf        one file per frame: brick payloads, then octree, brick table, footer
//   store.lock              the writers' locks (StoreLock.h); readers ignore it
// Every file is written atomically (AtomicFile). The frame table in store.fsh lists the frames
// of the store; it is rewritten (atomically) after each frame file is committed, so after an
// interruption at any moment every listed frame is complete. Any number of writers may add
// frames to one store at once, on one machine or over a shared filesystem (store.lock,
// StoreLock.h); two writers of the same frame each rename a complete file into place, and
// the last one wins. A frame file the table does not
// list is not part of the store (readers ignore it; the next convert removes it when it carries
// the store's id). A store whose table is empty is incomplete (an interrupted or failed first
// convert): `info` refuses it and the next convert into it starts it anew. Each frame file's
// footer carries the store id, so a frame file from another store is refused.
//
// Frame file layout (little endian, offsets in bytes):
//   [payload 0][payload 1]...           each brick's payload: zstd frame of an encoded brick
//   [octree nodes][brick table]         OctreeNode[nodeCount], BrickRecord[brickCount]
//   [footer]                            FrameFooter, last kFrameFooterBytes bytes of the file
// The footer holds the checksum of the octree, the table and itself; every BrickRecord holds
// the checksum of its compressed payload, so any brick reads and verifies alone.
//
// Bricks are ordered by the Morton code of their brick coordinates; the octree is built over
// that order (see PresenceOctree.h). Thread safety: a BrickStore's header is immutable after
// open(); readBrick() may be called from any number of threads; addFrame() (the writer's) is
// serialised internally.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/UninitializedVector.h"
#include "core/UpAxis.h"
#include "preprocess/store/ParticleKind.h"
#include "preprocess/store/PresenceOctree.h"

namespace flipscope {

/// 2: StoreHeader::particleSpacing. 3: the store id (in store.fsh and every frame footer) and
/// the frame table. 4: the attribute's name (any attribute of the input files, not only speed)
/// and the store's attribute range in store.fsh; frame files unchanged but for their version.
/// 5: StoreHeader::particleKinds in store.fsh, a kind per cell in the payloads of such stores,
/// and FrameStats::kindCells in the frame footer (136 bytes, 104 before).
/// 6: StoreHeader::upAxis in store.fsh; frame files unchanged but for their version.
/// 7: payloads code their attribute values as deltas in byte planes (AttributeCoding); store.fsh
/// unchanged but for its version.
/// Version 3 to 6 stores are read and appended to as what they are (attribute values as they
/// are; version 3 to 5: no up axis; version 3 and 4: no kinds; version 3: speed or no attribute,
/// its range gathered from the frames); older ones are refused (convert again).
inline constexpr std::uint32_t kStoreVersion = 7;
inline constexpr std::uint32_t kOldestStoreVersion = 3;
inline constexpr char kStoreHeaderName[] = "store.fsh";
/// Frame numbers a store holds: 0 to kMaxFrame (six digits in the file name).
inline constexpr int kMaxFrame = 999999;

/// A store's identity: 16 random bytes (all zero: none yet).
using StoreId = std::array<std::uint8_t, 16>;
StoreId randomStoreId();
std::string storeIdText(const StoreId& id);  ///< 32 hex digits

/// The per-particle attribute a store carries, quantized to 16 bits over [min, max] of the frame:
/// none, the speed (magnitude of the input's velocity), a scalar attribute of the input files, or
/// the magnitude of a vector attribute of theirs (StoreHeader::attributeName names it).
enum class AttributeKind : std::uint32_t { None = 0, Speed = 1, Scalar = 2, Magnitude = 3 };
/// "none", "speed", "scalar", "magnitude".
const char* attributeKindName(AttributeKind kind);
/// Longest StoreHeader::attributeName.
inline constexpr std::size_t kMaxAttributeNameBytes = 255;

/// Values of the stored attribute, min <= max.
struct AttributeRange {
  float min = 0;
  float max = 0;
  bool operator==(const AttributeRange&) const = default;
};

/// Store-wide constants. World position of cell (i,j,k) centre:
/// origin + (ijk + 0.5) * cellSize. Brick b covers cells [b*brickSize, (b+1)*brickSize).
struct StoreHeader {
  std::uint32_t version = kStoreVersion;
  std::uint32_t brickSize = 64;       ///< cells per brick edge: 32, 64 or 128
  double cellSize = 0;                ///< world units
  glm::dvec3 origin{0};               ///< world position of the domain's min corner
  glm::uvec3 brickGrid{0};            ///< bricks per axis (each < kMortonAxisLimit)
  AttributeKind attribute = AttributeKind::None;
  /// The attribute's name: "speed" for Speed, the input files' name of it for Scalar and
  /// Magnitude, empty for None. What `info` prints and the EXR channel of `render` is called.
  std::string attributeName;
  /// World units: the particle spacing convert measured (ParticleSpacing.h), the cube root of
  /// the volume per particle; 0 = unknown. Not part of the domain: appending keeps the store's.
  double particleSpacing = 0;
  /// Made by BrickStore::createOrAppend for a new store (random unless given); frames carry it.
  StoreId id{};
  /// Every brick carries a ParticleKind per occupied cell (DecodedBrick::kinds). Version 5 only.
  /// convert quantizes the attribute of such stores to 14 bits (BrickBinning.h).
  bool particleKinds = false;
  /// The scene's up axis as convert learnt it (`convert --up`, else the input files'
  /// conventions: ParticleSource::upAxis); what `render` and `view` frame with unless given
  /// `--up`. Version 6 only; Unknown in older stores and when nobody said.
  UpAxis upAxis = UpAxis::Unknown;

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
  /// Occupied cells of each kind (index: ParticleKind), summed over the bricks; all zero in a
  /// store without particle kinds, and not stored before version 5.
  std::array<std::uint64_t, kParticleKindCount> kindCells{};
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
/// grouped by cell in the order of `cells`, ascending within a cell. kinds (empty if the store
/// has no particle kinds) has the kind of each cell, in the order of `cells`.
struct DecodedBrick {
  std::vector<std::uint32_t> cells;
  std::vector<std::uint32_t> counts;
  std::vector<std::uint16_t> attributes;
  std::vector<ParticleKind> kinds;
  std::uint64_t particleCount() const;
};

/// How a payload holds its attribute values (BrickCodec.cpp): as they are (versions 3 to 6), or,
/// from version 7, as deltas in byte planes, which zstd packs into about half the bytes.
enum class AttributeCoding { Values, CellDeltas };
inline constexpr AttributeCoding attributeCodingOf(std::uint32_t storeVersion) {
  return storeVersion >= 7 ? AttributeCoding::CellDeltas : AttributeCoding::Values;
}

/// The coding this version writes.
inline constexpr AttributeCoding kAttributeCoding = attributeCodingOf(kStoreVersion);

/// Payload codec (exposed for tests and the streaming benchmark); `coding` is the store
/// version's (attributeCodingOf): no default, so that no caller codes an older store's payloads
/// as this version's.
std::vector<std::byte> encodeBrick(const DecodedBrick& brick, int zstdLevel, AttributeCoding coding);
/// encodeBrick into `payload`, whose capacity is reused: binning recycles a few payload
/// buffers, where a fresh one per brick cost a first touch of every payload page.
void encodeBrickInto(const DecodedBrick& brick, int zstdLevel, UninitializedVector<std::byte>& payload,
                     AttributeCoding coding);
/// Throws FileError naming `file` and `brickIndex` on any malformation; checks `expected`
/// particle and cell counts, that every cell index is < cellsPerBrick and, with `hasKinds`,
/// that every kind is < kParticleKindCount. Without `readAttributes`, a payload's attribute
/// values (`hasAttribute`) stay compressed and `attributes` empty: only the streams before them
/// are decompressed and checked (a render that shows no attribute; most of a payload's bytes).
DecodedBrick decodeBrick(std::span<const std::byte> payload, const std::filesystem::path& file,
                         std::uint32_t brickIndex, const BrickRecord& expected, std::uint32_t cellsPerBrick,
                         bool hasAttribute, bool hasKinds, AttributeCoding coding, bool readAttributes = true);

class BrickStore {
 public:
  /// Opens an existing store; reads and verifies the header and its frame table. Frame indices
  /// load lazily. Throws FileError. A store with no frames opens (see incomplete()).
  static BrickStore open(const std::filesystem::path& dir);
  /// What createOrAppend does with an existing store that has no frames yet: replace it (an
  /// interrupted first convert, when its writer is alone in the store), or join it (a store made
  /// by `convert --prepare`, or one that another writer is creating now).
  enum class FramelessStore { Replace, Join };
  /// Creates a new store directory with `header` (its id, or a random one when it is all
  /// zero), or, if a store with frames exists (or one without, to join), checks that its header
  /// matches (same brick size, cell size, origin, grid, attribute, particle kinds) and opens it
  /// for appending (a version 3 or 4 store stays one: no particle kinds).
  /// Under the table lock (StoreLock.h), so concurrent writers agree on one store.
  /// `created`, when given, says whether this call wrote store.fsh.
  static BrickStore createOrAppend(const std::filesystem::path& dir, const StoreHeader& header,
                                   FramelessStore frameless = FramelessStore::Replace, bool* created = nullptr);
  /// Removes store.fsh of the store `id` while it lists no frame (under the table lock): what a
  /// writer whose first frame failed does with the header it made. False when another writer
  /// listed a frame meanwhile, or the header is another store's.
  static bool removeIfFrameless(const std::filesystem::path& dir, const StoreId& id);
  static bool exists(const std::filesystem::path& dir);

  const std::filesystem::path& directory() const { return mDir; }
  const StoreHeader& header() const { return mHeader; }
  /// The frame table: the frames of the store, ascending.
  std::vector<int> frames() const;
  bool hasFrame(int frame) const;
  /// No frame yet: an interrupted or failed first convert.
  bool incomplete() const { return frames().empty(); }
  std::filesystem::path framePath(int frame) const;
  /// Listed frames whose file is not a regular file (gone, or something else in its place),
  /// ascending.
  std::vector<int> missingFrames() const;
  /// Why listed frame `frame` has no file (for FileError on framePath(frame)): "missing: ...",
  /// naming what is there instead when something is. Empty when its file is a regular file.
  std::string missingFrameReason(int frame) const;
  /// Files in the directory named like frame files whose frame the table does not list.
  std::vector<std::filesystem::path> unlistedFrameFiles() const;
  /// Loads (once, then cached) and verifies a frame's footer, octree and table. Throws
  /// InputError for a frame the table does not list, FileError naming the file when it is
  /// missing, damaged or from another store.
  std::shared_ptr<const FrameIndex> frame(int frame) const;
  /// Reads, verifies and decodes one brick; without `attributes`, leaves its attribute values
  /// compressed (decodeBrick's readAttributes). Thread safe.
  DecodedBrick readBrick(const FrameIndex& frame, std::uint32_t brickIndex, bool attributes = true) const;
  /// Reads one brick's compressed payload and verifies its checksum. Thread safe.
  UninitializedVector<std::byte> readPayload(const FrameIndex& frame, std::uint32_t brickIndex) const;

  /// The range of the attribute over the store's frames (those with particles): recorded in
  /// store.fsh since version 4 (a frame converted again widens it, never narrows it), gathered
  /// from the frames' footers for version 3. nullopt without attribute or particles. Throws
  /// FileError for a version 3 store with a missing or damaged frame.
  std::optional<AttributeRange> attributeRange() const;

  /// Re-reads the frame table from store.fsh and adds the frames that other writers listed
  /// since (what a viewer does while a convert fills the store). Returns whether any was added.
  /// Thread safe. Throws FileError when store.fsh is unreadable or now another store's.
  bool reloadFrameTable();

  /// Lists `frame` in the frame table, widening the attribute range by `stats` (rewrites store.fsh
  /// atomically when either changes). Called after the frame file is committed. Under the table
  /// lock, merging the frames other writers listed meanwhile (StoreLock.h). Throws FileError,
  /// also when store.fsh now belongs to another store (started anew meanwhile).
  void addFrame(int frame, const FrameStats& stats = {});

 private:
  struct Shared;
  std::filesystem::path mDir;
  StoreHeader mHeader;
  std::shared_ptr<Shared> mShared;
};

/// Parses a frame file completely in memory-bounded steps (footer, octree, table).
/// Throws FileError naming the file and the field on any truncation or corruption, and when
/// the footer's store id is not header.id (a frame of another store).
FrameIndex readFrameIndex(const std::filesystem::path& file, const StoreHeader& header);

/// store.fsh: the header, the attribute range (since version 4), the particle kinds flag (since
/// version 5) and the frame table (frames ascending, unique, 0..kMaxFrame; stored as runs of
/// consecutive frames), in the layout of header.version (3, 4 or 5).
std::vector<std::byte> serializeStoreHeader(const StoreHeader& header, const std::vector<int>& frames = {},
                                            const std::optional<AttributeRange>& range = std::nullopt);
/// Throws FileError on any truncation, corruption, unknown version or trailing bytes. The frame
/// table goes to `frames` and the attribute range (since version 4; nullopt for 3) to `range`
/// when given.
StoreHeader parseStoreHeader(std::span<const std::byte> bytes, const std::filesystem::path& file,
                             std::vector<int>* frames = nullptr, std::optional<AttributeRange>* range = nullptr);

/// The frame file name of `frame` (frame_NNNNNN.fsf), and back (nullopt for other names).
std::string frameFileName(int frame);
std::optional<int> frameFromFileName(const std::string& name);

}  // namespace flipscope
