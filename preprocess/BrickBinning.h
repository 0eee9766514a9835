// BrickBinning: the in-memory core of the preprocess (Reichl et al. 2014 §3, Fig. 2).
// Particles become 64-bit sort keys; a bucket of keys becomes Morton-ordered, encoded bricks.
//
// Key layout (fits because a store has at most 65536 = 2^16 cells per axis):
//   [ brick Morton code : 3*(16 - log2 B) bits ][ cell in brick : 3*log2 B bits ][ attribute : 16 bits ]
// so sorting keys orders particles by brick (Morton), then cell (x fastest), then attribute:
// the canonical order of a brick payload. Keys are built without the attribute first
// (`cellKey`, 48 bits) because the attribute's quantization range is known only after the
// whole frame was read.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "core/Box.h"
#include "core/UninitializedVector.h"
#include "preprocess/store/BrickStore.h"
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

  std::uint64_t brickCodeOf(std::uint64_t cellKey) const { return cellKey >> cellBits; }
};

using KeyVector = UninitializedVector<std::uint64_t>;
using ValueVector = UninitializedVector<float>;

/// Keys of particles: cellKeys (48-bit) and, when the store has an attribute, its values.
struct KeyBatch {
  KeyVector cellKeys;
  ValueVector values;
  void clear() {
    cellKeys.clear();
    values.clear();
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

/// Appends the keys of `chunk` to `out` (parallel over the chunk, deterministic order), and the
/// values of attribute `kind` (attributeValue; not None) when it is not None.
KeyTally computeKeys(const ParticleChunk& chunk, const KeyGrid& grid, AttributeKind kind, KeyBatch& out);

/// Quantizes value s into [0, 65535] over [min, max] (NaN and -inf: 0, +inf: 65535).
std::uint16_t quantizeAttribute(float s, float min, float max);

/// One encoded brick, ready for FrameWriter::addBrick.
struct EncodedBrick {
  glm::uvec3 coord;
  std::uint32_t particles = 0;
  std::uint32_t cells = 0;
  std::vector<std::byte> payload;
};

/// Sorts `keys` (full 64-bit keys, attribute included) by brick, groups them and encodes each
/// brick; calls `sink` in ascending Morton order. `scratch` is resized to keys.size().
/// Memory: keys + scratch + one batch of compressed payloads.
void binKeys(KeyVector& keys, KeyVector& scratch, const KeyGrid& grid, bool attribute,
             int zstdLevel, const std::function<void(EncodedBrick&&)>& sink);

}  // namespace flipscope::detail
