// CPU brick cache (Reichl et al. 2014 §4.1) with optional in-memory zstd compression.
#include "streaming/ConvertedBrickCache.h"

#include <cstring>
#include <set>

#include <zstd.h>

#include "core/Bytes.h"
#include "core/Error.h"

namespace flipscope {
namespace {

constexpr const char* kCacheName = "<converted brick cache>";

template <class T>
void putVector(ByteWriter& out, const std::vector<T>& values) {
  out.put(std::uint64_t(values.size()));
  out.putArray(std::span<const T>(values));
}

template <class T>
void getVector(ByteReader& in, std::vector<T>& values, const char* field) {
  auto count = in.get<std::uint64_t>(field);
  FLIPSCOPE_CHECK(count <= in.remaining() / sizeof(T), field << " count " << count);
  values.resize(count);
  in.getArray(std::span<T>(values), field);
}

}  // namespace

std::vector<std::byte> compressConvertedBrick(const ConvertedBrick& brick, int zstdLevel) {
  ByteWriter raw;
  raw.put(brick.key.frame);
  raw.put(brick.key.coord);
  raw.put(brick.bits.brickSize);
  raw.put(brick.bits.overlap);
  putVector(raw, brick.bits.subBricks);
  putVector(raw, brick.bits.rowOffsets);
  putVector(raw, brick.bits.subBrickOffsets);
  putVector(raw, brick.bits.attributes);
  putVector(raw, brick.mipmap);
  putVector(raw, brick.foamKinds);
  std::vector<std::byte> out(sizeof(std::uint64_t) + ZSTD_compressBound(raw.size()));
  std::uint64_t rawSize = raw.size();
  std::memcpy(out.data(), &rawSize, sizeof(rawSize));
  std::size_t written = ZSTD_compress(out.data() + sizeof(rawSize), out.size() - sizeof(rawSize), raw.view().data(),
                                      raw.size(), zstdLevel);
  FLIPSCOPE_CHECK(!ZSTD_isError(written), ZSTD_getErrorName(written));
  out.resize(sizeof(rawSize) + written);
  out.shrink_to_fit();
  return out;
}

ConvertedBrick decompressConvertedBrick(std::span<const std::byte> bytes) {
  ByteReader header(bytes, kCacheName);
  auto rawSize = header.get<std::uint64_t>("raw size");
  std::vector<std::byte> raw(rawSize);
  std::size_t read =
      ZSTD_decompress(raw.data(), raw.size(), bytes.data() + sizeof(rawSize), bytes.size() - sizeof(rawSize));
  FLIPSCOPE_CHECK(!ZSTD_isError(read) && read == rawSize, "decompressed " << read << " of " << rawSize);
  ByteReader in(raw, kCacheName);
  ConvertedBrick brick;
  brick.key.frame = in.get<int>("frame");
  brick.key.coord = in.get<glm::uvec3>("coord");
  brick.bits.brickSize = in.get<std::uint32_t>("brick size");
  brick.bits.overlap = in.get<std::uint32_t>("overlap");
  getVector(in, brick.bits.subBricks, "sub-bricks");
  getVector(in, brick.bits.rowOffsets, "row offsets");
  getVector(in, brick.bits.subBrickOffsets, "sub-brick offsets");
  getVector(in, brick.bits.attributes, "attributes");
  getVector(in, brick.mipmap, "mipmap");
  getVector(in, brick.foamKinds, "foam kinds");
  in.expectEnd("converted brick");
  return brick;
}

ConvertedBrickCache::ConvertedBrickCache(std::size_t byteBudget, bool compress)
    : mCompress(compress), mEntries(byteBudget) {}

std::shared_ptr<const ConvertedBrick> ConvertedBrickCache::find(const BrickKey& key) {
  auto found = mEntries.find(key);
  if (!found || !*found) return nullptr;
  const Entry& entry = **found;
  if (!mCompress) return entry.brick;
  return std::make_shared<const ConvertedBrick>(decompressConvertedBrick(entry.compressed));
}

void ConvertedBrickCache::insert(std::shared_ptr<const ConvertedBrick> brick) {
  auto entry = std::make_shared<Entry>();
  std::size_t bytes;
  const BrickKey key = brick->key;
  if (mCompress) {
    entry->compressed = compressConvertedBrick(*brick, 1);
    bytes = entry->compressed.size();
  } else {
    bytes = brick->bytes();
    entry->brick = std::move(brick);
  }
  mEntries.insert(key, std::move(entry), bytes + sizeof(Entry));
}

std::vector<int> ConvertedBrickCache::frames() const {
  std::set<int> frames;
  mEntries.forEachKey([&](const BrickKey& key) { frames.insert(key.frame); });
  return {frames.begin(), frames.end()};
}

}  // namespace flipscope
