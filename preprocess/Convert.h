// convert(): the preprocess of Reichl et al. 2014 §3 (Fig. 2), "spatial particle binning,
// which is the only required preprocess": particle files -> BrickStore.
//
// Per frame, particles are quantized to cells of `cellSize` (world units), binned into bricks
// of brickSize^3 cells, and each brick's particles are stored contiguously (cells and counts,
// plus an optional 16-bit attribute: the speed, or any attribute of the input files),
// zstd-compressed one brick at a time; a presence octree over the non-empty bricks closes the
// frame (PresenceOctree.h).
//
// Out of core: memory stays within `memoryBudget` (plus a small constant) whatever the input
// size. Keys that do not fit are spilled to bucket files by Morton range of their brick and
// each bucket is binned on its own (recursively split when the data is skewed); the store is
// identical to an in-core conversion but for the store id (random per store).
//
// Oddities are counted, reported (FrameStats) and skipped: NaN/Inf coordinates, particles
// outside `domain`.
//
// Particle kinds (ParticleKind.h): a store has them (StoreHeader::particleKinds) when an input
// file of the convert carries a kind attribute (ConvertOptions::kindAttribute); a cell's kind is
// the smallest of its particles', and the particles of a file without a kind attribute are
// liquid (Mantaflow's FLIP file beside its secondary particles).
//
// Cell size: --cell-size, else longest domain axis / --resolution, else (neither given) one cell
// per particle spacing of the first frame (ParticleSpacing.h), falling back, with a warning, to
// kDefaultResolution cells along the longest axis when the spacing is unknown, and to the most a
// store holds (kMaxCellsPerAxis - 1 cells along it) when one per spacing would exceed
// kMaxCellsPerAxis. The spacing (ConvertOptions::particleSpacing, else
// measured) is recorded in the store header either way (StoreHeader::particleSpacing).
//
// Concurrent writers: any number of convert() calls, in any processes and on any machines of a
// shared filesystem, may add frames to one store at once (StoreLock.h). They must agree on the
// header: a store with frames (or one made by prepareOnly, joined with `append`) keeps its own.
//
// Interruptions (see BrickStore.h for the frame table): convert() takes the store's writer lock;
// when no other convert is writing the store, it removes what a killed convert left there
// (AtomicFile temporaries and spill files whose PID is gone, and frame files of the store that
// its table never listed); then it commits each frame file before listing it in store.fsh. A new store's
// store.fsh (no frames yet) and a directory convert() created are removed again when it fails
// before the first frame. Every temporary, spill file and not yet listed frame file is registered
// with CleanupOnSignal, so SIGINT, SIGTERM and SIGHUP remove them once the command installed
// installCleanupSignalHandlers() (`flipscope convert` does); creating a file and registering
// it, and listing a frame and releasing its registration, are each one DeferCleanupSignals
// step, so a signal on any thread at any moment leaves only complete, listed frames (and no
// store.fsh without frames). After SIGKILL the store holds its complete, listed frames (or no
// frames: incomplete) and the next convert removes the rest.
//
// Test hook: FLIPSCOPE_CONVERT_STOP="<point>:<n>:<KILL|INT|TERM|HUP>" raises that signal in the
// converting thread the n-th time convert passes <point>: lock (the store's lock file created, in
// the step that registers it for removal), directory (created and locked), header (store.fsh
// written), chunk (a chunk of particles read), spill (a spill file written to), brick (a brick
// appended to the frame's temporary, on the thread that appends it), frame-file (the frame file
// committed, not listed yet), frame (listed in store.fsh); and, through testStopPoint, the
// commands' own points around a convert (ConvertStopPoint.h): render-store (`render` of particle files: the store it
// converted registered for removal, before it renders).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/Box.h"
#include "core/Progress.h"
#include "preprocess/ConvertStopPoint.h"  // testStopPoint, the hook above, for a command's own points
#include "preprocess/particles/InputSequence.h"
#include "preprocess/particles/ParticleSource.h"
#include "preprocess/store/BrickStore.h"

namespace flipscope {

inline constexpr std::uint64_t kDefaultMemoryBudget = 4ull << 30;
inline constexpr std::uint32_t kMaxCellsPerAxis = 65536;
inline constexpr std::uint32_t kDefaultResolution = 1024;

struct ConvertOptions {
  std::optional<Box> domain;           ///< world units; default: bounds of all frames (an extra read pass)
  std::optional<double> cellSize;      ///< world units; default: longest domain axis / resolution
  /// Cells along the longest axis when cellSize is unset. Unset too: convert() makes one cell
  /// per particle spacing, makeStoreHeader() uses kDefaultResolution.
  std::optional<std::uint32_t> resolution;
  /// World units; default: measured on the first frame (estimateParticleSpacing: free for
  /// OpenVDB points, one or two extra reads of the frame for other sources). Given (0: unknown,
  /// not measured), convert reads no frame for it, and with `domain` given too reads each
  /// frame once. An existing store keeps its own: a different value is refused.
  std::optional<double> particleSpacing;
  std::uint32_t brickSize = 64;        ///< 32, 64 or 128
  std::uint64_t memoryBudget = kDefaultMemoryBudget;  ///< bytes
  /// The per-particle attribute to store (16 bits, quantized over each frame's [min, max]): unset
  /// (`auto`): speed when every input has velocities, else none; "none"; or a name: the inputs'
  /// attribute of that name (a scalar one as it is, a vector one by its length), else, for
  /// "speed", the length of the velocity. A name an input lacks is a FileError naming the file
  /// and what it holds. Appending keeps the store's attribute; another one asked for is refused.
  std::optional<std::string> attribute;
  /// The integer attribute that holds each particle's type, as Mantaflow's flags
  /// (fromMantaflowType): unset (`auto`): what each file's conventions name
  /// (ParticleSource::kindAttribute: Blender Mantaflow's `U` of `particles_secondary`); "none":
  /// no kinds; or a name: that attribute, in every file that has it (an input that has none is
  /// liquid). A name no input has, or one of a non-integer attribute, is a FileError naming the
  /// file and the option. Appending keeps the store's kinds: a name given for a store without
  /// kinds is refused, and the kinds `auto` finds then are dropped with a warning.
  std::optional<std::string> kindAttribute;
  /// The scene's up axis the store records (StoreHeader::upAxis): unset (`auto`): what the first
  /// input file that states one says (ParticleSource::upAxis), else Unknown. Appending keeps the
  /// store's; another axis asked for is refused.
  std::optional<UpAxis> upAxis;
  int zstdLevel = 1;
  /// Read the next chunk of particles on a thread of its own while this one is binned (and
  /// while the bounds and the spacing passes work on it): PrefetchingSource; out of core, also
  /// the next spill bucket while this one is binned. Off: one thread reads and bins in turn
  /// (spill files are still removed on threads of their own). The store is the same either way.
  bool readAhead = true;
  std::filesystem::path scratchDir;    ///< spill files; default: the store directory
  /// Add to the store at storeDir, which must exist, with its header: also a store with no
  /// frames yet (made by prepareOnly), which is otherwise started anew. What farm tasks do.
  bool append = false;
  /// Write the store header (domain, cell size and attribute as a convert of `inputs` would
  /// choose them; the particle spacing measured on the first frame) and no frames: a store that
  /// concurrent converts then fill with `append`.
  bool prepareOnly = false;
  ReadOptions read;
  Progress::Mode progress = Progress::Mode::Auto;
};

struct FrameReport {
  int frame = 0;
  FrameStats stats;
  std::uint32_t bricks = 0;
  std::uint64_t storeBytes = 0;
  double seconds = 0;
  std::uint32_t spillBuckets = 0;  ///< 0 when the frame was binned in core
  std::uint64_t spillBytes = 0;    ///< written to its spill files (SpillBuckets::bytesWritten)
};

struct ConvertReport {
  StoreHeader header;
  std::vector<FrameReport> frames;
  /// How the cell size was chosen, e.g. "particle spacing (OpenVDB grid ...)", "--cell-size".
  std::string cellSizeOrigin;
  /// How header.particleSpacing was found, or why it is unknown (0).
  std::string spacingOrigin;
  /// Where header.upAxis came from ("--up", the file that states it, "the existing store"),
  /// or why it is unknown.
  std::string upAxisOrigin;
  /// Worth telling the user (e.g. a fallback from one cell per particle spacing).
  std::vector<std::string> warnings;
};

/// Converts every frame of `inputs` into the store at `storeDir` (created, or appended to:
/// then its domain and cell size are kept). Throws InputError/FileError.
ConvertReport convert(const std::vector<FrameInput>& inputs, const std::filesystem::path& storeDir,
                      const ConvertOptions& options = {});

/// The store header for particles within `bounds` (particleSpacing from the options, else 0):
/// cell size options.cellSize, else longest axis / options.resolution (default
/// kDefaultResolution). Throws InputError when the grid would exceed kMaxCellsPerAxis cells or
/// the cell size is not positive.
/// `attribute` and `attributeName` become the header's (the name is "speed" for Speed, empty for
/// None).
StoreHeader makeStoreHeader(const Box& bounds, const ConvertOptions& options,
                            AttributeKind attribute = AttributeKind::None, const std::string& attributeName = "");

/// The bounds of the finite particle positions of every frame of `inputs` (options.read and
/// options.memoryBudget apply): the domain convert() derives without one. An empty box when
/// there are none. `particles`: how many to expect, for the progress line (0: unknown).
Box scanInputBounds(const std::vector<FrameInput>& inputs, const ConvertOptions& options, std::uint64_t particles = 0);

/// What removeStaleFiles() removed.
struct StaleFiles {
  std::uint64_t files = 0;
  std::uint64_t bytes = 0;
};

/// Removes from `dir` the spill files and, with `temporaries`, the AtomicFile temporaries that a
/// process now gone left (the PID in their names, see AtomicFile.h); never this process's own.
StaleFiles removeStaleFiles(const std::filesystem::path& dir, bool temporaries);

/// Bins one frame read from `source` into `store` (lower-level step of convert()): writes its
/// frame file, then lists it in the store's frame table. For a store with particle kinds, the
/// last column of each chunk holds the particles' type flags (fromMantaflowType).
FrameReport convertFrame(ParticleSource& source, BrickStore& store, int frame, const ConvertOptions& options,
                         Progress* progress = nullptr);

}  // namespace flipscope
