// The frame file format of the BrickStore (layout in BrickStore.h), in one place: its magic
// numbers, the footer, and FrameWriter, which streams payloads out in brick order and writes
// octree, table and footer at the end.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <vector>

#include "core/AtomicFile.h"
#include "preprocess/store/BrickStore.h"

namespace flipscope {

inline constexpr char kFrameMagic[8] = {'F', 'S', 'F', 'R', 'A', 'M', 'E', '1'};
inline constexpr char kFooterMagic[8] = {'F', 'S', 'F', 'O', 'O', 'T', 'R', '1'};
/// The smallest footer (versions 3 and 4); version 5 adds FrameStats::kindCells.
inline constexpr std::uint64_t kFrameFooterBytes = 104;
constexpr std::uint64_t frameFooterBytes(std::uint32_t version) { return version >= 5 ? 136 : kFrameFooterBytes; }

/// The last frameFooterBytes(version) of a frame file. The version sits at the same distance
/// from the end of the file in every version, so that an old frame is named as such.
struct FrameFooter {
  std::uint64_t octreeOffset = 0;
  std::uint32_t octreeLevels = 0;
  std::uint32_t nodeCount = 0;
  std::uint64_t tableOffset = 0;
  std::uint32_t brickCount = 0;
  std::int32_t frame = 0;
  FrameStats stats;                 ///< kindCells since version 5
  StoreId storeId{};                ///< the id of the store the frame belongs to (since version 3)
  std::uint32_t version = kStoreVersion;  ///< the store's; 24 bytes before the end in every version
  std::uint32_t reserved = 0;
  std::uint64_t indexChecksum = 0;  ///< over octree, table and the footer bytes before this field
};

/// Writes one frame file atomically, carrying header.id. Bricks must be added in strictly
/// ascending Morton order of their coordinates; finish() builds the octree and commits. Not
/// thread safe.
class FrameWriter {
 public:
  FrameWriter(const std::filesystem::path& file, const StoreHeader& header, int frame);
  void addBrick(glm::uvec3 coord, std::uint32_t particles, std::uint32_t cells, std::span<const std::byte> payload);
  /// Writes octree, table and footer, then commits. Returns the index as a reader sees it.
  FrameIndex finish(const FrameStats& stats);
  std::uint64_t bytesWritten() const { return mFile.offset(); }

 private:
  StoreHeader mHeader;
  int mFrame;
  AtomicFile mFile;
  std::vector<BrickRecord> mRecords;
  std::vector<std::uint32_t> mCodes;
};

}  // namespace flipscope
