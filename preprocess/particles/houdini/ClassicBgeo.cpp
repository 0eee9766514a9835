// Houdini classic binary geometry ("BgeoV", GPD version 5; see ClassicBgeo.h for the layout),
// read as particles: the points, with every numeric point attribute. Big-endian throughout;
// strings are a var16 length (an int16, or -1 and an int32) and their bytes.
//
// The points are read in chunks, about 1 MiB of records at a time (readRecordBatches), decoded
// while they are in cache (memory: the chunk and that batch). What follows them is checked once
// the last point has been read: the vertex and primitive dictionaries, the primitives (particle
// systems, "Part", are walked and their point indices checked), the detail attributes and the
// extra section, which ends the file with 00 ff. Where the file holds something this reader
// cannot walk (other primitive types, groups, unknown attribute types after the points), the
// rest is taken on trust, except that the file must still end with the end marker 0xff.
#include "preprocess/particles/houdini/ClassicBgeo.h"

#include <algorithm>
#include <array>
#include <cstring>

#include "core/Error.h"
#include "preprocess/particles/BinaryColumns.h"
#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleFormats.h"

namespace flipscope::detail {
namespace houdini {

std::string classicTypeName(std::int32_t type) {
  switch (type) {
    case 0:
      return "float";
    case 1:
      return "int";
    case 2:
      return "string";
    case 3:
      return "mixed";
    case 4:
      return "index";
    case 5:
      return "vector";
  }
  return std::to_string(type);
}

ClassicPlan planClassicAttributes(const std::vector<ClassicAttribute>& point) {
  ClassicPlan plan;
  for (std::size_t i = 0; i < point.size(); ++i) {
    const ClassicAttribute& a = point[i];
    if (a.type != ClassicType::Float && a.type != ClassicType::Int && a.type != ClassicType::Vector) continue;
    plan.exposed.push_back({a.name, a.type == ClassicType::Int ? ValueType::Int32 : ValueType::Float32, a.size});
    plan.exposedSource.push_back(i);
    if (!plan.velocity && a.name == "v" && a.size == 3 && a.type != ClassicType::Int) plan.velocity = i;
  }
  return plan;
}

}  // namespace houdini

namespace {

using houdini::ClassicAttribute;
using houdini::ClassicType;

constexpr char kBinaryMagic[5] = {'B', 'g', 'e', 'o', 'V'};
constexpr std::int32_t kVersion = 5;
constexpr std::int32_t kParticlePrimitive = 0x8000;  // "Part"

/// Big-endian fields read from an InputFile, with the messages of a classic bgeo.
class Fields {
 public:
  explicit Fields(InputFile& file) : mFile(file) {}
  std::uint64_t offset() const { return mFile.offset(); }
  std::uint64_t left() const { return mFile.size() - mFile.offset(); }
  std::uint8_t byte(const char* what) {
    std::uint8_t v;
    mFile.readExact(&v, 1, what);
    return v;
  }
  std::uint16_t uint16(const char* what) {
    std::uint16_t v;
    mFile.readExact(&v, 2, what);
    return __builtin_bswap16(v);
  }
  std::int32_t int32(const char* what) {
    std::uint32_t v;
    mFile.readExact(&v, 4, what);
    return std::int32_t(__builtin_bswap32(v));
  }
  /// A var16: an int16, or -1 and then an int32.
  std::int64_t var16(const char* what) {
    const auto v = std::int16_t(uint16(what));
    return v == -1 ? std::int64_t(int32(what)) : std::int64_t(v);
  }
  std::string string(const char* what) {
    const std::uint64_t at = offset();
    const std::int64_t length = var16(what);
    if (length < 0 || std::uint64_t(length) > left())
      throw FileError(mFile.path(), std::string("classic bgeo: ") + what + " at byte " + std::to_string(at) +
                                        " has length " + std::to_string(length) + ", but " + std::to_string(left()) +
                                        " bytes are left in the file");
    std::string text(std::size_t(length), '\0');
    mFile.readExact(text.data(), text.size(), what);
    return text;
  }
  void skip(std::uint64_t bytes, const char* what) {
    if (bytes > left())
      throw FileError(mFile.path(), std::string("truncated: the file ends inside ") + what + " (" +
                                        std::to_string(bytes) + " bytes at byte " + std::to_string(offset()) +
                                        ", file size " + std::to_string(mFile.size()) + ")");
    mFile.seek(offset() + bytes);
  }

 private:
  InputFile& mFile;
};

struct BgeoHeader {
  std::int64_t points = 0, primitives = 0, pointGroups = 0, primitiveGroups = 0;
  std::int64_t pointAttributes = 0, vertexAttributes = 0, primitiveAttributes = 0, detailAttributes = 0;
};

class ClassicBgeoReader final : public ParticleSource {
 public:
  ClassicBgeoReader(InputFile file, const ReadOptions& options) : mFile(std::move(file)) {
    Fields in(mFile);
    char magic[5] = {};
    if (mFile.read(magic, 5) != 5 || std::memcmp(magic, kBinaryMagic, 5) != 0)
      throw FileError(mFile.path(),
                      "bad magic: not a Houdini classic geometry file (expected 'BgeoV' or 'PGEOMETRY V5')");
    const std::int32_t version = in.int32("the version");
    if (version != kVersion)
      throw FileError(mFile.path(), "classic bgeo version " + std::to_string(version) + " (this reader reads version " +
                                        std::to_string(kVersion) + ")");
    const char* names[8] = {"NPoints",      "NPrims",        "NPointGroups", "NPrimGroups",
                            "NPointAttrib", "NVertexAttrib", "NPrimAttrib",  "NAttrib"};
    std::int64_t* counts[8] = {
        &mHeader.points,          &mHeader.primitives,       &mHeader.pointGroups,         &mHeader.primitiveGroups,
        &mHeader.pointAttributes, &mHeader.vertexAttributes, &mHeader.primitiveAttributes, &mHeader.detailAttributes};
    for (int i = 0; i < 8; ++i) {
      const std::uint64_t at = in.offset();
      *counts[i] = in.int32(names[i]);
      if (*counts[i] < 0)
        throw FileError(mFile.path(), std::string("classic bgeo header: ") + names[i] + " at byte " +
                                          std::to_string(at) + " is negative (" + std::to_string(*counts[i]) + ")");
    }
    mPoint = *readDictionary(in, mHeader.pointAttributes, "point", false);
    mStride = 16;
    for (auto& a : mPoint) {
      a.offset = mStride;
      mStride += std::size_t(a.size) * 4;
    }
    mDataOffset = in.offset();
    const std::uint64_t available = in.left() / mStride;
    if (available < std::uint64_t(mHeader.points))
      throw FileError(mFile.path(), "truncated: the file ends at point " + std::to_string(available) + " of " +
                                        std::to_string(mHeader.points) + " (points start at byte " +
                                        std::to_string(mDataOffset) + ", " + std::to_string(mStride) +
                                        " bytes a point, file size " + std::to_string(mFile.size()) + ")");
    mPlan = houdini::planClassicAttributes(mPoint);
    mSelected = selectAttributes(mPlan.exposed, options, mFile.path());
    mColumns = makeColumns(mPlan.exposed, mSelected);
    mHasVelocity = options.velocity && mPlan.velocity.has_value();
  }

  std::string name() const override { return mFile.path().string(); }
  std::string format() const override {
    return "Houdini classic binary geometry (BgeoV version " + std::to_string(kVersion) + ")";
  }
  /// Houdini's world is +y up.
  UpAxis upAxis() const override { return UpAxis::Y; }
  std::vector<AttributeDesc> attributes() const override { return mPlan.exposed; }
  bool hasVelocity() const override { return mHasVelocity; }
  std::optional<std::uint64_t> countHint() const override { return std::uint64_t(mHeader.points); }

  bool read(ParticleChunk& chunk, std::size_t maxParticles) override {
    FLIPSCOPE_CHECK(maxParticles > 0);
    chunk.clear();
    const std::uint64_t total = std::uint64_t(mHeader.points);
    const std::size_t n = std::size_t(std::min<std::uint64_t>(maxParticles, total - mNext));
    prepareColumns(chunk, mColumns, n);
    if (n == 0) {
      if (!mTailChecked) checkTail();  // no points: what follows the header is all there is
      mTailChecked = true;
      return false;
    }
    chunk.positions.resize(n);
    if (mHasVelocity) chunk.velocities.resize(n);
    readRecordBatches(
        mFile, mStride, n, mBuffer,
        [&](const std::byte* records, std::size_t count, std::size_t begin) {
          decodeVec3Column(ValueType::Float32, ByteOrder::Big, records, mStride, count, chunk.positions.data() + begin);
          if (mHasVelocity)
            decodeVec3Column(ValueType::Float32, ByteOrder::Big, records + mPoint[*mPlan.velocity].offset, mStride,
                             count, chunk.velocities.data() + begin);
          for (std::size_t k = 0; k < mSelected.size(); ++k) {
            const ClassicAttribute& a = mPoint[mPlan.exposedSource[mSelected[k]]];
            decodeColumn(a.type == ClassicType::Int ? ValueType::Int32 : ValueType::Float32, ByteOrder::Big,
                         records + a.offset, mStride, a.size, count,
                         chunk.attributes[k].values.data() + begin * std::size_t(a.size));
          }
        },
        [&](std::size_t inside) {
          return FileError(mFile.path(), "the file ends inside point " + std::to_string(mNext + inside) + " of " +
                                             std::to_string(total) + " (was it truncated while being read?)");
        });
    mNext += n;
    if (mNext == total && !mTailChecked) {
      checkTail();
      mTailChecked = true;
    }
    return true;
  }

  void rewind() override {
    mFile.seek(mDataOffset);
    mNext = 0;
  }

 private:
  /// An attribute dictionary of `count` entries. Unknown types throw for the point dictionary;
  /// elsewhere (`lenient`) they return nullopt: the caller stops walking the file.
  std::optional<std::vector<ClassicAttribute>> readDictionary(Fields& in, std::int64_t count, const char* kind,
                                                              bool lenient) {
    constexpr std::uint64_t kMinDefinitionBytes = 8;  // name length, size, type
    if (std::uint64_t(count) > in.left() / kMinDefinitionBytes)
      throw FileError(mFile.path(), std::string("classic bgeo: ") + std::to_string(count) + " " + kind +
                                        " attributes cannot fit in the " + std::to_string(in.left()) +
                                        " bytes left at byte " + std::to_string(in.offset()));
    std::vector<ClassicAttribute> dictionary;
    for (std::int64_t i = 0; i < count; ++i) {
      const std::uint64_t at = in.offset();
      ClassicAttribute a;
      a.name = in.string("an attribute name");
      a.size = in.uint16("an attribute size");
      const std::int32_t type = in.int32("an attribute type");
      const std::string where =
          std::string(kind) + " attribute '" + a.name + "' (definition at byte " + std::to_string(at) + ")";
      if (a.size == 0) throw FileError(mFile.path(), "classic bgeo: " + where + " has size 0");
      switch (type) {
        case std::int32_t(ClassicType::Float):
        case std::int32_t(ClassicType::Int):
        case std::int32_t(ClassicType::Vector):
          a.type = ClassicType(type);
          in.skip(std::uint64_t(a.size) * 4, "an attribute default");
          break;
        case std::int32_t(ClassicType::Index): {
          a.type = ClassicType::Index;
          const std::uint64_t stringsAt = in.offset();
          const std::int32_t strings = in.int32("an index attribute's string count");
          if (strings < 0 || std::uint64_t(strings) > in.left() / 2)
            throw FileError(mFile.path(), "classic bgeo: " + where + " has " + std::to_string(strings) +
                                              " strings (count at byte " + std::to_string(stringsAt) + "), but " +
                                              std::to_string(in.left()) + " bytes are left");
          for (std::int32_t s = 0; s < strings; ++s) (void)in.string("an index attribute's string");
          break;
        }
        default:
          if (lenient) return std::nullopt;
          throw FileError(mFile.path(), "classic bgeo: " + where + " has type " + houdini::classicTypeName(type) +
                                            ", which this reader cannot read (float, int, vector and index)");
      }
      dictionary.push_back(std::move(a));
    }
    return dictionary;
  }

  static std::uint64_t valueBytes(const std::vector<ClassicAttribute>& dictionary) {
    std::uint64_t bytes = 0;
    for (const auto& a : dictionary) bytes += std::uint64_t(a.size) * 4;
    return bytes;
  }

  /// What follows the points (see the file comment). The file offset is the end of the points.
  void checkTail() {
    Fields in(mFile);
    const auto vertex = readDictionary(in, mHeader.vertexAttributes, "vertex", true);
    if (!vertex) return trustTheRest("a vertex attribute of a type this reader does not walk");
    const auto primitive = readDictionary(in, mHeader.primitiveAttributes, "primitive", true);
    if (!primitive) return trustTheRest("a primitive attribute of a type this reader does not walk");
    const std::uint64_t vertexBytes = valueBytes(*vertex) + (mHeader.points <= 0xffff ? 2 : 4);
    const std::uint64_t primitiveBytes = valueBytes(*primitive);
    for (std::int64_t p = 0; p < mHeader.primitives; ++p) {
      const std::uint64_t at = in.offset();
      const std::int32_t type = in.int32("a primitive type");
      if (type != kParticlePrimitive) return trustTheRest("primitives other than particle systems");
      const std::int32_t vertices = in.int32("a particle primitive's vertex count");
      if (vertices < 0 || std::uint64_t(vertices) > in.left() / vertexBytes)
        throw FileError(mFile.path(), "classic bgeo: particle primitive " + std::to_string(p) + " (at byte " +
                                          std::to_string(at) + ") has " + std::to_string(vertices) + " vertices, but " +
                                          std::to_string(in.left()) + " bytes are left");
      checkVertexIndices(std::uint64_t(vertices), vertexBytes, p);
      in.skip(primitiveBytes, "primitive attribute values");
    }
    if (mHeader.pointGroups > 0 || mHeader.primitiveGroups > 0) return trustTheRest("groups");
    const auto detail = readDictionary(in, mHeader.detailAttributes, "detail", true);
    if (!detail) return trustTheRest("a detail attribute of a type this reader does not walk");
    in.skip(valueBytes(*detail), "detail attribute values");
    const std::uint64_t extraAt = in.offset();
    const std::uint8_t begin = in.byte("the extra section");
    if (begin != 0x00)
      throw FileError(mFile.path(), "classic bgeo: expected the extra section (byte 0x00) at byte " +
                                        std::to_string(extraAt) + ", found 0x" + hex(begin));
    if (in.byte("the extra section") != 0xff) return trustTheRest("an extra section");
    if (in.left() > 0)
      throw FileError(mFile.path(), std::to_string(in.left()) + " bytes of trailing garbage after the end of the " +
                                        "geometry at byte " + std::to_string(in.offset()));
  }

  /// The point indices of a particle primitive's vertices (each followed by vertex values).
  void checkVertexIndices(std::uint64_t vertices, std::uint64_t vertexBytes, std::int64_t primitive) {
    const bool wide = mHeader.points > 0xffff;
    const std::uint64_t at = mFile.offset();
    readRecordBatches(
        mFile, std::size_t(vertexBytes), std::size_t(vertices), mBuffer,
        [&](const std::byte* records, std::size_t count, std::size_t first) {
          for (std::size_t v = 0; v < count; ++v) {
            const std::byte* p = records + v * std::size_t(vertexBytes);
            std::uint32_t index;
            if (wide) {
              std::memcpy(&index, p, 4);
              index = __builtin_bswap32(index);
            } else {
              std::uint16_t narrow;
              std::memcpy(&narrow, p, 2);
              index = __builtin_bswap16(narrow);
            }
            if (index >= std::uint64_t(mHeader.points))
              throw FileError(mFile.path(), "classic bgeo: vertex " + std::to_string(first + v) +
                                                " of particle primitive " + std::to_string(primitive) +
                                                " refers to point " + std::to_string(index) + " of " +
                                                std::to_string(mHeader.points));
          }
        },
        [&](std::size_t inside) {
          return FileError(mFile.path(), "truncated: the file ends inside vertex " + std::to_string(inside) +
                                             " of particle primitive " + std::to_string(primitive) + " (at byte " +
                                             std::to_string(at + inside * vertexBytes) + ", file size " +
                                             std::to_string(mFile.size()) + ")");
        });
  }

  /// The file holds `what`, which this reader does not walk: it must still end with 0xff.
  void trustTheRest(const char* what) {
    std::uint8_t last = 0;
    if (mFile.size() == 0 || mFile.readAt(mFile.size() - 1, &last, 1) != 1 || last != 0xff)
      throw FileError(mFile.path(), std::string("classic bgeo: the file does not end with the end marker 0xff ") +
                                        "(found 0x" + hex(last) + " after " + what + "): truncated?");
  }

  static std::string hex(std::uint8_t value) {
    static constexpr char kDigits[] = "0123456789abcdef";
    return {kDigits[value >> 4], kDigits[value & 15]};
  }

  InputFile mFile;
  BgeoHeader mHeader;
  std::vector<ClassicAttribute> mPoint;
  houdini::ClassicPlan mPlan;
  std::vector<std::size_t> mSelected;  ///< into mPlan.exposed
  std::vector<AttributeColumn> mColumns;
  bool mHasVelocity = false;
  std::size_t mStride = 16;
  std::uint64_t mDataOffset = 0;
  std::uint64_t mNext = 0;
  bool mTailChecked = false;
  std::vector<std::byte> mBuffer;
};

bool startsWith(std::span<const std::byte> head, std::string_view text) {
  return head.size() >= text.size() && std::memcmp(head.data(), text.data(), text.size()) == 0;
}

}  // namespace

bool isClassicBgeo(std::span<const std::byte> head) {
  return startsWith(head, std::string_view(kBinaryMagic, 5)) || startsWith(head, "PGEOMETRY ");
}

std::unique_ptr<ParticleSource> openClassicBgeo(InputFile file, const ReadOptions& options) {
  const std::vector<std::byte> head = file.peekHead(10);
  if (startsWith(head, "PGEOMETRY")) return houdini::openClassicBgeoAscii(std::move(file), options);
  return std::make_unique<ClassicBgeoReader>(std::move(file), options);
}

}  // namespace flipscope::detail
