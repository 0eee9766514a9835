// CPU cache of converted bricks across frames (Reichl et al. 2014 §4.1: "even the largest fluid
// simulation we preview can be stored in CPU RAM entirely"): LRU under a byte budget,
// optionally zstd-compressed in memory. Thread safe.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "streaming/BitBrick.h"
#include "streaming/BrickSource.h"
#include "streaming/LruCache.h"

namespace flipscope {

/// A brick ready for upload: bits, attributes and mipmap (streaming/glsl/BitBrick.glsl layouts),
/// and the cells whose stored kind counts as foam, in the layout of bits.subBricks (empty when
/// none does: the store has no kinds, or they are not wanted).
struct ConvertedBrick {
  BrickKey key;
  BitBrick bits;
  std::vector<std::uint32_t> mipmap;
  std::vector<glm::uvec4> foamKinds;
  std::size_t bytes() const { return bits.bytes() + mipmap.size() * 4 + foamKinds.size() * 16; }
};

/// In-memory serialization used by the compressed cache (not a file format).
std::vector<std::byte> compressConvertedBrick(const ConvertedBrick& brick, int zstdLevel);
ConvertedBrick decompressConvertedBrick(std::span<const std::byte> bytes);

class ConvertedBrickCache {
 public:
  /// byteBudget counts what the cache holds (compressed sizes when compressing).
  ConvertedBrickCache(std::size_t byteBudget, bool compress);
  /// nullptr on a miss; a compressed entry is decompressed into a new ConvertedBrick.
  std::shared_ptr<const ConvertedBrick> find(const BrickKey& key);
  void insert(std::shared_ptr<const ConvertedBrick> brick);
  bool contains(const BrickKey& key) const { return mEntries.contains(key); }
  bool isCompressing() const { return mCompress; }
  std::size_t bytes() const { return mEntries.bytes(); }
  /// The frames of which the cache holds at least one brick, ascending. Thread safe.
  std::vector<int> frames() const;
  std::size_t budget() const { return mEntries.budget(); }
  CacheStats stats() const { return mEntries.stats(); }

 private:
  struct Entry {
    std::shared_ptr<const ConvertedBrick> brick;  ///< when not compressing
    std::vector<std::byte> compressed;            ///< when compressing
  };
  bool mCompress;
  LruCache<BrickKey, Entry, BrickKeyHash> mEntries;
};

}  // namespace flipscope
