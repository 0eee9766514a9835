// PLY particle files (Turk 1994, "The PLY Polygon File Format"): the vertex element's x y z and,
// when present, vx vy vz. Reads ascii, binary_little_endian and binary_big_endian with any
// scalar property type; elements after the vertex element are skipped.
//
// Attributes: every vertex property other than x, y, z is one scalar attribute, named and typed
// as the header declares it (vx, vy, vz included: PLY has no vector properties, and the reader
// groups none; the velocity is vx vy vz, and `speed` in convert is its magnitude). Writes float x y z [vx vy vz] in any
// of the three encodings; the vertex count is a fixed-width field in the header, patched on commit, so writing streams.
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cstring>
#include <sstream>

#include "core/AtomicFile.h"
#include "core/Error.h"
#include "preprocess/particles/BinaryColumns.h"
#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleFormats.h"

namespace flipscope::detail {
namespace {

constexpr std::size_t kMaxHeaderBytes = 1 << 20;
constexpr std::size_t kMaxLineBytes = 1 << 16;

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

struct PlyTypeName {
  const char* name;
  PlyType type;
};
constexpr std::array<PlyTypeName, 16> kPlyTypeNames{{{"char", PlyType::Int8},
                                                     {"int8", PlyType::Int8},
                                                     {"uchar", PlyType::UInt8},
                                                     {"uint8", PlyType::UInt8},
                                                     {"short", PlyType::Int16},
                                                     {"int16", PlyType::Int16},
                                                     {"ushort", PlyType::UInt16},
                                                     {"uint16", PlyType::UInt16},
                                                     {"int", PlyType::Int32},
                                                     {"int32", PlyType::Int32},
                                                     {"uint", PlyType::UInt32},
                                                     {"uint32", PlyType::UInt32},
                                                     {"float", PlyType::Float32},
                                                     {"float32", PlyType::Float32},
                                                     {"double", PlyType::Float64},
                                                     {"float64", PlyType::Float64}}};

std::optional<PlyType> plyTypeFromName(const std::string& name) {
  for (const auto& entry : kPlyTypeNames)
    if (name == entry.name) return entry.type;
  return std::nullopt;
}

ValueType valueTypeOf(PlyType type) {
  switch (type) {
    case PlyType::Int8:
      return ValueType::Int8;
    case PlyType::UInt8:
      return ValueType::UInt8;
    case PlyType::Int16:
      return ValueType::Int16;
    case PlyType::UInt16:
      return ValueType::UInt16;
    case PlyType::Int32:
      return ValueType::Int32;
    case PlyType::UInt32:
      return ValueType::UInt32;
    case PlyType::Float32:
      return ValueType::Float32;
    case PlyType::Float64:
      return ValueType::Float64;
  }
  return ValueType::Float32;
}

std::size_t plyTypeBytes(PlyType type) {
  switch (type) {
    case PlyType::Int8:
    case PlyType::UInt8:
      return 1;
    case PlyType::Int16:
    case PlyType::UInt16:
      return 2;
    case PlyType::Int32:
    case PlyType::UInt32:
    case PlyType::Float32:
      return 4;
    case PlyType::Float64:
      return 8;
  }
  return 0;
}

template <class Bits>
Bits swapBytes(Bits bits) {
  if constexpr (sizeof(Bits) == 2) return __builtin_bswap16(bits);
  if constexpr (sizeof(Bits) == 4) return __builtin_bswap32(bits);
  if constexpr (sizeof(Bits) == 8) return __builtin_bswap64(bits);
  return bits;
}

/// Reads one binary value of type T stored in the byte order given by `Swap`.
template <class T, bool Swap>
float decodeBinary(const std::byte* p) {
  using Bits = std::conditional_t<sizeof(T) == 1, std::uint8_t,
                                  std::conditional_t<sizeof(T) == 2, std::uint16_t,
                                                     std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>>;
  Bits bits;
  std::memcpy(&bits, p, sizeof bits);
  if constexpr (Swap) bits = swapBytes(bits);
  return static_cast<float>(std::bit_cast<T>(bits));
}

using BinaryDecoder = float (*)(const std::byte*);

template <bool Swap>
BinaryDecoder binaryDecoder(PlyType type) {
  switch (type) {
    case PlyType::Int8:
      return decodeBinary<std::int8_t, Swap>;
    case PlyType::UInt8:
      return decodeBinary<std::uint8_t, Swap>;
    case PlyType::Int16:
      return decodeBinary<std::int16_t, Swap>;
    case PlyType::UInt16:
      return decodeBinary<std::uint16_t, Swap>;
    case PlyType::Int32:
      return decodeBinary<std::int32_t, Swap>;
    case PlyType::UInt32:
      return decodeBinary<std::uint32_t, Swap>;
    case PlyType::Float32:
      return decodeBinary<float, Swap>;
    case PlyType::Float64:
      return decodeBinary<double, Swap>;
  }
  return nullptr;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::Float32;
  std::size_t offset = 0;  ///< byte offset inside a binary vertex record
};

/// What the reader needs from the header.
struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::Ascii;
  std::string formatName;  ///< as the format line spells it
  std::uint64_t vertexCount = 0;
  std::vector<PlyProperty> vertexProperties;
  std::size_t vertexBytes = 0;  ///< binary record size
  std::uint64_t dataOffset = 0;
  std::uint64_t headerLines = 0;
};

std::vector<std::string> splitWords(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string word; in >> word;) words.push_back(word);
  return words;
}

PlyHeader readPlyHeader(InputFile& file) {
  auto fail = [&](std::uint64_t line, const std::string& what) -> FileError {
    return FileError(file.path(), "PLY header line " + std::to_string(line) + ": " + what);
  };
  char magic[4] = {};
  std::size_t got = file.read(magic, 4);
  if (got < 3 || std::memcmp(magic, "ply", 3) != 0 || (got == 4 && magic[3] != '\n' && magic[3] != '\r'))
    throw FileError(file.path(), "bad magic: not a PLY file (expected 'ply' on the first line)");
  file.seek(0);
  PlyHeader header;
  std::string line;
  file.readLine(line, kMaxLineBytes);
  std::uint64_t lineNumber = 1;
  bool hasFormat = false;
  enum class Element { None, BeforeVertex, Vertex, AfterVertex } element = Element::None;
  bool seenVertex = false;
  for (;;) {
    if (!file.readLine(line, kMaxLineBytes)) throw fail(lineNumber + 1, "file ends before end_header");
    ++lineNumber;
    if (file.offset() > kMaxHeaderBytes)
      throw fail(lineNumber, "no end_header within the first " + std::to_string(kMaxHeaderBytes) + " bytes");
    auto words = splitWords(line);
    if (words.empty()) continue;
    const std::string& keyword = words[0];
    if (keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "end_header") break;
    if (keyword == "format") {
      if (words.size() != 3) throw fail(lineNumber, "expected 'format <encoding> 1.0', found '" + line + "'");
      if (words[1] == "ascii")
        header.encoding = PlyEncoding::Ascii;
      else if (words[1] == "binary_little_endian")
        header.encoding = PlyEncoding::BinaryLittleEndian;
      else if (words[1] == "binary_big_endian")
        header.encoding = PlyEncoding::BinaryBigEndian;
      else
        throw fail(lineNumber,
                   "unknown format '" + words[1] + "' (expected ascii, binary_little_endian or binary_big_endian)");
      if (words[2] != "1.0") throw fail(lineNumber, "unknown format version '" + words[2] + "' (expected 1.0)");
      header.formatName = words[1];
      hasFormat = true;
    } else if (keyword == "element") {
      if (words.size() != 3) throw fail(lineNumber, "expected 'element <name> <count>', found '" + line + "'");
      std::uint64_t count = 0;
      auto [end, ec] = std::from_chars(words[2].data(), words[2].data() + words[2].size(), count);
      if (ec != std::errc() || end != words[2].data() + words[2].size())
        throw fail(lineNumber, "malformed element count '" + words[2] + "'");
      if (words[1] == "vertex") {
        if (seenVertex) throw fail(lineNumber, "second vertex element");
        seenVertex = true;
        element = Element::Vertex;
        header.vertexCount = count;
      } else if (seenVertex) {
        element = Element::AfterVertex;
      } else {
        if (count != 0) throw fail(lineNumber, "element '" + words[1] + "' before the vertex element is not supported");
        element = Element::BeforeVertex;
      }
    } else if (keyword == "property") {
      if (element == Element::None) throw fail(lineNumber, "property before any element");
      if (words.size() >= 2 && words[1] == "list") {
        if (element == Element::Vertex)
          throw fail(lineNumber, "list property '" + words.back() + "' in the vertex element is not supported");
        continue;
      }
      if (words.size() != 3) throw fail(lineNumber, "expected 'property <type> <name>', found '" + line + "'");
      auto type = plyTypeFromName(words[1]);
      if (!type) throw fail(lineNumber, "unknown property type '" + words[1] + "' for '" + words[2] + "'");
      if (element == Element::Vertex) {
        header.vertexProperties.push_back({words[2], *type, header.vertexBytes});
        header.vertexBytes += plyTypeBytes(*type);
      }
    } else {
      throw fail(lineNumber, "unknown keyword '" + keyword + "'");
    }
  }
  if (!hasFormat) throw fail(lineNumber, "end_header before a format line");
  if (!seenVertex) throw FileError(file.path(), "PLY header has no vertex element");
  header.dataOffset = file.offset();
  header.headerLines = lineNumber;
  return header;
}

class PlyReader final : public ParticleSource {
 public:
  PlyReader(InputFile file, const ReadOptions& options) : mFile(std::move(file)) {
    const std::filesystem::path& path = mFile.path();
    mHeader = readPlyHeader(mFile);
    const char* names[6] = {"x", "y", "z", "vx", "vy", "vz"};
    for (int i = 0; i < 6; ++i) {
      for (std::size_t p = 0; p < mHeader.vertexProperties.size(); ++p)
        if (mHeader.vertexProperties[p].name == names[i]) mFields[i] = p;
      if (i < 3 && !mFields[i])
        throw FileError(path, std::string("PLY vertex element has no property '") + names[i] + "' (needs x, y, z)");
    }
    mHasVelocity = options.velocity && mFields[3] && mFields[4] && mFields[5];
    for (std::size_t p = 0; p < mHeader.vertexProperties.size(); ++p)
      if (p != *mFields[0] && p != *mFields[1] && p != *mFields[2]) {
        const PlyProperty& prop = mHeader.vertexProperties[p];
        mAttributes.push_back({prop.name, valueTypeOf(prop.type), 1});
        mAttributeProperty.push_back(p);
      }
    const std::vector<std::size_t> selected = selectAttributes(mAttributes, options, path);
    for (std::size_t index : selected) mSelected.push_back(mAttributeProperty[index]);
    mColumns = makeColumns(mAttributes, selected);
    if (mHeader.encoding != PlyEncoding::Ascii) {
      std::uint64_t available = mFile.size() - mHeader.dataOffset;
      if (available / mHeader.vertexBytes < mHeader.vertexCount) throw truncated(available / mHeader.vertexBytes);
      bool swap = mHeader.encoding == PlyEncoding::BinaryBigEndian;
      for (int i = 0; i < 6; ++i)
        if (mFields[i]) {
          PlyType type = mHeader.vertexProperties[*mFields[i]].type;
          mDecoders[i] = swap ? binaryDecoder<true>(type) : binaryDecoder<false>(type);
        }
      for (std::size_t p : mSelected) {
        PlyType type = mHeader.vertexProperties[p].type;
        mSelectedDecoders.push_back(swap ? binaryDecoder<true>(type) : binaryDecoder<false>(type));
      }
    }
  }

  std::string name() const override { return mFile.path().string(); }
  std::string format() const override { return "PLY " + mHeader.formatName + " 1.0"; }
  bool hasVelocity() const override { return mHasVelocity; }
  std::optional<std::uint64_t> countHint() const override { return mHeader.vertexCount; }
  std::vector<AttributeDesc> attributes() const override { return mAttributes; }

  bool read(ParticleChunk& chunk, std::size_t maxParticles) override {
    FLIPSCOPE_CHECK(maxParticles > 0);
    syncColumns(chunk.attributes, mColumns);
    std::uint64_t n = std::min<std::uint64_t>(maxParticles, mHeader.vertexCount - mNext);
    if (n == 0) {
      chunk.clear();
      return false;
    }
    chunk.resizeForOverwrite(n, mHasVelocity);
    for (auto& column : chunk.attributes) column.values.resize(n);
    if (mHeader.encoding == PlyEncoding::Ascii)
      readAscii(chunk, n);
    else
      readBinary(chunk, n);
    mNext += n;
    return true;
  }

  void rewind() override {
    mFile.seek(mHeader.dataOffset);
    mNext = 0;
  }
  bool readPositionsAt(std::span<const std::uint64_t> indices, std::vector<glm::vec3>& positions) override {
    if (mHeader.encoding == PlyEncoding::Ascii) return false;  // lines of any length
    const std::size_t stride = mHeader.vertexBytes;
    std::vector<std::uint64_t> offsets(indices.size());
    for (std::size_t i = 0; i < indices.size(); ++i) {
      FLIPSCOPE_CHECK(indices[i] < mHeader.vertexCount);
      offsets[i] = mHeader.dataOffset + indices[i] * stride;
    }
    std::vector<std::byte> records(indices.size() * stride);
    if (!mFile.readScattered(offsets, stride, records.data())) return false;
    positions.resize(indices.size());
    splitRecords(records.data(), indices.size(), positions.data(), nullptr);
    return true;
  }
  bool readPositionRange(std::uint64_t first, std::size_t count, std::vector<glm::vec3>& positions) override {
    if (mHeader.encoding == PlyEncoding::Ascii || !mFile.randomAccess()) return false;
    FLIPSCOPE_CHECK(first + count <= mHeader.vertexCount);
    positions.resize(count);
    // A megabyte of records at a time, into each thread's buffer (kept: no fresh pages a range).
    const std::size_t stride = mHeader.vertexBytes;
    const std::size_t slice = recordsPerSlice();
    thread_local std::vector<std::byte> records;
    for (std::size_t done = 0; done < count; done += slice) {
      const std::size_t n = std::min(slice, count - done);
      records.resize(n * stride);
      const std::size_t got =
          mFile.readAt(mHeader.dataOffset + (first + done) * stride, records.data(), records.size());
      if (got != records.size()) throw truncated(first + done + got / stride);
      splitRecords(records.data(), n, positions.data() + done, nullptr);
    }
    return true;
  }

 private:
  FileError truncated(std::uint64_t particle) const {
    return FileError(mFile.path(), "file ends at particle " + std::to_string(particle) + " of " +
                                       std::to_string(mHeader.vertexCount) + " (byte offset " +
                                       std::to_string(mHeader.dataOffset + particle * mHeader.vertexBytes) +
                                       ", vertex data starts at byte " + std::to_string(mHeader.dataOffset) + ", " +
                                       std::to_string(mHeader.vertexBytes) + " bytes a vertex)");
  }

  /// Binary records in one read of kRecordBatchBytes (at least one).
  std::size_t recordsPerSlice() const { return std::max<std::size_t>(1, kRecordBatchBytes / mHeader.vertexBytes); }

  /// About a megabyte of records at a time (readRecordBatches): the reader holds that, not a
  /// chunk's records (24 MB for a million particles of six floats), and the split reads them from
  /// the cache.
  void readBinary(ParticleChunk& chunk, std::uint64_t n) {
    const std::size_t stride = mHeader.vertexBytes;
    readRecordBatches(
        mFile, stride, std::size_t(n), mBuffer,
        [&](const std::byte* records, std::size_t count, std::size_t done) {
          splitRecords(records, count, chunk.positions.data() + done,
                       mHasVelocity ? chunk.velocities.data() + done : nullptr);
          for (std::size_t a = 0; a < mSelected.size(); ++a) {
            const std::size_t offset = mHeader.vertexProperties[mSelected[a]].offset;
            const BinaryDecoder decode = mSelectedDecoders[a];
            float* out = chunk.attributes[a].values.data() + done;
            for (std::size_t k = 0; k < count; ++k) out[k] = decode(records + k * stride + offset);
          }
        },
        [&](std::size_t inside) { return truncated(mNext + inside); });
  }

  /// The positions (and, where `velocities` is given, the velocities) of `n` binary records
  /// that lie one after the other at `records`. Thread safe.
  void splitRecords(const std::byte* records, std::uint64_t n, glm::vec3* positions, glm::vec3* velocities) const {
    const std::size_t stride = mHeader.vertexBytes;
    const bool velocity = velocities != nullptr;
    std::size_t offsets[6] = {};
    for (int i = 0; i < 6; ++i)
      if (mFields[i]) offsets[i] = mHeader.vertexProperties[*mFields[i]].offset;
    // The common case, little-endian float32 fields, is plain copies (no call a value).
    bool plainFloats = mHeader.encoding == PlyEncoding::BinaryLittleEndian;
    for (int i = 0; i < (velocity ? 6 : 3); ++i)
      plainFloats = plainFloats && mHeader.vertexProperties[*mFields[i]].type == PlyType::Float32;
    // Most writers put x, y, z (and vx, vy, vz) side by side: one 12-byte copy each.
    const bool sideBySide = offsets[1] == offsets[0] + 4 && offsets[2] == offsets[0] + 8 &&
                            (!velocity || (offsets[4] == offsets[3] + 4 && offsets[5] == offsets[3] + 8));
    if (plainFloats && sideBySide) {
      const std::byte* record = records;
      for (std::uint64_t k = 0; k < n; ++k, record += stride) {
        std::memcpy(&positions[k], record + offsets[0], sizeof(glm::vec3));
        if (velocity) std::memcpy(&velocities[k], record + offsets[3], sizeof(glm::vec3));
      }
    } else if (plainFloats) {
      for (std::uint64_t k = 0; k < n; ++k) {
        const std::byte* record = records + k * stride;
        for (int c = 0; c < 3; ++c) std::memcpy(&positions[k][c], record + offsets[c], 4);
        if (velocity)
          for (int c = 0; c < 3; ++c) std::memcpy(&velocities[k][c], record + offsets[3 + c], 4);
      }
    } else {
      for (std::uint64_t k = 0; k < n; ++k) {
        const std::byte* record = records + k * stride;
        for (int c = 0; c < 3; ++c) positions[k][c] = mDecoders[c](record + offsets[c]);
        if (velocity)
          for (int c = 0; c < 3; ++c) velocities[k][c] = mDecoders[3 + c](record + offsets[3 + c]);
      }
    }
  }

  void readAscii(ParticleChunk& chunk, std::uint64_t n) {
    const auto& props = mHeader.vertexProperties;
    std::vector<std::string_view> words;
    for (std::uint64_t k = 0; k < n; ++k) {
      std::uint64_t lineNumber = mHeader.headerLines + mNext + k + 1;
      if (!mFile.readLine(mLine, kMaxLineBytes))
        throw FileError(mFile.path(), "file ends at particle " + std::to_string(mNext + k) + " of " +
                                          std::to_string(mHeader.vertexCount) + " (line " + std::to_string(lineNumber) +
                                          ", byte offset " + std::to_string(mFile.offset()) + ")");
      // A vertex line must end with a line break: without it the file may be cut inside the
      // last number, which would read as a different value.
      if (!mFile.lineTerminated())
        throw FileError(mFile.path(), "file ends inside line " + std::to_string(lineNumber) + " (particle " +
                                          std::to_string(mNext + k) + " of " + std::to_string(mHeader.vertexCount) +
                                          ") without a line break: truncated?");
      words.clear();
      for (std::size_t i = 0; i < mLine.size();) {
        while (i < mLine.size() && std::isspace(static_cast<unsigned char>(mLine[i]))) ++i;
        std::size_t start = i;
        while (i < mLine.size() && !std::isspace(static_cast<unsigned char>(mLine[i]))) ++i;
        if (i > start) words.emplace_back(mLine.data() + start, i - start);
      }
      if (words.size() != props.size())
        throw FileError(mFile.path(), "line " + std::to_string(lineNumber) + ": expected " +
                                          std::to_string(props.size()) + " values for a vertex, found " +
                                          std::to_string(words.size()));
      auto value = [&](std::size_t property) {
        const PlyProperty& prop = props[property];
        std::string_view word = words[property];
        if (word.size() > 1 && word[0] == '+') word.remove_prefix(1);
        float result = 0;
        std::from_chars_result parsed;
        if (prop.type == PlyType::Float32) {
          parsed = std::from_chars(word.data(), word.data() + word.size(), result);
        } else {
          double wide = 0;
          parsed = std::from_chars(word.data(), word.data() + word.size(), wide);
          result = static_cast<float>(wide);
        }
        if (parsed.ec != std::errc() || parsed.ptr != word.data() + word.size())
          throw FileError(mFile.path(), "line " + std::to_string(lineNumber) + ": malformed number '" +
                                            std::string(words[property]) + "' for property '" + prop.name + "'");
        return result;
      };
      for (int c = 0; c < 3; ++c) chunk.positions[k][c] = value(*mFields[c]);
      if (mHasVelocity)
        for (int c = 0; c < 3; ++c) chunk.velocities[k][c] = value(*mFields[3 + c]);
      for (std::size_t a = 0; a < mSelected.size(); ++a) chunk.attributes[a].values[k] = value(mSelected[a]);
    }
  }

  InputFile mFile;
  PlyHeader mHeader;
  std::optional<std::size_t> mFields[6];  ///< property index of x y z vx vy vz
  BinaryDecoder mDecoders[6] = {};
  bool mHasVelocity = false;
  std::vector<AttributeDesc> mAttributes;        ///< every property but x y z, in header order
  std::vector<std::size_t> mAttributeProperty;   ///< property index of each of mAttributes
  std::vector<std::size_t> mSelected;            ///< property index of each column read
  std::vector<BinaryDecoder> mSelectedDecoders;  ///< binary: decoder of each column read
  std::vector<AttributeColumn> mColumns;         ///< the columns read, empty
  std::uint64_t mNext = 0;
  std::vector<std::byte> mBuffer;
  std::string mLine;
};

class PlyWriter final : public ParticleWriter {
 public:
  PlyWriter(const std::filesystem::path& path, const WriteOptions& options)
      : mFile(path), mEncoding(options.plyEncoding), mVelocity(options.velocity) {
    const char* format = mEncoding == PlyEncoding::Ascii                ? "ascii"
                         : mEncoding == PlyEncoding::BinaryLittleEndian ? "binary_little_endian"
                                                                        : "binary_big_endian";
    std::string header = std::string("ply\nformat ") + format + " 1.0\ncomment written by flipscope\nelement vertex ";
    mCountOffset = header.size();
    header += std::string(kCountFieldDigits, '0') + "\nproperty float x\nproperty float y\nproperty float z\n";
    if (mVelocity) header += "property float vx\nproperty float vy\nproperty float vz\n";
    header += "end_header\n";
    mFile.write(header.data(), header.size());
  }

  void write(const ParticleChunk& chunk) override {
    FLIPSCOPE_CHECK(!mVelocity || chunk.velocities.size() == chunk.size(),
                    "velocities=" << chunk.velocities.size() << " positions=" << chunk.size());
    mBuffer.clear();
    for (std::size_t k = 0; k < chunk.size(); ++k) {
      put(chunk.positions[k]);
      if (mVelocity) put(chunk.velocities[k]);
      if (mEncoding == PlyEncoding::Ascii) mBuffer.back() = '\n';
    }
    mFile.write(mBuffer.data(), mBuffer.size());
    mCount += chunk.size();
  }

  void commit() override {
    const std::string count = countField(mCount);
    mFile.writeAt(mCountOffset, count.data(), count.size());
    mFile.commit();
  }

 private:
  void put(const glm::vec3& v) {
    for (int c = 0; c < 3; ++c) {
      if (mEncoding == PlyEncoding::Ascii) {
        char text[32];
        auto end = std::to_chars(text, text + sizeof text, v[c]).ptr;
        mBuffer.insert(mBuffer.end(), text, end);
        mBuffer.push_back(' ');
      } else {
        auto bits = std::bit_cast<std::uint32_t>(v[c]);
        if (mEncoding == PlyEncoding::BinaryBigEndian) bits = swapBytes(bits);
        const char* bytes = reinterpret_cast<const char*>(&bits);
        mBuffer.insert(mBuffer.end(), bytes, bytes + 4);
      }
    }
  }

  AtomicFile mFile;
  PlyEncoding mEncoding;
  bool mVelocity;
  std::uint64_t mCountOffset = 0;
  std::uint64_t mCount = 0;
  std::vector<char> mBuffer;
};

}  // namespace

bool isPly(std::span<const std::byte> head) {
  return head.size() >= 4 && std::memcmp(head.data(), "ply", 3) == 0 &&
         (head[3] == std::byte{'\n'} || head[3] == std::byte{'\r'});
}

std::unique_ptr<ParticleSource> openPlyParticles(InputFile file, const ReadOptions& options) {
  return std::make_unique<PlyReader>(std::move(file), options);
}

std::unique_ptr<ParticleWriter> createPlyWriter(const std::filesystem::path& path, const WriteOptions& options) {
  return std::make_unique<PlyWriter>(path, options);
}

}  // namespace flipscope::detail
