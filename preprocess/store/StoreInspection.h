// What `flipscope info` reports about a BrickStore, as library calls.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "preprocess/store/BrickStore.h"

namespace flipscope {

struct FrameSummary {
  int frame = 0;
  std::uint64_t particles = 0;
  std::uint64_t skippedInvalid = 0;
  std::uint64_t skippedOutside = 0;
  std::uint32_t bricks = 0;
  std::uint64_t occupiedCells = 0;
  double fillRate = 0;         ///< occupied cells / cells of the non-empty bricks
  double bitsPerParticle = 0;  ///< bit-brick representation: bricks x cells per brick / particles (§4.1)
  std::uint64_t storeBytes = 0;
  double ratioToRaw = 0;       ///< raw float32 xyz bytes (12 per particle) / store bytes
  float attributeMin = 0;      ///< the frame's attribute range (FrameStats)
  float attributeMax = 0;
  std::array<std::uint64_t, kParticleKindCount> kindCells{};  ///< FrameStats::kindCells
};

FrameSummary summarizeFrame(const FrameIndex& frame, const StoreHeader& header);

/// The particle spacing the store recorded, in cells of the store (0 when unknown).
double spacingInCells(const StoreHeader& header);

/// Why a store with no frames is refused (names no file; the caller adds store.fsh).
std::string incompleteStoreReason();

/// Checks the store's frame set against its frame table, without reading frames: one message
/// when the store has no frames (incomplete), one per listed frame whose file is missing, each
/// naming the file. Empty when every listed frame is there.
std::vector<std::string> checkFrameTable(const BrickStore& store);

/// Reads every brick of `frame`, checks its checksum and decodes it, and that the cells of each
/// particle kind add up to the footer's. Returns one message per damaged brick (naming the file
/// and the brick) or wrong count; empty when the frame is intact. Parallel.
std::vector<std::string> verifyFrame(const BrickStore& store, const FrameIndex& frame);

}  // namespace flipscope
