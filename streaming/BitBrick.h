// BitBrick: a brick's particles as one bit per cell, in the sub-brick layout of
// streaming/glsl/BitBrick.glsl, with an overlap border taken from the neighbouring bricks and
// optional compact per-cell attributes (Reichl et al. 2014 §3.1, §3.2, §3.3.1).
//
// Conversion works in two steps, integer and bit operations only:
//  1. BrickCells: a decoded brick's cells as a flat bitset (bit x + B*(y + B*z)), built once per
//     decoded brick, whether it is converted or only lends its border to a neighbour;
//  2. convertBrick: assembles the stored rows [-n, B+n) of the centre brick from the bitsets of
//     the 3x3x3 neighbourhood and scatters each row's nibbles into the sub-bricks.
// Simple call first: convertBrick(DecodedBrick neighbourhood, options).
//
// Attributes (§3.2): the 16-bit attribute of every set stored cell (border included) is written
// sequentially in sub-brick index order, then bit order. A sub-brick's base offset is
// rowOffsets[b + sy*c] (32 bits, one per row of sx sub-bricks) + subBrickOffsets[index]
// (16 bits): a brick may hold more than 65535 set cells, a row never does (sx*128 <= 4608).
// A cell's value is the mean (rounded down) or the maximum of its particles' 16-bit values.
//
// Thread safety: all functions are pure; BitBrick and BrickCells are plain values.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "preprocess/store/BrickStore.h"
#include "streaming/BitBrickLayout.h"

namespace flipscope {

/// How a cell's attribute is made from its particles' attributes; None stores no attributes.
enum class AttributeReduction : std::uint32_t { None = 0, Mean = 1, Max = 2 };

struct ConversionOptions {
  std::uint32_t brickSize = 64;  ///< cells per brick edge: 32, 64 or 128
  std::uint32_t overlap = 4;     ///< border cells per side, <= kMaxOverlap; >= sphere radius + jitter
  AttributeReduction attribute = AttributeReduction::None;
  /// Stores with particle kinds (DecodedBrick::kinds): drop the cells whose kind is Bubble (they
  /// lie inside the liquid), and gather the cells whose kind is Foam or Spray in
  /// BrickCells::foamKinds (for convertFoamKinds).
  bool hideBubbles = false;
  bool foamKinds = false;
};
/// Throws InputError naming the option when `options` is out of range.
void validate(const ConversionOptions& options);

struct BitBrick {
  std::uint32_t brickSize = 0;
  std::uint32_t overlap = 0;
  std::vector<glm::uvec4> subBricks;           ///< bitBrickSubBrickDims() product, GLSL layout
  std::vector<std::uint32_t> rowOffsets;       ///< per sub-brick row b + sy*c; empty without attributes
  std::vector<std::uint16_t> subBrickOffsets;  ///< per sub-brick, relative to its row
  std::vector<std::uint16_t> attributes;       ///< one per set stored cell

  glm::uvec3 subBrickDims() const { return bitBrickSubBrickDims(brickSize, overlap); }
  bool hasAttributes() const { return !rowOffsets.empty(); }
  /// Base offset of sub-brick `index` in `attributes` (§3.2 baseOffset).
  std::uint32_t attributeBase(std::uint32_t index) const;
  /// Whether brick-local `cell` (in [-overlap, brickSize + overlap)) is set.
  bool isSet(glm::ivec3 cell) const;
  /// Attribute of a set brick-local cell.
  std::uint16_t attribute(glm::ivec3 cell) const;
  std::uint64_t setCells() const;
  /// Bytes of the four arrays.
  std::size_t bytes() const;
  bool operator==(const BitBrick&) const = default;
};

/// A decoded brick's occupied cells as a flat bitset, plus what attribute lookups need.
struct BrickCells {
  std::uint32_t brickSize = 0;
  std::vector<std::uint64_t> bits;            ///< bit x + B*(y + B*z); one padding word at the end
  std::vector<std::uint32_t> wordRank;        ///< set bits before each word (with attributes only)
  std::vector<std::uint16_t> cellAttributes;  ///< reduced value per occupied cell, in cell order
  /// The cells of `bits` whose kind is Foam or Spray, in its layout; empty when there is none (no
  /// kinds, ConversionOptions::foamKinds off, or no such cell).
  std::vector<std::uint64_t> foamKinds;

  bool isSet(std::uint32_t linearCell) const { return (bits[linearCell >> 6] >> (linearCell & 63)) & 1u; }
  std::size_t bytes() const;
};

/// Builds a brick's BrickCells. Checks that cells are ascending and < brickSize^3 and that
/// attributes match the counts when `reduction` is not None (FLIPSCOPE_CHECK: the store's
/// decoder has validated the file already).
BrickCells makeBrickCells(const DecodedBrick& brick, std::uint32_t brickSize, AttributeReduction reduction);
/// The same with the kind options of `options` (hideBubbles, foamKinds).
BrickCells makeBrickCells(const DecodedBrick& brick, const ConversionOptions& options);

/// The 3x3x3 bricks around a centre: index (dx+1) + 3*(dy+1) + 9*(dz+1), centre at 13;
/// nullptr where a neighbour is empty or absent.
template <class T>
using Neighbourhood = std::array<const T*, 27>;
inline constexpr int kCentre = 13;
inline constexpr int neighbourIndex(int dx, int dy, int dz) { return (dx + 1) + 3 * (dy + 1) + 9 * (dz + 1); }

/// Converts the centre of `cells` (must not be nullptr) into a BitBrick. Every non-null entry
/// must have options.brickSize (and attributes when options.attribute is not None).
BitBrick convertBrick(const Neighbourhood<BrickCells>& cells, const ConversionOptions& options);
/// The foam kinds of the centre of `cells` (BrickCells::foamKinds) as sub-bricks in the layout
/// of convertBrick's, or empty when no brick of the neighbourhood has a foam or spray cell.
std::vector<glm::uvec4> convertFoamKinds(const Neighbourhood<BrickCells>& cells, const ConversionOptions& options);
/// Simple call: builds the BrickCells of every non-null brick, then converts.
BitBrick convertBrick(const Neighbourhood<DecodedBrick>& bricks, const ConversionOptions& options);

}  // namespace flipscope
