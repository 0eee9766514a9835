// Houdini's "seekable compressed" container (.bgeo.sc, .geo.sc; Houdini 16 and later), as a
// ByteSource that presents the decoded bytes with random access. Layout, as read from the files
// Houdini 17.5 and 18.5 wrote (no public description was found):
//   "scf1", 8 bytes (zero in every file seen)
//   Blosc-1 chunks, one after the other (16-byte Blosc header each: version, versionlz, flags,
//     typesize, nbytes, blocksize, cbytes; Houdini uses LZ4 with byte shuffle)
//   the index: big-endian u64 entries; every file seen has one chunk and the index
//     {1048576, decoded size}: the block size (the largest a chunk decodes to), then the size
//   footer: big-endian u64 byte size of the index, then "1fcs"
// The chunk headers are the index this source uses: it walks them once (16 bytes a chunk) and
// checks that they tile the file up to the index, and the index against them where its layout
// is known (see checkIndex). Decoded chunks are kept in a small cache (kCachedChunks), so that
// the Houdini reader's cursors, one per attribute, decode each chunk about once a pass.
// Every size is checked before anything is allocated; Blosc decodes through
// blosc_decompress_ctx after blosc_cbuffer_validate and a check of its block offsets.
#include <blosc.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>

#include "core/Error.h"
#include "preprocess/particles/ParticleFormats.h"

namespace flipscope::detail {
namespace {

constexpr unsigned char kScfMagic[4] = {'s', 'c', 'f', '1'};
constexpr unsigned char kScfFooterMagic[4] = {'1', 'f', 'c', 's'};
constexpr std::uint64_t kHeaderBytes = 12;   ///< "scf1" and 8 bytes
constexpr std::uint64_t kTrailerBytes = 12;  ///< index size, "1fcs"
constexpr std::size_t kBloscHeaderBytes = 16;
constexpr std::uint32_t kMaxChunkBytes = std::uint32_t(1) << 24;  ///< decoded; Houdini writes 1 MiB
constexpr std::uint64_t kMaxIndexBytes = std::uint64_t(1) << 24;
constexpr std::size_t kCachedChunks = 4;

std::uint64_t bigEndian64(const unsigned char* p) {
  std::uint64_t value = 0;
  for (int i = 0; i < 8; ++i) value = value << 8 | p[i];
  return value;
}
std::uint32_t littleEndian32(const unsigned char* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}

struct Chunk {
  std::uint64_t fileOffset = 0;     ///< of its Blosc header
  std::uint32_t compressedBytes = 0;
  std::uint32_t decodedBytes = 0;
  std::uint64_t decodedOffset = 0;  ///< of its first decoded byte
};

class ScfByteSource final : public ByteSource {
 public:
  explicit ScfByteSource(InputFile file) : mFile(std::move(file)) {
    const std::uint64_t size = mFile.size();
    if (size < kHeaderBytes + kTrailerBytes + kBloscHeaderBytes)
      throw error("is too small for a scf1 container (" + std::to_string(size) + " bytes): truncated?");
    unsigned char trailer[kTrailerBytes];
    readExact(size - kTrailerBytes, trailer, kTrailerBytes, "the scf1 footer");
    if (std::memcmp(trailer + 8, kScfFooterMagic, 4) != 0)
      throw error("scf1 container without its footer ('1fcs' in the last 4 bytes): truncated?");
    const std::uint64_t indexBytes = bigEndian64(trailer);
    if (indexBytes % 8 != 0 || indexBytes > size - kHeaderBytes - kTrailerBytes - kBloscHeaderBytes ||
        indexBytes > kMaxIndexBytes)
      throw error("scf1 footer: an index of " + std::to_string(indexBytes) + " bytes does not fit the file (" +
                  std::to_string(size) + " bytes)");
    const std::uint64_t indexStart = size - kTrailerBytes - indexBytes;
    for (std::uint64_t at = kHeaderBytes; at < indexStart;) {
      if (indexStart - at < kBloscHeaderBytes)
        throw error("scf1: the chunk at byte " + std::to_string(at) + " is cut off by the index at byte " +
                    std::to_string(indexStart));
      unsigned char header[kBloscHeaderBytes];
      readExact(at, header, kBloscHeaderBytes, "a Blosc chunk header");
      Chunk chunk;
      chunk.fileOffset = at;
      const std::uint32_t decoded = littleEndian32(header + 4), compressed = littleEndian32(header + 12);
      const std::string where = "scf1 chunk " + std::to_string(mChunks.size()) + " at byte " + std::to_string(at);
      if (header[0] == 0 || header[0] > BLOSC_VERSION_FORMAT)
        throw error(where + ": not a Blosc chunk (format version " + std::to_string(header[0]) + ")");
      if (compressed < kBloscHeaderBytes || compressed > indexStart - at)
        throw error(where + ": compressed size " + std::to_string(compressed) + " does not fit before the index at byte " +
                    std::to_string(indexStart));
      if (decoded == 0 || decoded > kMaxChunkBytes)
        throw error(where + ": decoded size " + std::to_string(decoded) + " is out of range (1 to " +
                    std::to_string(kMaxChunkBytes) + ")");
      chunk.compressedBytes = compressed;
      chunk.decodedBytes = decoded;
      chunk.decodedOffset = mSize;
      mChunks.push_back(chunk);
      mSize += decoded;
      at += compressed;
    }
    if (mChunks.empty()) throw error("scf1 container without chunks");
    std::vector<unsigned char> index(indexBytes);
    readExact(indexStart, index.data(), index.size(), "the scf1 index");
    checkIndex(index, indexStart);
  }

  std::uint64_t size() const override { return mSize; }

  std::size_t readAt(std::uint64_t offset, void* data, std::size_t bytes) override {
    if (offset >= mSize) return 0;
    bytes = std::size_t(std::min<std::uint64_t>(bytes, mSize - offset));
    auto* out = static_cast<std::byte*>(data);
    std::size_t done = 0;
    while (done < bytes) {
      const std::uint64_t at = offset + done;
      auto next = std::upper_bound(mChunks.begin(), mChunks.end(), at,
                                   [](std::uint64_t value, const Chunk& c) { return value < c.decodedOffset; });
      const std::size_t index = std::size_t(next - mChunks.begin()) - 1;
      const std::vector<std::byte>& decoded = chunkBytes(index);
      const auto within = std::size_t(at - mChunks[index].decodedOffset);
      const std::size_t n = std::min(bytes - done, decoded.size() - within);
      std::memcpy(out + done, decoded.data() + within, n);
      done += n;
    }
    return done;
  }

 private:
  FileError error(const std::string& message) const { return FileError(mFile.path(), message); }

  void readExact(std::uint64_t offset, void* data, std::size_t bytes, const char* what) {
    if (mFile.readAt(offset, data, bytes) != bytes)
      throw error(std::string("truncated: the file ends inside ") + what + " (at byte " + std::to_string(offset) + ")");
  }

  /// The index against the chunks, where its layout is known: {block size, decoded size} for a
  /// single chunk (every file seen); for several, {block size, total} or {block size, then each
  /// chunk's decoded size, or its decoded end}. Other layouts are left unchecked.
  void checkIndex(const std::vector<unsigned char>& index, std::uint64_t indexStart) const {
    const std::size_t entries = index.size() / 8;
    auto entry = [&](std::size_t i) { return bigEndian64(index.data() + 8 * i); };
    const std::string where = "scf1 index at byte " + std::to_string(indexStart);
    if (entries == 2) {
      if (entry(1) != mSize)
        throw error(where + ": it gives a decoded size of " + std::to_string(entry(1)) + ", the chunks hold " +
                    std::to_string(mSize) + " bytes");
      if (mChunks.size() == 1 && entry(0) < mChunks[0].decodedBytes)
        throw error(where + ": block size " + std::to_string(entry(0)) + " is smaller than its chunk (" +
                    std::to_string(mChunks[0].decodedBytes) + " bytes)");
    } else if (mChunks.size() > 1 && entries == mChunks.size() + 1) {
      bool sizes = true, ends = true;
      for (std::size_t i = 0; i < mChunks.size(); ++i) {
        sizes = sizes && entry(i + 1) == mChunks[i].decodedBytes;
        ends = ends && entry(i + 1) == mChunks[i].decodedOffset + mChunks[i].decodedBytes;
      }
      if (!sizes && !ends)
        throw error(where + ": its entries match neither the sizes nor the ends of the " +
                    std::to_string(mChunks.size()) + " chunks");
    }
  }

  const std::vector<std::byte>& chunkBytes(std::size_t index) {
    ++mUse;
    for (auto& slot : mCache)
      if (slot.chunk == index) {
        slot.lastUse = mUse;
        return slot.bytes;
      }
    auto slot = std::min_element(mCache.begin(), mCache.end(),
                                 [](const Cached& a, const Cached& b) { return a.lastUse < b.lastUse; });
    slot->chunk = std::numeric_limits<std::size_t>::max();
    decode(mChunks[index], index, slot->bytes);
    slot->chunk = index;
    slot->lastUse = mUse;
    return slot->bytes;
  }

  void decode(const Chunk& chunk, std::size_t index, std::vector<std::byte>& out) {
    const std::string where = "scf1 chunk " + std::to_string(index) + " at byte " + std::to_string(chunk.fileOffset);
    mCompressed.resize(chunk.compressedBytes);
    readExact(chunk.fileOffset, mCompressed.data(), mCompressed.size(), "a Blosc chunk");
    const unsigned char* src = mCompressed.data();
    std::size_t nbytes = 0;
    if (blosc_cbuffer_validate(src, mCompressed.size(), &nbytes) != 0 || nbytes != chunk.decodedBytes)
      throw error(where + ": damaged Blosc header");
    const std::uint8_t flags = src[2];
    if (flags & BLOSC_MEMCPYED) {
      if (std::size_t(chunk.compressedBytes) != kBloscHeaderBytes + nbytes)
        throw error(where + ": a stored (uncompressed) chunk of the wrong size");
    } else {
      // The offsets of Blosc's blocks, which follow the header, must point into the chunk.
      const std::uint32_t blockSize = littleEndian32(src + 8);
      if (blockSize == 0) throw error(where + ": Blosc block size 0");
      const std::uint64_t blocks = (nbytes + blockSize - 1) / blockSize;
      if (kBloscHeaderBytes + 4 * blocks > chunk.compressedBytes) throw error(where + ": Blosc block table does not fit");
      for (std::uint64_t b = 0; b < blocks; ++b) {
        const std::uint32_t start = littleEndian32(src + kBloscHeaderBytes + 4 * b);
        if (start < kBloscHeaderBytes + 4 * blocks || start >= chunk.compressedBytes)
          throw error(where + ": Blosc block " + std::to_string(b) + " starts outside the chunk");
      }
    }
    out.resize(nbytes);
    const int got = blosc_decompress_ctx(src, out.data(), out.size(), 1);
    if (got < 0 || std::size_t(got) != nbytes)
      throw error(where + ": Blosc cannot decompress it (error " + std::to_string(got) + "): damaged data");
  }

  struct Cached {
    std::size_t chunk = std::numeric_limits<std::size_t>::max();
    std::uint64_t lastUse = 0;
    std::vector<std::byte> bytes;
  };

  InputFile mFile;
  std::vector<Chunk> mChunks;
  std::uint64_t mSize = 0;
  std::array<Cached, kCachedChunks> mCache;
  std::uint64_t mUse = 0;
  std::vector<unsigned char> mCompressed;
};

}  // namespace

bool isScf(InputFile& file) {
  const std::vector<std::byte> head = file.peekHead(4);
  return head.size() == 4 && std::memcmp(head.data(), kScfMagic, 4) == 0;
}

std::unique_ptr<ByteSource> decodeScf(InputFile file) { return std::make_unique<ScfByteSource>(std::move(file)); }

}  // namespace flipscope::detail
