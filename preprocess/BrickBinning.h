// BrickBinning: the in-memory core of the preprocess (Reichl et al. 2014 §3, Fig. 2).
// Particles become 64-bit sort keys (32-bit where they fit: KeyBatch::narrow); a bucket of keys
// becomes Morton-ordered, encoded bricks.
//
// Key layout (fits because a store has at most 65536 = 2^16 cells per axis):
//   [ brick Morton code : 3*(16 - log2 B) bits ][ cell in brick : 3*log2 B bits ][ attribute : 16 bits ]
// so sorting keys orders particles by brick (Morton), then cell (x fastest), then attribute:
// the canonical order of a brick payload. Keys are built as batch keys first (KeyBatch: the
// `cellKey`, 48 bits, and the attribute's value) because the attribute's quantization range is
// known only after the whole frame was read.
//
// Stores with particle kinds: the cell key carries the particle's kind (through the spill files,
// which look at the brick code only), and the full key is
// [ brick ][ cell ][ attribute : 14 bits ][ kind : 2 bits ] (binningKey). Of the
// layouts that fit 64 bits this is the simplest and fastest: nothing travels beside the keys,
// attributes stay ascending within a cell (DecodedBrick), and a cell's kind, the smallest of its
// particles', is taken on the pass that groups the cell's keys anyway. The price: attributes of
// such stores are quantized to 14 bits (widened back to 16 when stored, 0 and max kept).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "core/Box.h"
#include "core/UninitializedVector.h"
#include "preprocess/store/BrickStore.h"
#include "preprocess/store/ParticleKind.h"
#include "preprocess/particles/ParticleSource.h"

namespace flipscope::detail {

/// World -> key mapping of one store.
struct KeyGrid {
  explicit KeyGrid(const StoreHeader& header, std::optional<Box> clip = std::nullopt);

  StoreHeader header;
  std::optional<Box> clip;  ///< particles outside are skipped as "outside"
  double invCellSize;
  glm::u64vec3 cells;       ///< cells per axis of the brick grid
  std::uint32_t brickShift; ///< log2(brickSize)
  std::uint32_t cellBits;   ///< 3 * brickShift
  std::uint32_t codeBits;   ///< 3 * octree levels: bits of a brick Morton code
  /// Whether a batch key carries its particle's attribute value (see KeyBatch): the store has an
  /// attribute and a cell key fits kPackedCellBits.
  bool valueInKey;
  /// Per axis, a cell coordinate's bits of its cell key: the axis' bits of the brick's Morton
  /// code and of the cell in the brick. A cell key is the OR of its three coordinates' entries.
  std::array<std::vector<std::uint64_t>, 3> axisKeys;

  bool attribute() const { return header.attribute != AttributeKind::None; }
  /// Whether a batch's attribute values travel beside its keys (KeyBatch::values).
  bool valuesBesideKeys() const { return attribute() && !valueInKey; }
  /// Where a batch key's cell key starts: 32 when valueInKey, else 0.
  std::uint32_t cellKeyShift() const { return valueInKey ? 32 : 0; }
  /// The bits a batch key of this grid may set (KeyBatch's layouts): its cell key's, the
  /// value's where it lies in the key, and the kind's in stores with particle kinds.
  std::uint64_t batchKeyBits() const;
  /// Whether a batch key fits 32 bits (KeyBatch::narrow): a store without an attribute and
  /// without kinds, whose cell keys (brick code and cell) need at most 32 bits.
  bool narrowKeys() const { return !attribute() && batchKeyBits() <= 0xffffffffull; }
};

/// Bits of a cell key below the kind (ParticleKind in bits 48-49 of stores with kinds).
inline constexpr std::uint32_t kKindShift = 48;
inline constexpr std::uint64_t kCellKeyMask = (1ull << kKindShift) - 1;
/// Bits of a cell key below the kind in a batch key that carries its value (KeyGrid::valueInKey).
inline constexpr std::uint32_t kPackedCellBits = 30;

/// Keys [begin, end) of a batch.
struct BrickRun {
  std::size_t begin, end;
};
/// A run of a batch's keys with one brick code.
struct CodedRun {
  std::uint64_t code;
  BrickRun run;
};
/// Sorting by brick a block at a time keeps at most one run per this many keys (plus one a brick
/// of the grid): 24 bytes a 32 keys, whatever the particles' order (BrickBinning.cpp).
inline constexpr std::size_t kKeysPerRun = 32;

using KeyVector = UninitializedVector<std::uint64_t>;
using NarrowKeyVector = UninitializedVector<std::uint32_t>;
using ValueVector = UninitializedVector<float>;

/// Keys of particles, one batch key a particle, in one of two layouts (KeyGrid::valueInKey):
/// - [ kind : 2 ][ cell key : 30 ][ attribute value : float32 bits ], values empty; the usual
///   layout of stores with an attribute, 8 bytes a particle;
/// - [ kind : 2 at bit 48 ][ cell key : 48 ], and values[i] the attribute value when the store
///   has one (grids whose cell keys need more than 30 bits).
/// The attribute's quantization range is known only after the whole frame was read, so the
/// value travels with the key until binKeys() reads it.
///
/// Where the grid's batch keys fit 32 bits (KeyGrid::narrowKeys) and the batch is `narrow`, its
/// keys are kept in narrowKeys, 4 bytes each, instead of cellKeys: half the memory, and half the
/// fresh pages, whose first touch was the largest part of binning the 100 M particle frame of
/// `bench preprocess` (a fifth of its samples). A narrow key is the batch key, its upper half 0.
struct KeyBatch {
  KeyVector cellKeys;          ///< the keys, unless `narrow`
  NarrowKeyVector narrowKeys;  ///< the keys, where `narrow`
  ValueVector values;
  /// Where computeKeys() left the keys sorted by brick code a block at a time (see its
  /// contract): runs of one code each, which cover keys [0, sortedKeys), a block's runs in
  /// ascending code. binKeys() then need not sort them by brick again; keys added any other way
  /// (a spill bucket's) leave sortedKeys short of keyCount().
  std::vector<CodedRun> runs;
  std::size_t sortedKeys = 0;
  /// Whether computeKeys() sorts and keeps runs (not for keys that go to spill files).
  bool sortRuns = true;
  /// Whether the keys are narrowKeys (set by setNarrow before keys are added; only for grids
  /// whose keys fit).
  bool narrow = false;
  /// Sets `narrow` and frees the other size's keys: storage kept from batch to batch serves only
  /// the size in use, so the two are never held at once.
  void setNarrow(bool on) {
    narrow = on;
    if (on)
      KeyVector().swap(cellKeys);
    else
      NarrowKeyVector().swap(narrowKeys);
  }
  std::size_t keyCount() const { return narrow ? narrowKeys.size() : cellKeys.size(); }
  /// f(the keys' vector): narrowKeys where `narrow`, else cellKeys.
  template <class F>
  decltype(auto) withKeys(F&& f) {
    return narrow ? f(narrowKeys) : f(cellKeys);
  }
  void clear() {
    cellKeys.clear();
    narrowKeys.clear();
    values.clear();
    runs.clear();
    sortedKeys = 0;
  }
};

/// What computeKeys() kept and skipped.
struct KeyTally {
  std::uint64_t kept = 0;
  std::uint64_t invalid = 0;  ///< NaN/Inf
  std::uint64_t outside = 0;  ///< outside the grid or the clip box
  /// Over the finite attribute values of kept particles, when `ranged` (some were finite).
  bool ranged = false;
  float valueMin = 0, valueMax = 0;
};

/// The attribute value of particle i of `chunk`: |velocity| for Speed, the first column's value
/// for Scalar, the length of its components for Magnitude.
float attributeValue(const ParticleChunk& chunk, AttributeKind kind, std::size_t i);

/// The kind of a particle whose type column (converted to float) holds `flags`: Mantaflow's
/// type flags (fromMantaflowType); a value that is no int32 is liquid.
ParticleKind kindOfTypeValue(float flags);

/// Appends the batch keys of `chunk` to `out` (parallel over the chunk, deterministic order),
/// with the values of the store's attribute (attributeValue) when it has one. With `types` (a
/// column of chunk, arity 1: the particles' type flags), each key carries the particle's kind
/// (kindOfTypeValue); without, none (liquid). On grids of at most 512 bricks and 64 along an
/// axis whose values lie in the keys, each block of 16 Ki particles' keys is sorted by brick and
/// its runs kept (KeyBatch::runs), where `out` asks for them (sortRuns) and its keys so far are
/// all sorted; not where the runs would pass one per kKeysPerRun keys (plus one a brick): then
/// `out` keeps no runs, and binKeys() sorts its keys. The keys go to out.narrowKeys where `out` is
/// narrow (only for a grid whose keys fit, KeyGrid::narrowKeys, and without `types`), else to
/// out.cellKeys.
KeyTally computeKeys(const ParticleChunk& chunk, const KeyGrid& grid, KeyBatch& out,
                     const AttributeColumn* types = nullptr);

/// Quantizes value s into [0, 65535] over [min, max] (NaN and -inf: 0, +inf: 65535).
std::uint16_t quantizeAttribute(float s, float min, float max);

/// The full 64-bit key of a cell key (kind included) and its quantized attribute: without kinds
/// [cell key][attribute]; with `kinds` [cell key][attribute / 4, 14 bits][kind].
inline std::uint64_t binningKey(std::uint64_t cellKey, std::uint16_t attribute, bool kinds) {
  if (!kinds) return (cellKey << 16) | attribute;
  const std::uint64_t narrow = (std::uint64_t(attribute) * 16383 + 32767) / 65535;  // rounded to 14 bits
  return ((cellKey & kCellKeyMask) << 16) | (narrow << 2) | (cellKey >> kKindShift);
}

/// One encoded brick, ready for FrameWriter::addBrick.
struct EncodedBrick {
  glm::uvec3 coord;
  std::uint32_t particles = 0;
  std::uint32_t cells = 0;
  std::array<std::uint32_t, kParticleKindCount> kindCells{};  ///< cells of each kind (with kinds)
  UninitializedVector<std::byte> payload;
};

/// Sorts the keys of `batch` by brick (a block of them at a time, see BrickBinning.cpp), unless
/// computeKeys() did (KeyBatch::runs), groups them and encodes each brick, with a kind per cell
/// when the store has kinds; calls `sink` in ascending Morton order. The attribute is quantized
/// over [min, max] (quantizeAttribute) as each key is read: the bricks are those of the binning
/// keys (binningKey), without a pass over every key that makes them first, except where the
/// values lie beside the keys. Frees the batch's values and runs; its keys are left in another
/// order. Memory: the keys; twice the threads' count of compressed payloads; the runs, 24 bytes
/// each, at most one per kKeysPerRun keys (plus one a brick) when sorted by blocks, at most one
/// a brick in each of 8 stripes otherwise; and, kept by each thread for the next call, a block of
/// keys (64 Ki, more for grids of over 2 Ki bricks, at most 1 Mi: 8 MiB, 4 for narrow keys; a
/// thread that has binned both sizes keeps both) and a counter a brick code (at most 1 MiB).
/// `sink` runs on any one thread at a time; the brick it is given is valid only during the call.
void binKeys(KeyBatch& batch, const KeyGrid& grid, float min, float max, int zstdLevel,
             const std::function<void(const EncodedBrick&)>& sink);

}  // namespace flipscope::detail
