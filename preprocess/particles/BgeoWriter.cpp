// Houdini JSON geometry writer: binary JSON .bgeo (the magic 7f 'N' 'S' 'J' 'b', then UT_JID
// tokens, little-endian), its ASCII twin .geo, and either inside Houdini's scf1 container
// (.bgeo.sc, .geo.sc: Blosc LZ4, byte shuffle, 1 MiB chunks; the layout ScfContainer.cpp
// reads). The geometry is points only, laid out as Houdini's GA format writes it (the layout
// houdini/GeoScan.cpp reads): fileversion, hasindex, pointcount, vertexcount 0, primitivecount
// 0, info, an empty topology, the point attributes P (fpreal32, 3, type "point") and, with
// velocities, v (fpreal32, 3, type "vector"), each as "rawpagedata" of pages of 1024 points
// with one packed subvector and no constant pages (so the page data is the xyz triples in
// order), and no primitives. Binary strings are plain string tokens (no token table).
//
// Streaming, bounded memory: the point count appears twice before the positions (pointcount
// and the length of P's page data). Both are written as fixed-width placeholders (an int64
// token, a 64-bit length; in ASCII a space-padded field) and patched at commit(). The
// positions go straight into the output as the chunks arrive; the velocities come after every
// position, so they are kept, in their final encoding, in a SpillFile (an unnamed temporary
// file beside the output: 12 bytes a particle in binary) and appended at commit(). In memory:
// the header, the spill's 1 MiB buffer and, in ASCII, the text of kTextParticles (about 1 MiB).
//
// scf1 (ScfOutput): the decoded stream is cut into 1 MiB chunks, each Blosc-compressed as it
// fills, written in order, then the index ({1 MiB, each chunk's decoded size}, big-endian u64)
// and the footer. The placeholders lie in the first chunk, so that chunk is kept in memory until
// the second begins; if the geometry is larger than one chunk, the first is then stored
// uncompressed (a Blosc "memcpyed" chunk, which any Blosc decoder reads) so that commit() can
// patch it in place: at most 1 MiB stays uncompressed. Memory: two 1 MiB buffers and 8 bytes of
// index a chunk.
#include <blosc.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/AtomicFile.h"
#include "core/Error.h"
#include "preprocess/particles/ParticleFormats.h"
#include "preprocess/particles/SpillFile.h"

namespace flipscope::detail {
namespace {

static_assert(std::endian::native == std::endian::little && sizeof(glm::vec3) == 12,
              "binary JSON payloads and page data are written as stored in memory");

enum class Encoding { Binary, Ascii };

/// The GA layout this writer follows is the one of Houdini 18.5 (and 12 to 20).
constexpr std::string_view kFileVersion = "18.5.408";
constexpr std::int64_t kPageSize = 1024;
constexpr std::size_t kFlushBytes = std::size_t(1) << 20;
constexpr std::size_t kTextParticles = std::size_t(1) << 14;  ///< ASCII: formatted this many at a time
constexpr std::size_t kScfChunkBytes = std::size_t(1) << 20;
constexpr int kScfLevel = 5;
constexpr int kAsciiCountWidth = 20;

// Binary JSON token ids (UT_JID).
constexpr char kArrayBegin = 0x5b, kArrayEnd = 0x5d, kMapBegin = 0x7b, kMapEnd = 0x7d, kFalse = 0x30, kTrue = 0x31,
               kString = 0x27, kInt8 = 0x11, kInt16 = 0x12, kInt32 = 0x13, kInt64 = 0x14, kReal32 = 0x19,
               kReal64 = 0x1a, kUniform = 0x40;
constexpr char kLength64 = char(0xf8);

/// Where the bytes of the geometry go: the file itself, or the scf1 container around it.
class GeoOutput {
 public:
  virtual ~GeoOutput() = default;
  virtual void write(const void* data, std::size_t bytes) = 0;
  /// Overwrites bytes already written in the first 1 MiB (a placeholder).
  virtual void patch(std::uint64_t offset, const void* data, std::size_t bytes) = 0;
  /// Bytes of the geometry written so far.
  virtual std::uint64_t offset() const = 0;
  virtual void commit() = 0;
};

class PlainOutput final : public GeoOutput {
 public:
  explicit PlainOutput(const std::filesystem::path& path) : mFile(path) {}
  void write(const void* data, std::size_t bytes) override { mFile.write(data, bytes); }
  void patch(std::uint64_t offset, const void* data, std::size_t bytes) override { mFile.writeAt(offset, data, bytes); }
  std::uint64_t offset() const override { return mFile.offset(); }
  void commit() override { mFile.commit(); }

 private:
  AtomicFile mFile;
};

/// The scf1 container (see the file comment).
class ScfOutput final : public GeoOutput {
 public:
  explicit ScfOutput(const std::filesystem::path& path) : mFile(path) {
    constexpr char kHeader[12] = {'s', 'c', 'f', '1'};
    mFile.write(kHeader, sizeof kHeader);
    mChunk.reserve(kScfChunkBytes);
  }

  void write(const void* data, std::size_t bytes) override {
    const auto* in = static_cast<const std::byte*>(data);
    while (bytes > 0) {
      if (mChunk.size() == kScfChunkBytes) storeChunk(/*compress=*/!mChunkSizes.empty());
      const std::size_t n = std::min(bytes, kScfChunkBytes - mChunk.size());
      mChunk.insert(mChunk.end(), in, in + n);
      in += n;
      bytes -= n;
      mOffset += n;
    }
  }

  void patch(std::uint64_t offset, const void* data, std::size_t bytes) override {
    FLIPSCOPE_CHECK(offset + bytes <= std::min<std::uint64_t>(kScfChunkBytes, mOffset),
                    "offset=" << offset << " bytes=" << bytes);
    if (mChunkSizes.empty())
      std::memcpy(mChunk.data() + offset, data, bytes);
    else
      mFile.writeAt(mFirstChunkData + offset, data, bytes);
  }

  std::uint64_t offset() const override { return mOffset; }

  void commit() override {
    if (!mChunk.empty()) storeChunk(true);
    std::vector<std::uint64_t> index{kScfChunkBytes};
    index.insert(index.end(), mChunkSizes.begin(), mChunkSizes.end());
    index.push_back(8 * index.size());  // the footer: the index size
    std::string tail;
    for (std::uint64_t value : index)
      for (int i = 7; i >= 0; --i) tail += char((value >> (8 * i)) & 0xff);
    tail += "1fcs";
    mFile.write(tail.data(), tail.size());
    mFile.commit();
  }

 private:
  void storeChunk(bool compress) {
    mCompressed.resize(mChunk.size() + BLOSC_MAX_OVERHEAD);
    const int size = blosc_compress_ctx(compress ? kScfLevel : 0, BLOSC_SHUFFLE, 4, mChunk.size(), mChunk.data(),
                                        mCompressed.data(), mCompressed.size(), BLOSC_LZ4_COMPNAME, 0, 1);
    FLIPSCOPE_CHECK(size > 0, "blosc_compress_ctx " << size);
    if (!compress) {
      FLIPSCOPE_CHECK(std::size_t(size) == mChunk.size() + BLOSC_MAX_OVERHEAD &&
                      (std::to_integer<unsigned>(mCompressed[2]) & BLOSC_MEMCPYED));
      mFirstChunkData = mFile.offset() + BLOSC_MAX_OVERHEAD;
    }
    mFile.write(mCompressed.data(), std::size_t(size));
    mChunkSizes.push_back(mChunk.size());
    mChunk.clear();
  }

  AtomicFile mFile;
  std::vector<std::byte> mChunk;  ///< the chunk being filled
  std::vector<std::byte> mCompressed;
  std::vector<std::uint64_t> mChunkSizes;  ///< decoded, of the chunks written
  std::uint64_t mFirstChunkData = 0;       ///< file offset of the stored first chunk's bytes
  std::uint64_t mOffset = 0;
};

/// `value` as ASCII JSON text that reads back as the same float (the shortest text of the
/// double, which the reader parses as a double: exact).
void appendReal(std::string& out, double value) {
  char text[32];
  out.append(text, std::to_chars(text, text + sizeof text, value).ptr);
}

/// Appends `n` vectors as comma-separated text, a point a line; `first`: no comma yet.
void appendVectorText(std::string& out, const glm::vec3* vectors, std::size_t n, bool& first) {
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      if (!first) out += c == 0 ? ",\n" : ",";
      first = false;
      appendReal(out, double(vectors[i][c]));
    }
}

/// The JSON token writer, binary or ASCII, into a GeoOutput (through a buffer).
class GeoJson {
 public:
  GeoJson(GeoOutput& out, Encoding encoding) : mOut(out), mEncoding(encoding) {
    if (encoding == Encoding::Binary) mBuffer.append("\x7fNSJb", 5);
  }
  Encoding encoding() const { return mEncoding; }

  void beginArray() { open('[', kArrayBegin); }
  void endArray() { close(']', kArrayEnd); }
  void beginMap() { open('{', kMapBegin); }
  void endMap() { close('}', kMapEnd); }
  /// A key of a map.
  void key(std::string_view text) {
    string(text);
    if (mEncoding == Encoding::Ascii) {
      mBuffer += ':';
      mAfterKey = true;
    }
  }
  void string(std::string_view text) {  // the writer's strings need no escapes
    separate();
    if (mEncoding == Encoding::Ascii) {
      ((mBuffer += '"') += text) += '"';
      return;
    }
    mBuffer += kString;
    length(text.size());
    mBuffer += text;
  }
  void integer(std::int64_t value) {
    separate();
    if (mEncoding == Encoding::Ascii) {
      char text[24];
      mBuffer.append(text, std::to_chars(text, text + sizeof text, value).ptr);
      return;
    }
    if (value >= -128 && value <= 127) {
      mBuffer += kInt8;
      raw(std::int8_t(value));
    } else if (value >= -32768 && value <= 32767) {
      mBuffer += kInt16;
      raw(std::int16_t(value));
    } else if (value >= INT32_MIN && value <= INT32_MAX) {
      mBuffer += kInt32;
      raw(std::int32_t(value));
    } else {
      mBuffer += kInt64;
      raw(value);
    }
  }
  void real64(double value) {
    separate();
    if (mEncoding == Encoding::Ascii) return appendReal(mBuffer, value);
    mBuffer += kReal64;
    raw(value);
  }
  void boolean(bool value) {
    separate();
    if (mEncoding == Encoding::Ascii)
      mBuffer += value ? "true" : "false";
    else
      mBuffer += value ? kTrue : kFalse;
  }

  /// A non-negative integer to patch(): an int64 token (binary) or a space-padded field.
  /// Returns where its bytes are.
  std::uint64_t placeholderInteger() {
    separate();
    if (mEncoding == Encoding::Binary) mBuffer += kInt64;
    const std::uint64_t at = position();
    mBuffer.append(mEncoding == Encoding::Binary ? 8 : kAsciiCountWidth, mEncoding == Encoding::Binary ? '\0' : ' ');
    return at;
  }
  void patchInteger(std::uint64_t at, std::uint64_t value) {
    flush();
    if (mEncoding == Encoding::Binary) return mOut.patch(at, &value, 8);
    std::string text = std::to_string(value);
    FLIPSCOPE_CHECK(text.size() <= kAsciiCountWidth);
    text.insert(0, kAsciiCountWidth - text.size(), ' ');
    mOut.patch(at, text.data(), text.size());
  }

  /// An fpreal32 array, its values to follow (vectors(), or the caller's bytes); binary: a
  /// uniform array whose 64-bit length is at the returned offset (to patch with patchLength).
  std::uint64_t beginFloats(std::uint64_t count) {
    if (mEncoding == Encoding::Ascii) {
      beginArray();
      mFirstValue = true;
      return 0;
    }
    separate();
    mBuffer += kUniform;
    mBuffer += kReal32;
    mBuffer += kLength64;
    const std::uint64_t at = position();
    raw(count);
    flush();
    return at;
  }
  void patchLength(std::uint64_t at, std::uint64_t count) {
    flush();
    mOut.patch(at, &count, 8);
  }
  void vectors(const glm::vec3* data, std::size_t n) {
    if (mEncoding == Encoding::Binary) {
      flush();
      mOut.write(data, n * sizeof(glm::vec3));
      return;
    }
    for (std::size_t begin = 0; begin < n; begin += kTextParticles) {
      appendVectorText(mBuffer, data + begin, std::min(kTextParticles, n - begin), mFirstValue);
      if (mBuffer.size() >= kFlushBytes) flush();
    }
  }
  /// Bytes of the array's values as they go in the file (a spill).
  void encodedValues(std::span<const std::byte> bytes) {
    flush();
    mOut.write(bytes.data(), bytes.size());
  }
  void endFloats() {
    if (mEncoding == Encoding::Ascii) endArray();
  }

  void flush() {
    mOut.write(mBuffer.data(), mBuffer.size());
    mBuffer.clear();
  }

 private:
  std::uint64_t position() const { return mOut.offset() + mBuffer.size(); }

  template <class T>
  void raw(T value) {
    char bytes[sizeof value];
    std::memcpy(bytes, &value, sizeof value);
    mBuffer.append(bytes, sizeof value);
  }
  void length(std::uint64_t n) {
    FLIPSCOPE_CHECK(n < 0xf1);  // the writer's strings are short
    mBuffer += char(n);
  }
  /// ASCII: the comma before a value, unless it follows a key or opens its array or map.
  void separate() {
    if (mEncoding != Encoding::Ascii || mLevels.empty()) return;
    if (mAfterKey) {
      mAfterKey = false;
    } else {
      if (!mLevels.back()) mBuffer += ',';
      mLevels.back() = false;
    }
  }
  void open(char text, char token) {
    separate();
    mBuffer += mEncoding == Encoding::Ascii ? text : token;
    mLevels.push_back(true);
  }
  void close(char text, char token) {
    FLIPSCOPE_CHECK(!mLevels.empty());
    mLevels.pop_back();
    mBuffer += mEncoding == Encoding::Ascii ? text : token;
  }

  GeoOutput& mOut;
  Encoding mEncoding;
  std::string mBuffer;
  std::vector<bool> mLevels;  ///< ASCII: whether each open array or map has no element yet
  bool mAfterKey = false;
  bool mFirstValue = true;  ///< ASCII vectors(): no value written yet
};

class BgeoWriter final : public ParticleWriter {
 public:
  BgeoWriter(const std::filesystem::path& path, Encoding encoding, bool scf, const WriteOptions& options)
      : mOutput(scf ? std::unique_ptr<GeoOutput>(std::make_unique<ScfOutput>(path))
                    : std::make_unique<PlainOutput>(path)),
        mJson(*mOutput, encoding) {
    if (options.velocity) mVelocities.emplace(path.parent_path());
    mJson.beginArray();
    mJson.string("fileversion");
    mJson.string(kFileVersion);
    mJson.string("hasindex");
    mJson.boolean(false);
    mJson.string("pointcount");
    mPointCountAt = mJson.placeholderInteger();
    mJson.string("vertexcount");
    mJson.integer(0);
    mJson.string("primitivecount");
    mJson.integer(0);
    mJson.string("info");
    mJson.beginMap();
    mJson.key("software");
    mJson.string("flipscope");
    mJson.endMap();
    mJson.string("topology");
    mJson.beginArray();
    mJson.string("pointref");
    mJson.beginArray();
    mJson.string("indices");
    mJson.beginArray();
    mJson.endArray();
    mJson.endArray();
    mJson.endArray();
    mJson.string("attributes");
    mJson.beginArray();
    mJson.string("pointattributes");
    mJson.beginArray();
    mPositionLengthAt = beginAttribute("P", "point", 0);
  }

  void write(const ParticleChunk& chunk) override {
    FLIPSCOPE_CHECK(!mVelocities || chunk.velocities.size() == chunk.size(),
                    "velocities=" << chunk.velocities.size() << " positions=" << chunk.size());
    mJson.vectors(chunk.positions.data(), chunk.size());
    if (mVelocities) {
      if (mJson.encoding() == Encoding::Binary) {
        mVelocities->write(chunk.velocities.data(), chunk.size() * sizeof(glm::vec3));
      } else {
        for (std::size_t begin = 0; begin < chunk.size(); begin += kTextParticles) {
          mText.clear();
          appendVectorText(mText, chunk.velocities.data() + begin, std::min(kTextParticles, chunk.size() - begin),
                           mFirstVelocity);
          mVelocities->write(mText.data(), mText.size());
        }
      }
    }
    mCount += chunk.size();
  }

  void commit() override {
    endAttribute();
    if (mVelocities) {
      beginAttribute("v", "vector", 3 * mCount);
      mVelocities->readBack([&](std::span<const std::byte> bytes) { mJson.encodedValues(bytes); });
      endAttribute();
    }
    mJson.endArray();  // pointattributes
    mJson.endArray();  // attributes
    mJson.string("primitives");
    mJson.beginArray();
    mJson.endArray();
    mJson.endArray();
    mJson.flush();
    if (mJson.encoding() == Encoding::Ascii) mOutput->write("\n", 1);
    mJson.patchInteger(mPointCountAt, mCount);
    if (mJson.encoding() == Encoding::Binary) mJson.patchLength(mPositionLengthAt, 3 * mCount);
    mJson.flush();
    mOutput->commit();
  }

 private:
  /// A point attribute of 3 fpreal32 up to its first value; returns where its length is.
  std::uint64_t beginAttribute(std::string_view name, std::string_view typeInfo, std::uint64_t values) {
    mJson.beginArray();
    mJson.beginArray();
    for (std::string_view text : {"scope", "public", "type", "numeric", "name"}) mJson.string(text);
    mJson.string(name);
    mJson.string("options");
    mJson.beginMap();
    mJson.key("type");
    mJson.beginMap();
    mJson.key("type");
    mJson.string("string");
    mJson.key("value");
    mJson.string(typeInfo);
    mJson.endMap();
    mJson.endMap();
    mJson.endArray();
    mJson.beginArray();
    sizeAndStorage();
    mJson.string("defaults");
    mJson.beginArray();
    mJson.string("size");
    mJson.integer(1);
    mJson.string("storage");
    mJson.string("fpreal64");
    mJson.string("values");
    mJson.beginArray();
    mJson.real64(0);
    mJson.endArray();
    mJson.endArray();
    mJson.string("values");
    mJson.beginArray();
    sizeAndStorage();
    mJson.string("pagesize");
    mJson.integer(kPageSize);
    mJson.string("rawpagedata");
    return mJson.beginFloats(values);
  }
  void sizeAndStorage() {
    mJson.string("size");
    mJson.integer(3);
    mJson.string("storage");
    mJson.string("fpreal32");
  }
  void endAttribute() {
    mJson.endFloats();
    mJson.endArray();  // values
    mJson.endArray();  // the attribute's body
    mJson.endArray();  // the attribute
  }

  std::unique_ptr<GeoOutput> mOutput;
  GeoJson mJson;
  std::optional<SpillFile> mVelocities;  ///< in their final encoding
  std::uint64_t mPointCountAt = 0, mPositionLengthAt = 0;
  std::uint64_t mCount = 0;
  std::string mText;           ///< ASCII: velocities as text, kTextParticles at a time
  bool mFirstVelocity = true;  ///< ASCII: no velocity written yet
};

bool endsWith(std::string_view text, std::string_view suffix) {
  return text.size() >= suffix.size() && text.substr(text.size() - suffix.size()) == suffix;
}

}  // namespace

std::unique_ptr<ParticleWriter> createBgeoWriter(const std::filesystem::path& path, const WriteOptions& options) {
  std::string name = asciiLower(path.filename().string());
  if (endsWith(name, ".gz"))
    throw FileError(path, "cannot write gzip-compressed Houdini geometry: write .bgeo.sc (Blosc) or .bgeo instead");
  const bool scf = endsWith(name, ".sc");
  if (scf) name.resize(name.size() - 3);
  const Encoding encoding = endsWith(name, ".geo") && !endsWith(name, ".bgeo") ? Encoding::Ascii : Encoding::Binary;
  return std::make_unique<BgeoWriter>(path, encoding, scf, options);
}

}  // namespace flipscope::detail
