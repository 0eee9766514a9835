// OpenVDB point files read by our own decoder, not by OpenVDB's I/O: OpenVDB trusts every size
// it reads (a damaged file overflows its buffers or fails its assertions, and a truncated one
// reads as empty), so this reader parses the format itself and checks every size, offset and
// count against the file before it allocates or decodes anything. OpenVDB stays the oracle:
// tests compare this reader with OpenVDB's, bit for bit (VdbReaderOracleTest.cpp).
//
// What is read: every PointDataGrid of a file (or those named in ReadOptions::grids), its
// transform, tree topology and the multi-pass point buffers (OpenVDB 4 and later, file format
// 224): per leaf the voxel offsets, the position attribute P and the velocity attribute (`v`,
// else Blender Mantaflow's `particles_velocity*`), in any of OpenVDB's vec3s codecs, paged or
// not, blosc-compressed or not. Other grids are skipped by their sizes.
// World positions are transform.indexToWorld(voxel coordinate + P), computed as OpenVDB does.
//
// Attributes: attributes() lists every attribute of the descriptors except P (the velocity
// included) whose value type OpenVDB names (bool, int8 .. int64, uint8 .. uint64, float, double,
// vec2/3/4 s/d/i, quats/d, mat3/4 s/d), with the descriptor's value type and its components: the
// attributes every leaf of every grid read has, in the order of the first descriptor. Asked-for
// attributes are decoded into columns for every codec OpenVDB registers for their type (null;
// trnc for float, vec3s and Blender Mantaflow's int32; fxpt8/16, ufxpt8/16 and uvec for vec3s,
// fxpt for float), paged or not, blosc-compressed or not. Group membership arrays (codec grp) and
// string indices (codec str) are listed but refused when asked for, as is any other codec.
//
// Memory: opening keeps a few dozen bytes a leaf (where its data lies); reading decodes one
// leaf and one page of each attribute at a time, so a file larger than memory streams.
#include <blosc.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <openvdb/math/Mat4.h>
#include <openvdb/points/AttributeArray.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include "core/Error.h"
#include "preprocess/particles/ParticleFormats.h"

namespace flipscope::detail {
namespace {

using Vec3f = openvdb::Vec3f;
using Vec3d = openvdb::Vec3d;

constexpr std::int64_t kVdbMagic = 0x56444220;    // openvdb::OPENVDB_MAGIC, " BDV"
constexpr std::uint32_t kMultiPassVersion = 224;  // OPENVDB_FILE_VERSION_MULTIPASS_IO
constexpr char kPointGridType[] = "Tree_ptdataidx32_5_4_3";
constexpr char kHalfFloatSuffix[] = "_HalfFloat";
constexpr std::uint32_t kCompressZip = 0x1, kCompressActiveMask = 0x2, kCompressBlosc = 0x4;
constexpr std::size_t kLeafVoxels = 512;  // LeafNode<PointDataIndex32, 3>
constexpr std::size_t kVoxelBufferBytes = kLeafVoxels * 4;
constexpr std::uint16_t kUncompressedVoxels = 0xffff;
constexpr std::size_t kBloscHeaderBytes = BLOSC_MIN_HEADER_LENGTH;
constexpr std::size_t kBloscPadBytes = 128;  // compression::BLOSC_PAD_BYTES
/// Blosc with LZ4 (what OpenVDB writes), blosclz, snappy or zlib cannot expand data by more
/// than about 1:1032; a claimed size beyond this is damage, refused before it is allocated.
constexpr std::uint64_t kMaxBloscRatio = 1100;
/// Attributes a leaf can have: numPasses is 16 bits, 2 * attributes + 4 of them.
constexpr std::uint64_t kMaxAttributes = (0xffff - 4) / 2;
// AttributeArray flags and serialization flags (points/AttributeArray.h).
constexpr std::uint8_t kConstantStride = 0x8;
constexpr std::uint8_t kWriteStrided = 0x1, kWriteUniform = 0x2, kWritePaged = 0x8;

// ---- bytes ----------------------------------------------------------------------------

/// Random access to the file's bytes: pread on a file, or memory.
class ByteInput {
 public:
  virtual ~ByteInput() = default;
  std::uint64_t size() const { return mSize; }
  /// Reads exactly `n` bytes at `offset`; the caller checked offset + n <= size().
  virtual void read(std::uint64_t offset, void* out, std::size_t n) = 0;

 protected:
  std::uint64_t mSize = 0;
};

/// An InputFile's bytes (a file, memory or a decoded container), read where they are needed.
class InputFileInput final : public ByteInput {
 public:
  explicit InputFileInput(InputFile file) : mFile(std::move(file)) { mSize = mFile.size(); }
  void read(std::uint64_t offset, void* out, std::size_t n) override {
    if (mFile.readAt(offset, out, n) != n)
      throw FileError(mFile.path(), "the file ends at byte " + std::to_string(offset) + ", shorter than when it was opened");
  }

 private:
  InputFile mFile;
};

/// Sequential, bounds-checked reads for parsing, through a small buffer.
class Cursor {
 public:
  Cursor(ByteInput& input, const std::filesystem::path& path) : mInput(input), mPath(path), mBuffer(kBufferBytes) {}

  std::uint64_t offset() const { return mOffset; }
  std::uint64_t remaining() const { return mInput.size() - mOffset; }
  void seek(std::uint64_t offset, const char* what) {
    if (offset > mInput.size())
      throw error(std::string(what) + " at byte " + std::to_string(offset) + " lies past the end of the file (" +
                  std::to_string(mInput.size()) + " bytes)");
    mOffset = offset;
  }
  /// Throws "truncated" unless `n` more bytes follow.
  void need(std::uint64_t n, const char* field) const {
    if (n > remaining())
      throw FileError(mPath, "truncated or corrupted OpenVDB file: " + std::string(field) + " at byte " +
                                 std::to_string(mOffset) + " needs " + std::to_string(n) +
                                 " bytes, but the file ends at byte " + std::to_string(mInput.size()));
  }
  void read(void* out, std::size_t n, const char* field) {
    need(n, field);
    if (n > kBufferBytes) {
      mInput.read(mOffset, out, n);
    } else {
      if (mOffset < mBufferStart || mOffset + n > mBufferStart + mBufferSize) {
        mBufferStart = mOffset;
        mBufferSize = std::size_t(std::min<std::uint64_t>(kBufferBytes, remaining()));
        mInput.read(mBufferStart, mBuffer.data(), mBufferSize);
      }
      std::memcpy(out, mBuffer.data() + (mOffset - mBufferStart), n);
    }
    mOffset += n;
  }
  template <class T>
  T get(const char* field) {
    T value;
    read(&value, sizeof value, field);
    return value;
  }
  void skip(std::uint64_t n, const char* field) {
    need(n, field);
    mOffset += n;
  }
  /// A string: uint32 length, then its bytes.
  std::string string(const char* field) {
    const auto length = get<std::uint32_t>(field);
    need(length, field);
    std::string text(length, '\0');
    read(text.data(), length, field);
    return text;
  }
  void skipString(const char* field) { skip(get<std::uint32_t>(field), field); }

  /// A FileError for damage found at the current offset.
  FileError error(const std::string& what) const {
    return FileError(mPath, "corrupted OpenVDB file: " + what + " (at byte " + std::to_string(mOffset) + ")");
  }

 private:
  static constexpr std::size_t kBufferBytes = 1 << 16;
  ByteInput& mInput;
  const std::filesystem::path& mPath;
  std::uint64_t mOffset = 0;
  std::vector<std::byte> mBuffer;
  std::uint64_t mBufferStart = 0;
  std::size_t mBufferSize = 0;
};

/// A name or type read from the file, quoted for a message: at most 64 characters.
std::string quote(const std::string& text) {
  constexpr std::size_t kMax = 64;
  return "'" + (text.size() <= kMax ? text : text.substr(0, kMax) + "...") + "'";
}

// ---- attribute codecs -------------------------------------------------------------------

using DecodeVec3 = Vec3f (*)(const std::byte*);

template <class Codec>
Vec3f decodeWith(const std::byte* stored) {
  typename Codec::template Storage<Vec3f>::Type storage;
  std::memcpy(&storage, stored, sizeof storage);
  Vec3f value;
  Codec::decode(storage, value);
  return value;
}

struct Vec3Codec {
  std::size_t bytes;  ///< stored bytes a value
  DecodeVec3 decode;
};

template <class Codec>
constexpr Vec3Codec vec3Codec() {
  return {sizeof(typename Codec::template Storage<Vec3f>::Type), &decodeWith<Codec>};
}

/// How one value of an attribute is stored: its bytes, its components, and a decoder that
/// writes the components as floats.
struct AttributeCodec {
  std::size_t bytes = 0;
  int arity = 1;
  void (*decode)(const std::byte* stored, float* out) = nullptr;
};

/// Decodes one value of type T (made of Elem components) stored by Codec.
template <class T, class Elem, class Codec>
void decodeComponents(const std::byte* stored, float* out) {
  typename Codec::template Storage<T>::Type storage;
  std::memcpy(&storage, stored, sizeof storage);
  T value;
  Codec::decode(storage, value);
  constexpr std::size_t n = sizeof(T) / sizeof(Elem);
  Elem parts[n];
  std::memcpy(parts, &value, sizeof parts);
  for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<float>(parts[i]);
}

/// OpenVDB's "uvec" codec (points::UnitVecCodec: math::QuantizedUnitVec, after "Higher Accuracy
/// Quantized Normals", GameDev.net 2000), decoded here because OpenVDB's decode reads a table in
/// its library, which the reader does not link. The table is computed the way OpenVDB's source
/// (QuantizedUnitVec.cc) generates its own; the decode is unpack()'s arithmetic.
struct UnitVecCodec {
  template <class T>
  struct Storage {
    using Type = std::uint16_t;
  };
  static const char* name() { return "uvec"; }
  static void decode(const std::uint16_t& data, Vec3f& value) {
    static const std::array<float, 8192> weights = [] {
      std::array<float, 8192> w{};
      for (std::uint32_t b = 0; b < w.size(); ++b) {
        auto [x, y] = xyBits(b);
        const double dx = x, dy = y, dz = 126 - x - y;
        w[b] = float(1.0 / std::sqrt(dx * dx + dy * dy + dz * dz));
      }
      return w;
    }();
    const float w = weights[data & 0x1fff];
    const auto [x, y] = xyBits(data);
    value = Vec3f(float(x) * w, float(y) * w, float(126 - x - y) * w);
    if (data & 0x8000) value[0] = -value[0];
    if (data & 0x4000) value[1] = -value[1];
    if (data & 0x2000) value[2] = -value[2];
  }

 private:
  /// The two stored components, 0 to 126, the complement stored where their sum passes 126.
  static std::pair<int, int> xyBits(std::uint32_t data) {
    const int x = int((data & 0x1f80) >> 7), y = int(data & 0x7f);
    return x + y > 126 ? std::pair(127 - x, 127 - y) : std::pair(x, y);
  }
};

/// A value type and codec as a descriptor names them, and how to list and decode them.
struct CodecEntry {
  std::string type, codec;
  ValueType valueType;
  AttributeCodec decoder;
};

template <class T, class Elem, class Codec>
CodecEntry codecEntry(ValueType valueType) {
  static_assert(sizeof(T) % sizeof(Elem) == 0);
  return {openvdb::typeNameAsString<T>(),
          Codec::name(),
          valueType,
          {sizeof(typename Codec::template Storage<T>::Type), int(sizeof(T) / sizeof(Elem)),
           &decodeComponents<T, Elem, Codec>}};
}

/// Every value type flipscope lists, with each codec it decodes for it: those OpenVDB registers
/// (points::internal::initialize), Mantaflow's int32 trnc, and the null codec of the other
/// value types OpenVDB names.
const std::vector<CodecEntry>& codecTable() {
  namespace p = openvdb::points;
  namespace m = openvdb::math;
  using V = ValueType;
  static const std::vector<CodecEntry> table{
      codecEntry<bool, bool, p::NullCodec>(V::UInt8),
      codecEntry<std::int8_t, std::int8_t, p::NullCodec>(V::Int8),
      codecEntry<std::int16_t, std::int16_t, p::NullCodec>(V::Int16),
      codecEntry<std::int32_t, std::int32_t, p::NullCodec>(V::Int32),
      codecEntry<std::int32_t, std::int32_t, p::TruncateCodec>(V::Int32),
      codecEntry<std::int64_t, std::int64_t, p::NullCodec>(V::Int64),
      codecEntry<std::uint8_t, std::uint8_t, p::NullCodec>(V::UInt8),
      codecEntry<std::uint16_t, std::uint16_t, p::NullCodec>(V::UInt16),
      codecEntry<std::uint32_t, std::uint32_t, p::NullCodec>(V::UInt32),
      codecEntry<std::uint64_t, std::uint64_t, p::NullCodec>(V::UInt64),
      codecEntry<float, float, p::NullCodec>(V::Float32),
      codecEntry<float, float, p::TruncateCodec>(V::Float32),
      codecEntry<float, float, p::FixedPointCodec<true, p::PositionRange>>(V::Float32),
      codecEntry<float, float, p::FixedPointCodec<false, p::PositionRange>>(V::Float32),
      codecEntry<float, float, p::FixedPointCodec<true, p::UnitRange>>(V::Float32),
      codecEntry<float, float, p::FixedPointCodec<false, p::UnitRange>>(V::Float32),
      codecEntry<double, double, p::NullCodec>(V::Float64),
      codecEntry<Vec3f, float, p::NullCodec>(V::Float32),
      codecEntry<Vec3f, float, p::TruncateCodec>(V::Float32),
      codecEntry<Vec3f, float, p::FixedPointCodec<true, p::PositionRange>>(V::Float32),
      codecEntry<Vec3f, float, p::FixedPointCodec<false, p::PositionRange>>(V::Float32),
      codecEntry<Vec3f, float, p::FixedPointCodec<true, p::UnitRange>>(V::Float32),
      codecEntry<Vec3f, float, p::FixedPointCodec<false, p::UnitRange>>(V::Float32),
      codecEntry<Vec3f, float, UnitVecCodec>(V::Float32),
      codecEntry<Vec3d, double, p::NullCodec>(V::Float64),
      codecEntry<m::Vec3<std::int32_t>, std::int32_t, p::NullCodec>(V::Int32),
      codecEntry<m::Vec2<float>, float, p::NullCodec>(V::Float32),
      codecEntry<m::Vec2<double>, double, p::NullCodec>(V::Float64),
      codecEntry<m::Vec2<std::int32_t>, std::int32_t, p::NullCodec>(V::Int32),
      codecEntry<m::Vec4<float>, float, p::NullCodec>(V::Float32),
      codecEntry<m::Vec4<double>, double, p::NullCodec>(V::Float64),
      codecEntry<m::Vec4<std::int32_t>, std::int32_t, p::NullCodec>(V::Int32),
      codecEntry<m::Quat<float>, float, p::NullCodec>(V::Float32),
      codecEntry<m::Quat<double>, double, p::NullCodec>(V::Float64),
      codecEntry<m::Mat3<float>, float, p::NullCodec>(V::Float32),
      codecEntry<m::Mat3<double>, double, p::NullCodec>(V::Float64),
      codecEntry<m::Mat4<float>, float, p::NullCodec>(V::Float32),
      codecEntry<m::Mat4<double>, double, p::NullCodec>(V::Float64),
  };
  return table;
}

/// The entry of a value type (any codec), for listing; null for a type flipscope does not know.
const CodecEntry* findValueType(const std::string& type) {
  for (const auto& entry : codecTable())
    if (entry.type == type) return &entry;
  return nullptr;
}

/// The decoder of a value type and codec; null when flipscope cannot decode them.
const AttributeCodec* findAttributeCodec(const std::string& type, const std::string& codec) {
  for (const auto& entry : codecTable())
    if (entry.type == type && entry.codec == codec) return &entry.decoder;
  return nullptr;
}

/// The codecs OpenVDB registers for vec3s attributes (points::internal::initialize).
const Vec3Codec* findVec3Codec(const std::string& name) {
  namespace p = openvdb::points;
  static const std::array<std::pair<const char*, Vec3Codec>, 7> kCodecs{{
      {"null", vec3Codec<p::NullCodec>()},
      {"trnc", vec3Codec<p::TruncateCodec>()},
      {"fxpt8", vec3Codec<p::FixedPointCodec<true, p::PositionRange>>()},
      {"fxpt16", vec3Codec<p::FixedPointCodec<false, p::PositionRange>>()},
      {"ufxpt8", vec3Codec<p::FixedPointCodec<true, p::UnitRange>>()},
      {"ufxpt16", vec3Codec<p::FixedPointCodec<false, p::UnitRange>>()},
      {"uvec", vec3Codec<UnitVecCodec>()},
  }};
  for (const auto& [codecName, codec] : kCodecs)
    if (name == codecName) return &codec;
  return nullptr;
}

static_assert(sizeof(openvdb::points::TruncateCodec::Storage<Vec3f>::Type) == 6);
static_assert(sizeof(openvdb::points::FixedPointCodec<true, openvdb::points::PositionRange>::Storage<Vec3f>::Type) ==
              3);

// ---- transforms ---------------------------------------------------------------------------

/// The linear maps of openvdb::math (Maps.h), applied with the same arithmetic as OpenVDB.
struct Transform {
  enum class Kind { Scale, ScaleTranslate, Translate, Affine } kind = Kind::Scale;
  Vec3d scale{1, 1, 1};
  Vec3d translation{0, 0, 0};
  openvdb::math::Mat4d matrix = openvdb::math::Mat4d::identity();

  Vec3d indexToWorld(const Vec3d& in) const {
    switch (kind) {
      case Kind::Scale:
        return Vec3d(in.x() * scale.x(), in.y() * scale.y(), in.z() * scale.z());
      case Kind::ScaleTranslate:
        return Vec3d(in.x() * scale.x() + translation.x(), in.y() * scale.y() + translation.y(),
                     in.z() * scale.z() + translation.z());
      case Kind::Translate:
        return in + translation;
      case Kind::Affine:
        return in * matrix;
    }
    return in;
  }
  Vec3d voxelSize() const {
    if (kind == Kind::Scale || kind == Kind::ScaleTranslate)
      return Vec3d(std::abs(scale.x()), std::abs(scale.y()), std::abs(scale.z()));
    if (kind == Kind::Translate) return Vec3d(1, 1, 1);
    const Vec3d origin = indexToWorld(Vec3d(0, 0, 0));
    return Vec3d((indexToWorld(Vec3d(1, 0, 0)) - origin).length(), (indexToWorld(Vec3d(0, 1, 0)) - origin).length(),
                 (indexToWorld(Vec3d(0, 0, 1)) - origin).length());
  }
  double voxelVolume() const {
    if (kind == Kind::Affine) return std::abs(matrix.getMat3().det());
    const Vec3d size = voxelSize();
    return size.x() * size.y() * size.z();
  }
};

Vec3d readVec3d(Cursor& c, const char* field) {
  std::array<double, 3> v;
  c.read(v.data(), sizeof v, field);
  return Vec3d(v[0], v[1], v[2]);
}

Transform readTransform(Cursor& c) {
  const std::string type = c.string("transform type");
  Transform t;
  auto finite = [&](const Vec3d& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); };
  if (type == "UniformScaleMap" || type == "ScaleMap") {
    t.kind = Transform::Kind::Scale;
    t.scale = readVec3d(c, "transform scale");
    c.skip(4 * 24, "transform voxel size and inverses");
  } else if (type == "UniformScaleTranslateMap" || type == "ScaleTranslateMap") {
    t.kind = Transform::Kind::ScaleTranslate;
    t.translation = readVec3d(c, "transform translation");
    t.scale = readVec3d(c, "transform scale");
    c.skip(4 * 24, "transform voxel size and inverses");
  } else if (type == "TranslationMap") {
    t.kind = Transform::Kind::Translate;
    t.translation = readVec3d(c, "transform translation");
  } else if (type == "AffineMap" || type == "UnitaryMap") {
    t.kind = Transform::Kind::Affine;
    std::array<double, 16> m;
    c.read(m.data(), sizeof m, "transform matrix");
    for (double value : m)
      if (!std::isfinite(value)) throw c.error("transform matrix has a non-finite entry");
    t.matrix = openvdb::math::Mat4d(m.data());
  } else if (type == "NonlinearFrustumMap") {
    throw c.error("frustum transforms are not supported for points");
  } else {
    throw c.error("unknown transform type " + quote(type));
  }
  if (!finite(t.scale) || !finite(t.translation)) throw c.error("transform has a non-finite entry");
  return t;
}

// ---- grid structure ---------------------------------------------------------------------

/// An attribute set descriptor: the type and codec of each attribute, and their names.
struct Descriptor {
  std::vector<std::pair<std::string, std::string>> types;  ///< value type, codec
  std::map<std::string, std::size_t> names;                ///< name -> index, sorted as OpenVDB's
  std::size_t position = SIZE_MAX;                         ///< index of P
  std::size_t velocity = SIZE_MAX;                         ///< `v`, else `particles_velocity*`
  /// Per attribute index: its slot among the attributes to decode (VdbParser::extraNames), or -1.
  std::vector<int> slots;
  /// The attribute index of `slot`, or SIZE_MAX when this descriptor has no such attribute.
  std::size_t indexOfSlot(int slot) const {
    for (std::size_t a = 0; a < slots.size(); ++a)
      if (slots[a] == slot) return a;
    return SIZE_MAX;
  }
  bool operator==(const Descriptor& o) const { return types == o.types && names == o.names; }
};

bool validAttributeName(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '|' || c == ':';
  });
}

/// MetaMap::readMeta, skipped: count, then name, type name, byte count and bytes of each.
void skipMetadata(Cursor& c, const char* what) {
  const auto count = c.get<std::uint32_t>(what);
  for (std::uint32_t i = 0; i < count; ++i) {
    c.skipString(what);
    c.skipString(what);
    c.skip(c.get<std::uint32_t>(what), what);
  }
}

Descriptor readDescriptor(Cursor& c) {
  Descriptor d;
  const auto count = c.get<std::uint64_t>("attribute count");
  if (count > kMaxAttributes || count * 16 > c.remaining())
    throw c.error("descriptor claims " + std::to_string(count) + " attributes");
  d.types.resize(count);
  for (auto& [type, codec] : d.types) {
    type = c.string("attribute type");
    codec = c.string("attribute codec");
  }
  std::vector<bool> named(count, false);
  for (std::uint64_t n = 0; n < count; ++n) {
    std::string name = c.string("attribute name");
    if (!validAttributeName(name)) throw c.error("attribute name " + quote(name) + " has invalid characters");
    const auto index = c.get<std::uint64_t>("attribute index");
    if (index >= count || named[index] || d.names.count(name))
      throw c.error("attribute " + quote(name) + " has a repeated or out-of-range index " + std::to_string(index));
    named[index] = true;
    d.names.emplace(std::move(name), index);
  }
  const auto groups = c.get<std::uint64_t>("group count");
  for (std::uint64_t n = 0; n < groups; ++n) {
    const std::string name = c.string("group name");
    if (!validAttributeName(name)) throw c.error("group name " + quote(name) + " has invalid characters");
    c.skip(8, "group index");
  }
  skipMetadata(c, "descriptor metadata");
  auto isVec3f = [&](std::size_t index) { return d.types[index].first == "vec3s"; };
  if (auto p = d.names.find("P"); p != d.names.end()) d.position = p->second;
  if (auto v = d.names.find("v"); v != d.names.end() && isVec3f(v->second)) {
    d.velocity = v->second;
  } else {
    for (const auto& [name, index] : d.names)
      if (name.rfind("particles_velocity", 0) == 0 && isVec3f(index)) {
        d.velocity = index;
        break;
      }
  }
  return d;
}

/// One attribute array of one leaf: its metadata, and where its data lies.
struct ArrayInfo {
  std::uint64_t bytes = 0;  ///< stored bytes (compressed when blosc-compressed and not paged)
  std::uint32_t size = 0;   ///< values (points)
  std::uint32_t strideOrTotal = 1;
  std::uint8_t flags = 0;
  std::uint8_t serialization = 0;
  std::uint32_t page = 0;      ///< paged: index of its page in the attribute's page list
  std::uint64_t location = 0;  ///< paged: offset in the page; else file offset of its data
  bool present = false;        ///< for Leaf::extras: the leaf has this attribute
  bool uniform() const { return serialization & kWriteUniform; }
  bool paged() const { return serialization & kWritePaged; }
  /// Values stored: 1 when uniform (AttributeArray::dataSize otherwise).
  std::uint64_t storedValues() const {
    if (uniform()) return 1;
    return (flags & kConstantStride) ? std::uint64_t(size) * strideOrTotal : strideOrTotal;
  }
};

ArrayInfo readArrayMetadata(Cursor& c, std::uint64_t fileSize) {
  ArrayInfo a;
  const auto bytes = c.get<std::uint64_t>("attribute byte count");
  a.flags = c.get<std::uint8_t>("attribute flags");
  a.serialization = c.get<std::uint8_t>("attribute serialization flags");
  a.size = c.get<std::uint32_t>("attribute size");
  if (a.serialization & kWriteStrided) a.strideOrTotal = c.get<std::uint32_t>("attribute stride");
  if (a.serialization >= 0x10)
    throw c.error("unknown attribute serialization flags " + std::to_string(a.serialization));
  if (bytes < 6) throw c.error("attribute byte count " + std::to_string(bytes) + " is smaller than its header");
  a.bytes = bytes - 6;
  // Paged data lies in pages of at most 2^31 bytes; other data lies in the file itself.
  if (a.paged() ? a.bytes > std::uint64_t(std::numeric_limits<std::int32_t>::max()) : a.bytes > fileSize)
    throw c.error("attribute claims " + std::to_string(a.bytes) + " bytes of data");
  return a;
}

/// One page of a paged attribute stream (compression::Page).
struct Page {
  std::int32_t compressed = 0;  ///< > 0: blosc-compressed bytes; < 0: -(raw bytes)
  std::uint32_t uncompressed = 0;
  std::uint64_t offset = 0;  ///< of its data in the file
  std::uint64_t storedBytes() const {
    return compressed > 0 ? std::uint64_t(compressed) : std::uint64_t(-std::int64_t(compressed));
  }
};

struct Leaf {
  std::array<std::int32_t, 3> origin{};
  std::uint16_t voxelBytes = 0;   ///< pass 0: compressed voxel buffer bytes, 0xffff = raw
  std::uint64_t voxelOffset = 0;  ///< of its voxel data (value mask, size, values)
  std::uint32_t descriptor = 0;
  ArrayInfo position, velocity;
  std::vector<ArrayInfo> extras;  ///< the attributes to decode, by slot (VdbParser::extraNames)
};

struct PointGrid {
  std::string name;
  Transform transform;
  std::vector<Descriptor> descriptors;
  std::vector<Leaf> leaves;
  std::vector<std::vector<Page>> pages;  ///< per attribute index
  std::uint64_t points = 0;
  std::uint64_t activeVoxels = 0;
  bool hasVelocity = false;  ///< the first leaf's descriptor has a velocity attribute
};

/// The bytes a blosc buffer of `compressedBytes` may decompress to.
std::uint64_t maxDecompressedBytes(std::uint64_t compressedBytes) { return compressedBytes * kMaxBloscRatio + 4096; }

// ---- the file parser ----------------------------------------------------------------------

class VdbParser {
 public:
  VdbParser(ByteInput& input, const std::filesystem::path& path, const ReadOptions& options)
      : mInput(input), mPath(path), mOptions(options), mCursor(input, path) {
    if (!options.allAttributes)
      for (const auto& name : options.attributes)
        if (std::find(mExtraNames.begin(), mExtraNames.end(), name) == mExtraNames.end()) mExtraNames.push_back(name);
  }

  std::uint32_t version() const { return mVersion; }
  /// The attributes whose arrays the leaves keep (Leaf::extras), by slot: those ReadOptions asks
  /// for by name, or every attribute met but P for allAttributes.
  const std::vector<std::string>& extraNames() const { return mExtraNames; }

  std::vector<PointGrid> parse() {
    Cursor& c = mCursor;
    if (mInput.size() == 0) throw FileError(mPath, "empty file (0 bytes): not an OpenVDB file");
    if (mInput.size() < 8 || c.get<std::int64_t>("magic") != kVdbMagic)
      throw FileError(mPath, "bad magic: not an OpenVDB file");
    mVersion = c.get<std::uint32_t>("file format version");
    if (mVersion < kMultiPassVersion)
      throw FileError(mPath, "OpenVDB file format version " + std::to_string(mVersion) +
                                 " is not supported (points need version 224, written by OpenVDB 4 or later)");
    c.skip(8, "library version");
    const bool hasOffsets = c.get<std::uint8_t>("grid offsets flag") != 0;
    c.skip(36, "file UUID");
    skipMetadata(c, "file metadata");
    const auto gridCount = c.get<std::int32_t>("grid count");
    if (gridCount < 0) throw c.error("negative grid count " + std::to_string(gridCount));

    std::vector<PointGrid> grids;
    std::string unskippable;    // a grid without offsets that ends the listing early
    std::int32_t unlisted = 0;  // grids after it
    for (std::int32_t g = 0; g < gridCount; ++g) {
      const std::string uniqueName = c.string("grid name");
      std::string type = c.string("grid type");
      const bool halfFloat =
          type.size() > std::strlen(kHalfFloatSuffix) &&
          type.compare(type.size() - std::strlen(kHalfFloatSuffix), std::string::npos, kHalfFloatSuffix) == 0;
      if (halfFloat) type.resize(type.size() - std::strlen(kHalfFloatSuffix));
      const std::string instanceParent = c.string("grid instance parent");
      const auto gridPos = c.get<std::int64_t>("grid offset");
      const auto blockPos = c.get<std::int64_t>("grid block offset");
      const auto endPos = c.get<std::int64_t>("grid end offset");
      const std::string name = uniqueName.substr(0, uniqueName.find('\x1e'));  // GridDescriptor::stripSuffix
      mPresent += (mPresent.empty() ? "" : ", ") + quote(name) + " (" + type + ")";
      const bool isPoints = type == kPointGridType;
      mTypes.emplace(name, type);
      const bool wanted = isPoints && (mOptions.grids.empty() || std::find(mOptions.grids.begin(), mOptions.grids.end(),
                                                                           name) != mOptions.grids.end());
      if (hasOffsets && (gridPos != std::int64_t(c.offset()) || blockPos < gridPos || endPos < blockPos ||
                         std::uint64_t(endPos) > mInput.size()))
        throw c.error("grid " + quote(name) + " has inconsistent offsets " + std::to_string(gridPos) + ", " +
                      std::to_string(blockPos) + ", " + std::to_string(endPos));
      if (!instanceParent.empty()) {
        if (wanted) throw c.error("grid " + quote(name) + " is an instance of another grid, which is not supported");
        if (hasOffsets) {
          c.seek(std::uint64_t(endPos), "the end of a grid");
        } else {
          c.skip(4, "grid compression");
          skipMetadata(c, "grid metadata");
          readTransform(c);
        }
        continue;
      }
      if (wanted || (isPoints && !hasOffsets)) {
        PointGrid grid = readPointGrid(name);
        if (hasOffsets && c.offset() != std::uint64_t(endPos))
          throw c.error("grid " + quote(name) + " ends at byte " + std::to_string(c.offset()) +
                        ", but its descriptor says " + std::to_string(endPos));
        if (wanted) grids.push_back(std::move(grid));
      } else if (hasOffsets) {
        c.seek(std::uint64_t(endPos), "the end of a grid");
      } else {
        unskippable = name;  // no offsets: the end of this grid cannot be found without decoding it
        unlisted = gridCount - g - 1;
        if (unlisted > 0) mPresent += ", and " + std::to_string(unlisted) + " more";
        break;
      }
    }
    if (unskippable.empty() && c.offset() != mInput.size())
      throw c.error(std::to_string(mInput.size() - c.offset()) + " bytes follow the last grid");

    auto missing = [&](const std::string& what) {
      std::string text = what + " (grids: " + (mPresent.empty() ? "none" : mPresent) + ")";
      if (unlisted > 0)
        text += "; grid " + quote(unskippable) +
                " is not points and the file has no grid offsets, so the grids after it cannot be read";
      return FileError(mPath, text);
    };
    if (mOptions.grids.empty()) {
      if (grids.empty()) throw missing("no PointDataGrid in the file");
      if (unlisted > 0) throw missing("cannot read every PointDataGrid");
    } else {
      for (const auto& name : mOptions.grids) {
        auto type = mTypes.find(name);
        if (type == mTypes.end()) throw missing("no grid named " + quote(name));
        if (type->second != kPointGridType)
          throw FileError(mPath, "grid " + quote(name) + " is a " + type->second + ", not a PointDataGrid");
      }
    }
    return grids;
  }

 private:
  PointGrid readPointGrid(const std::string& name) {
    Cursor& c = mCursor;
    PointGrid grid;
    grid.name = name;
    mCompression = c.get<std::uint32_t>("grid compression");
    if (mCompression > (kCompressZip | kCompressActiveMask | kCompressBlosc))
      throw c.error("unknown grid compression flags " + std::to_string(mCompression));
    skipMetadata(c, "grid metadata");
    grid.transform = readTransform(c);
    readTopology(grid);
    readBuffers(grid);
    return grid;
  }

  // Topology: RootNode, InternalNode<5>, InternalNode<4>, LeafNode<3> (readTopology).
  void readTopology(PointGrid& grid) {
    Cursor& c = mCursor;
    c.skip(4, "tree buffer count");
    c.skip(4, "background value");
    const auto tiles = c.get<std::uint32_t>("root tile count");
    const auto children = c.get<std::uint32_t>("root child count");
    for (std::uint32_t t = 0; t < tiles; ++t) {
      c.skip(12 + 4, "root tile");
      if (c.get<std::uint8_t>("root tile state")) grid.activeVoxels += std::uint64_t(1) << 36;  // 4096^3
    }
    std::optional<std::array<std::int32_t, 3>> previous;
    for (std::uint32_t n = 0; n < children; ++n) {
      std::array<std::int32_t, 3> origin;
      c.read(origin.data(), sizeof origin, "root child origin");
      for (std::int32_t v : origin)
        if (v % 4096 != 0) throw c.error("root child origin is not a multiple of 4096");
      if (previous && !(*previous < origin)) throw c.error("root children out of order");
      previous = origin;
      readInternal(grid, 5, origin);
    }
  }

  void readInternal(PointGrid& grid, int log2, const std::array<std::int32_t, 3>& origin) {
    Cursor& c = mCursor;
    const std::size_t values = std::size_t(1) << (3 * log2);
    const std::size_t words = values / 64;
    std::vector<std::uint64_t> childMask(words), valueMask(words);
    c.read(childMask.data(), words * 8, "internal node child mask");
    c.read(valueMask.data(), words * 8, "internal node value mask");
    std::uint64_t active = 0, tiles = 0;
    for (std::size_t w = 0; w < words; ++w) {
      active += std::popcount(valueMask[w]);
      tiles += std::popcount(valueMask[w] & ~childMask[w]);
    }
    skipCompressedValues(values, active, log2 == 5 ? 4096 : 512, "internal node values");
    const std::int32_t childDim = log2 == 5 ? 128 : 8;
    grid.activeVoxels += tiles * (log2 == 5 ? std::uint64_t(128 * 128 * 128) : 512);
    for (std::size_t w = 0; w < words; ++w)
      for (std::uint64_t bits = childMask[w]; bits; bits &= bits - 1) {
        const std::size_t i = w * 64 + std::size_t(std::countr_zero(bits));
        const std::array<std::int32_t, 3> child{
            origin[0] + std::int32_t(i >> (2 * log2)) * childDim,
            origin[1] + std::int32_t((i >> log2) & ((std::size_t(1) << log2) - 1)) * childDim,
            origin[2] + std::int32_t(i & ((std::size_t(1) << log2) - 1)) * childDim};
        if (log2 == 5) {
          readInternal(grid, 4, child);
        } else {
          std::array<std::uint64_t, 8> mask;
          c.read(mask.data(), sizeof mask, "leaf value mask");
          for (std::uint64_t word : mask) grid.activeVoxels += std::popcount(word);
          Leaf leaf;
          leaf.origin = child;
          grid.leaves.push_back(leaf);
        }
      }
  }

  /// io::readCompressedValues of an internal node's PointDataIndex32 values, skipped.
  void skipCompressedValues(std::size_t values, std::uint64_t active, std::size_t maskBytes, const char* what) {
    Cursor& c = mCursor;
    const auto metadata = c.get<std::uint8_t>(what);
    if (metadata > 6) throw c.error(std::string(what) + ": unknown compression metadata " + std::to_string(metadata));
    if (metadata == 2 || metadata == 4 || metadata == 5) c.skip(4, what);  // one inactive value
    if (metadata == 5) c.skip(4, what);                                    // a second one
    if (metadata >= 3 && metadata <= 5) c.skip(maskBytes, what);           // selection mask
    const std::uint64_t count = (mCompression & kCompressActiveMask) && metadata != 6 ? active : values;
    const std::uint64_t bytes = count * 4;
    if (mCompression & (kCompressBlosc | kCompressZip)) {
      const auto stored = c.get<std::int64_t>(what);  // < 0: -(raw bytes)
      if (stored <= 0) {
        const std::uint64_t raw = std::uint64_t(0) - std::uint64_t(stored);  // -stored, defined for INT64_MIN too
        if (raw != bytes)
          throw c.error(std::string(what) + ": " + std::to_string(raw) + " raw bytes, expected " +
                        std::to_string(bytes));
        c.skip(bytes, what);
      } else {
        c.skip(std::uint64_t(stored), what);
      }
    } else {
      c.skip(bytes, what);
    }
  }

  // Buffers: the passes of PointDataLeafNode::readBuffers, every leaf in each pass.
  void readBuffers(PointGrid& grid) {
    Cursor& c = mCursor;
    const auto passes = c.get<std::uint16_t>("buffer pass count");
    if (grid.leaves.empty()) return;
    if (passes < 4 || passes % 2 != 0) throw c.error("invalid buffer pass count " + std::to_string(passes));
    const std::size_t attributes = (passes - 4) / 2;

    // Pass 0: voxel buffer sizes.
    for (Leaf& leaf : grid.leaves) {
      leaf.voxelBytes = c.get<std::uint16_t>("voxel buffer size");
      if (leaf.voxelBytes != kUncompressedVoxels &&
          (leaf.voxelBytes < kBloscHeaderBytes || leaf.voxelBytes >= kVoxelBufferBytes))
        throw c.error("invalid voxel buffer size " + std::to_string(leaf.voxelBytes));
    }

    // Pass 1: descriptors (one shared, or one per leaf) and attribute metadata.
    std::vector<std::uint64_t> arrays;      // every leaf's arrays: bytes << 2 | paged << 1 | uniform
    std::vector<std::uint64_t> firstArray;  // per leaf, into `arrays`; and the end
    std::optional<std::uint32_t> shared;
    std::size_t mostAttributes = 0;
    for (Leaf& leaf : grid.leaves) {
      if (shared) {
        leaf.descriptor = *shared;
      } else {
        const auto header = c.get<std::uint8_t>("descriptor header");
        Descriptor d = readDescriptor(c);
        if (header & 2) c.skip(c.get<std::uint64_t>("descriptor extra bytes"), "descriptor extra bytes");
        if (header > 3) throw c.error("unknown descriptor header flags " + std::to_string(header));
        assignSlots(d);
        if (grid.descriptors.empty() || !(grid.descriptors.back() == d)) grid.descriptors.push_back(std::move(d));
        leaf.descriptor = std::uint32_t(grid.descriptors.size() - 1);
        if (header & 1) shared = leaf.descriptor;
      }
      const Descriptor& d = grid.descriptors[leaf.descriptor];
      mostAttributes = std::max(mostAttributes, d.types.size());
      firstArray.push_back(arrays.size());
      for (std::size_t a = 0; a < d.types.size(); ++a) {
        const ArrayInfo info = readArrayMetadata(c, mInput.size());
        arrays.push_back(info.bytes << 2 | std::uint64_t(info.paged()) << 1 | std::uint64_t(info.uniform()));
        if (a == d.position) leaf.position = info;
        if (a == d.velocity) leaf.velocity = info;
        if (const int slot = d.slots[a]; slot >= 0) {
          if (leaf.extras.size() <= std::size_t(slot)) leaf.extras.resize(std::size_t(slot) + 1);
          leaf.extras[std::size_t(slot)] = info;
          leaf.extras[std::size_t(slot)].present = true;
        }
      }
    }
    firstArray.push_back(arrays.size());
    if (mostAttributes != attributes)
      throw c.error("buffer pass count " + std::to_string(passes) + " does not match " +
                    std::to_string(mostAttributes) + " attributes");
    grid.hasVelocity = grid.descriptors[grid.leaves.front().descriptor].velocity != SIZE_MAX;
    checkAttributes(grid);

    // Passes 2 .. attributes + 1: page headers of each paged attribute (PagedInputStream).
    grid.pages.resize(attributes);
    for (std::size_t a = 0; a < attributes; ++a) {
      std::uint64_t byteIndex = 0, pageBytes = 0;
      for (std::size_t l = 0; l < grid.leaves.size(); ++l) {
        if (firstArray[l] + a >= firstArray[l + 1]) continue;
        const std::uint64_t packed = arrays[firstArray[l] + a];
        if (!(packed & 2)) continue;
        if (byteIndex == pageBytes) {  // createHandle: the page is used up, a new one starts
          Page page;
          page.compressed = c.get<std::int32_t>("page size");
          if (page.compressed > 0) {
            const auto uncompressed = c.get<std::int32_t>("page uncompressed size");
            if (uncompressed <= 0) throw c.error("invalid page size " + std::to_string(uncompressed));
            page.uncompressed = std::uint32_t(uncompressed);
            if (page.uncompressed > maxDecompressedBytes(std::uint64_t(page.compressed)))
              throw c.error("page of " + std::to_string(page.compressed) + " bytes claims " +
                            std::to_string(page.uncompressed) + " bytes uncompressed");
          } else {
            if (page.compressed == 0 || page.compressed == std::numeric_limits<std::int32_t>::min())
              throw c.error("invalid page size " + std::to_string(page.compressed));
            page.uncompressed = std::uint32_t(-page.compressed);
          }
          grid.pages[a].push_back(page);
          byteIndex = 0;
          pageBytes = grid.pages[a].back().uncompressed;
        }
        const std::uint64_t bytes = packed >> 2;
        if (byteIndex + bytes > pageBytes)
          throw c.error("attribute " + std::to_string(a) + " of leaf " + std::to_string(l) +
                        " runs past the end of its page");
        Leaf& leaf = grid.leaves[l];
        forEachArray(leaf, grid.descriptors[leaf.descriptor], a, [&](ArrayInfo& info) {
          info.page = std::uint32_t(grid.pages[a].size() - 1);
          info.location = byteIndex;
        });
        byteIndex += bytes;
      }
    }

    // Pass attributes + 2: voxel data (value mask, voxel buffer size, voxel buffer).
    std::uint64_t offset = c.offset();
    auto advance = [&](std::uint64_t bytes, const char* what) {
      if (bytes > mInput.size() - offset) {
        c.seek(offset, what);
        c.need(bytes, what);
      }
      offset += bytes;
    };
    for (Leaf& leaf : grid.leaves) {
      leaf.voxelOffset = offset;
      advance(64 + 2 + (leaf.voxelBytes == kUncompressedVoxels ? kVoxelBufferBytes : leaf.voxelBytes), "voxel data");
    }

    // Passes attributes + 3 .. 2 * attributes + 2: attribute data, page by page or inline.
    for (std::size_t a = 0; a < attributes; ++a) {
      std::uint64_t byteIndex = 0, pageBytes = 0;
      std::size_t nextPage = 0;
      for (std::size_t l = 0; l < grid.leaves.size(); ++l) {
        if (firstArray[l] + a >= firstArray[l + 1]) continue;
        const std::uint64_t packed = arrays[firstArray[l] + a];
        const std::uint64_t bytes = packed >> 2;
        Leaf& leaf = grid.leaves[l];
        const Descriptor& d = grid.descriptors[leaf.descriptor];
        if (packed & 2) {
          if (byteIndex == pageBytes) {
            FLIPSCOPE_CHECK(nextPage < grid.pages[a].size(), "pages of attribute " << a);
            Page& page = grid.pages[a][nextPage++];
            page.offset = offset;
            advance(page.storedBytes(), "attribute page");
            byteIndex = 0;
            pageBytes = page.uncompressed;
          }
          byteIndex += bytes;
        } else {
          forEachArray(leaf, d, a, [&](ArrayInfo& info) { info.location = offset; });
          advance((packed & 1 ? 0 : 1) + bytes, "attribute data");
        }
      }
      FLIPSCOPE_CHECK(nextPage == grid.pages[a].size(), "pages of attribute " << a);
    }
    c.seek(offset, "the end of the grid");
  }

  /// The slots of `d`'s attributes (Descriptor::slots), adding names for allAttributes.
  void assignSlots(Descriptor& d) {
    d.slots.assign(d.types.size(), -1);
    for (const auto& [name, index] : d.names) {
      if (index == d.position) continue;
      auto found = std::find(mExtraNames.begin(), mExtraNames.end(), name);
      if (found == mExtraNames.end()) {
        if (!mOptions.allAttributes) continue;
        found = mExtraNames.insert(mExtraNames.end(), name);
      }
      d.slots[index] = int(found - mExtraNames.begin());
    }
  }

  /// Calls fn for each array the leaf keeps of attribute index `a`: P, the velocity, an extra.
  template <class Fn>
  static void forEachArray(Leaf& leaf, const Descriptor& d, std::size_t a, Fn&& fn) {
    if (a == d.position) fn(leaf.position);
    if (a == d.velocity) fn(leaf.velocity);
    if (const int slot = d.slots[a]; slot >= 0) fn(leaf.extras[std::size_t(slot)]);
  }

  /// P and the velocity of every leaf: known codecs, sizes that agree.
  void checkAttributes(PointGrid& grid) {
    Cursor& c = mCursor;
    const bool velocity = mOptions.velocity && grid.hasVelocity;
    for (std::size_t l = 0; l < grid.leaves.size(); ++l) {
      Leaf& leaf = grid.leaves[l];
      const Descriptor& d = grid.descriptors[leaf.descriptor];
      const std::string where = "grid " + quote(grid.name) + ": leaf at (" + std::to_string(leaf.origin[0]) + ", " +
                                std::to_string(leaf.origin[1]) + ", " + std::to_string(leaf.origin[2]) + ")";
      if (d.position == SIZE_MAX || d.types[d.position].first != "vec3s")
        throw FileError(mPath, where + " has no vec3s position attribute P");
      checkArray(c, where + ": P", leaf.position, d.types[d.position].second);
      grid.points += leaf.position.size;
      if (!velocity) continue;
      if (d.velocity == SIZE_MAX) throw FileError(mPath, where + " has no velocity attribute, unlike the first leaf");
      checkArray(c, where + ": velocity", leaf.velocity, d.types[d.velocity].second);
      if (leaf.velocity.size != leaf.position.size)
        throw FileError(mPath, where + " has " + std::to_string(leaf.position.size) + " positions but " +
                                   std::to_string(leaf.velocity.size) + " velocities");
    }
  }

  void checkArray(Cursor& c, const std::string& what, const ArrayInfo& a, const std::string& codecName) {
    const Vec3Codec* codec = findVec3Codec(codecName);
    if (!codec) throw FileError(mPath, what + " has the unknown vec3s codec " + quote(codecName));
    if (!a.uniform() && a.storedValues() != a.size)
      throw c.error(what + " stores " + std::to_string(a.storedValues()) + " values for " + std::to_string(a.size) +
                    " points");
    const std::uint64_t expected = a.storedValues() * codec->bytes;
    const bool exact = a.paged() || a.uniform();  // otherwise it may be blosc-compressed
    if (exact ? a.bytes != expected : a.bytes > expected)
      throw c.error(what + " holds " + std::to_string(a.bytes) + " bytes for " + std::to_string(expected) +
                    " bytes of values");
  }

  ByteInput& mInput;
  const std::filesystem::path& mPath;
  const ReadOptions& mOptions;
  Cursor mCursor;
  std::uint32_t mVersion = 0;
  std::uint32_t mCompression = 0;
  std::string mPresent;
  std::map<std::string, std::string> mTypes;  ///< grid name -> type
  std::vector<std::string> mExtraNames;
};

// ---- the reader -----------------------------------------------------------------------

class VdbPointsReader final : public ParticleSource {
 public:
  VdbPointsReader(std::unique_ptr<ByteInput> input, std::filesystem::path path, ReadOptions options)
      : mInput(std::move(input)), mPath(std::move(path)), mOptions(std::move(options)) {
    guarded([&] {
      VdbParser parser(*mInput, mPath, mOptions);
      mGrids = parser.parse();
      mFileVersion = parser.version();
      mExtraNames = parser.extraNames();
    });
    listAttributes();
    selectColumns();
    bool any = false;
    mHasVelocity = mOptions.velocity;
    for (const auto& g : mGrids) {
      mCount += g.points;
      addSpacingHint(g);
      if (!g.leaves.empty()) {
        any = true;
        mHasVelocity = mHasVelocity && g.hasVelocity;
      }
    }
    mHasVelocity = mHasVelocity && any;
  }

  std::string name() const override { return mPath.string(); }
  std::string format() const override { return "OpenVDB points, file format " + std::to_string(mFileVersion); }
  bool hasVelocity() const override { return mHasVelocity; }
  std::optional<std::uint64_t> countHint() const override { return mCount; }
  std::vector<AttributeDesc> attributes() const override { return mAttributes; }
  /// Particles per active voxel of the topology (no attribute is read): a FLIP solver's
  /// points grid has a voxel per simulation cell, and its particles fill the active ones.
  std::optional<SpacingHint> spacingHint() const override {
    if (mSpacing.points == 0 || !(mSpacing.volume > 0) || !std::isfinite(mSpacing.volume)) return std::nullopt;
    return mSpacing;
  }
  std::optional<std::string> kindAttribute() const override {
    const bool secondary = std::any_of(mGrids.begin(), mGrids.end(),
                                       [](const PointGrid& g) { return g.name == "particles_secondary"; });
    const bool typed = std::any_of(mAttributes.begin(), mAttributes.end(), [](const AttributeDesc& a) {
      return a.name == "U" && a.arity == 1 && isIntegerType(a.type);
    });
    if (secondary && typed) return std::string("U");
    return std::nullopt;
  }
  /// Blender's fluid caches name their points grids `particles` (the FLIP particles) and
  /// `particles_secondary` (spray, foam, bubbles), and Blender's world is +z up.
  UpAxis upAxis() const override {
    const bool blender = !mGrids.empty() && std::all_of(mGrids.begin(), mGrids.end(), [](const PointGrid& g) {
      return g.name == "particles" || g.name == "particles_secondary";
    });
    return blender ? UpAxis::Z : UpAxis::Unknown;
  }

  bool read(ParticleChunk& chunk, std::size_t maxParticles) override {
    FLIPSCOPE_CHECK(maxParticles > 0);
    chunk.clear();
    syncColumns(chunk.attributes, mColumns);
    guarded([&] { readInto(chunk, maxParticles); });
    return chunk.size() > 0;
  }

  void rewind() override {
    mGrid = mLeaf = 0;
    mLeafLoaded = false;
  }

 private:
  /// Runs `work`; an allocation failure (the sizes are checked, so memory is short) names the file.
  template <class Work>
  void guarded(Work&& work) {
    try {
      work();
    } catch (const std::bad_alloc&) {
      throw FileError(mPath, "out of memory while reading the OpenVDB file");
    }
  }

  /// attributes(): those every descriptor of every grid read has with the same value type and
  /// components, P excepted, in the order of the first descriptor's indices.
  void listAttributes() {
    bool first = true;
    for (const PointGrid& g : mGrids)
      for (const Descriptor& d : g.descriptors) {
        std::vector<std::string> names(d.types.size());
        for (const auto& [name, index] : d.names) names[index] = name;
        std::vector<AttributeDesc> here;
        for (std::size_t a = 0; a < d.types.size(); ++a) {
          if (a == d.position) continue;
          const CodecEntry* entry = findValueType(d.types[a].first);
          if (!entry) {
            mUnknownTypes.emplace(names[a], d.types[a].first);
            continue;
          }
          here.push_back({names[a], entry->valueType, entry->decoder.arity});
        }
        if (first)
          mAttributes = std::move(here);
        else
          std::erase_if(mAttributes,
                        [&](const AttributeDesc& a) { return std::find(here.begin(), here.end(), a) == here.end(); });
        first = false;
      }
  }

  /// The columns ReadOptions asks for: each must be decodable in every leaf of every grid read.
  void selectColumns() {
    if (!mOptions.allAttributes)
      for (const auto& name : mOptions.attributes)
        if (auto unknown = mUnknownTypes.find(name);
            unknown != mUnknownTypes.end() && std::none_of(mAttributes.begin(), mAttributes.end(),
                                                           [&](const AttributeDesc& a) { return a.name == name; }))
          throw FileError(mPath, "attribute " + quote(name) + " has the value type " + quote(unknown->second) +
                                     ", which flipscope does not read");
    const std::vector<std::size_t> selected = selectAttributes(mAttributes, mOptions, mPath);
    mColumns = makeColumns(mAttributes, selected);
    mColumnSources.assign(mGrids.size(), {});
    for (std::size_t index : selected) {
      const std::string& name = mAttributes[index].name;
      const auto slot = std::find(mExtraNames.begin(), mExtraNames.end(), name);
      FLIPSCOPE_CHECK(slot != mExtraNames.end(), name);
      mColumnSlots.push_back(std::size_t(slot - mExtraNames.begin()));
    }
    for (std::size_t gi = 0; gi < mGrids.size(); ++gi) {
      const PointGrid& g = mGrids[gi];
      for (const Descriptor& d : g.descriptors) {
        std::vector<ColumnSource> sources;
        for (std::size_t k = 0; k < mColumnSlots.size(); ++k) {
          const std::size_t a = d.indexOfSlot(int(mColumnSlots[k]));
          FLIPSCOPE_CHECK(a != SIZE_MAX, mColumns[k].name);
          const auto& [type, codecName] = d.types[a];
          const AttributeCodec* codec = findAttributeCodec(type, codecName);
          if (!codec)
            throw FileError(mPath, "grid " + quote(g.name) + ": attribute " + quote(mColumns[k].name) + " is " +
                                       quote(type) + " stored with the codec " + quote(codecName) +
                                       (codecName == "grp"   ? " (group membership bits, not values)"
                                        : codecName == "str" ? " (indices of strings, not values)"
                                                             : "") +
                                       ", which flipscope cannot decode");
          sources.push_back({a, codec});
        }
        mColumnSources[gi].push_back(std::move(sources));
      }
      for (const Leaf& leaf : g.leaves)
        for (std::size_t k = 0; k < mColumnSlots.size(); ++k)
          checkExtra(g, leaf, k, *mColumnSources[gi][leaf.descriptor][k].codec);
    }
  }

  /// An extra array's sizes against its points and its codec (as checkArray does for P).
  void checkExtra(const PointGrid& g, const Leaf& leaf, std::size_t column, const AttributeCodec& codec) const {
    const ArrayInfo& a = leaf.extras[mColumnSlots[column]];
    FLIPSCOPE_CHECK(a.present, mColumns[column].name);
    const std::string what = "attribute " + quote(mColumns[column].name);
    if (a.serialization & kWriteStrided)
      throw FileError(mPath, leafName(g, leaf) + ": " + what +
                                 " is a strided array (several values a point), which flipscope does not read");
    if (!a.uniform() && a.storedValues() != a.size)
      throw leafError(
          g, leaf,
          what + " stores " + std::to_string(a.storedValues()) + " values for " + std::to_string(a.size) + " points");
    if (a.size != leaf.position.size)
      throw leafError(
          g, leaf,
          what + " has " + std::to_string(a.size) + " values for " + std::to_string(leaf.position.size) + " positions");
    const std::uint64_t expected = a.storedValues() * codec.bytes;
    const bool exact = a.paged() || a.uniform();  // otherwise it may be blosc-compressed
    if (exact ? a.bytes != expected : a.bytes > expected)
      throw leafError(
          g, leaf,
          what + " holds " + std::to_string(a.bytes) + " bytes for " + std::to_string(expected) + " bytes of values");
  }

  void addSpacingHint(const PointGrid& g) {
    if (g.points == 0 || g.activeVoxels == 0) return;
    mSpacing.volume += double(g.activeVoxels) * g.transform.voxelVolume();
    mSpacing.points += g.points;
    std::ostringstream text;
    text << (mSpacing.origin.empty() ? "OpenVDB grid '" : ", grid '") << g.name << "': " << g.points << " points in "
         << g.activeVoxels << " active voxels of " << g.transform.voxelSize()[0];
    mSpacing.origin += text.str();
  }

  void readInto(ParticleChunk& chunk, std::size_t maxParticles) {
    while (chunk.size() < maxParticles && mGrid < mGrids.size()) {
      const PointGrid& g = mGrids[mGrid];
      if (mLeaf == g.leaves.size()) {
        ++mGrid;
        mLeaf = 0;
        continue;
      }
      if (!mLeafLoaded) loadLeaf(g, g.leaves[mLeaf]);
      if (emitPoints(g, g.leaves[mLeaf], chunk, maxParticles)) {
        ++mLeaf;
        mLeafLoaded = false;
      }
    }
  }

  std::string leafName(const PointGrid& g, const Leaf& leaf) const {
    return "grid '" + g.name + "': leaf at (" + std::to_string(leaf.origin[0]) + ", " + std::to_string(leaf.origin[1]) +
           ", " + std::to_string(leaf.origin[2]) + ")";
  }
  FileError leafError(const PointGrid& g, const Leaf& leaf, const std::string& what) const {
    return FileError(mPath, "corrupted OpenVDB file: " + leafName(g, leaf) + ": " + what);
  }

  /// Decompresses the blosc buffer `src` into exactly `expected` bytes of `out`.
  void bloscDecompress(std::span<const std::byte> src, std::byte* out, std::size_t expected,
                       const std::function<FileError(const std::string&)>& fail) {
    std::size_t nbytes = 0;
    if (src.size() < kBloscHeaderBytes || blosc_cbuffer_validate(src.data(), src.size(), &nbytes) != 0)
      throw fail("not a valid blosc buffer of " + std::to_string(src.size()) + " bytes");
    // OpenVDB pads buffers of fewer than 128 bytes to 128 before compressing them.
    const bool padded = expected < kBloscPadBytes && nbytes == kBloscPadBytes;
    if (nbytes != expected && !padded)
      throw fail("blosc buffer holds " + std::to_string(nbytes) + " bytes, expected " + std::to_string(expected));
    if (nbytes > maxDecompressedBytes(src.size()))
      throw fail("blosc buffer of " + std::to_string(src.size()) + " bytes claims " + std::to_string(nbytes));
    std::byte* target = out;
    if (padded) {
      mScratch.resize(nbytes);
      target = mScratch.data();
    }
    const int got = blosc_decompress_ctx(src.data(), target, nbytes, 1);
    if (got < 0 || std::size_t(got) != nbytes) throw fail("blosc data is corrupted");
    if (padded) std::memcpy(out, target, expected);
  }

  std::vector<std::byte>& readBytes(std::uint64_t offset, std::size_t n, std::vector<std::byte>& out) {
    FLIPSCOPE_CHECK(offset <= mInput->size() && n <= mInput->size() - offset, offset << " + " << n);
    out.resize(n);
    mInput->read(offset, out.data(), n);
    return out;
  }

  void loadLeaf(const PointGrid& g, const Leaf& leaf) {
    auto fail = [&](const std::string& what) { return leafError(g, leaf, what); };
    // Voxel data: the value mask (not needed: the topology's is the same), the buffer size, offsets.
    std::uint16_t stored = 0;
    mInput->read(leaf.voxelOffset + 64, &stored, 2);
    if (stored != leaf.voxelBytes)
      throw fail("voxel buffer size " + std::to_string(stored) + " differs from " + std::to_string(leaf.voxelBytes));
    std::vector<std::byte>& raw = readBytes(
        leaf.voxelOffset + 66, leaf.voxelBytes == kUncompressedVoxels ? kVoxelBufferBytes : leaf.voxelBytes, mRaw);
    if (leaf.voxelBytes == kUncompressedVoxels) {
      std::memcpy(mOffsets.data(), raw.data(), kVoxelBufferBytes);
    } else {
      bloscDecompress(raw, reinterpret_cast<std::byte*>(mOffsets.data()), kVoxelBufferBytes,
                      [&](const std::string& what) { return fail("voxel offsets: " + what); });
    }
    std::uint32_t previous = 0;
    for (std::uint32_t end : mOffsets) {
      if (end < previous) throw fail("voxel offsets decrease");
      previous = end;
    }
    if (previous != leaf.position.size)
      throw fail("voxels index " + std::to_string(previous) + " points, but P holds " +
                 std::to_string(leaf.position.size));
    const Descriptor& d = g.descriptors[leaf.descriptor];
    decodeArray(g, leaf, leaf.position, d.position, d.types[d.position].second, mPositions, mPositionPage, "P");
    if (mHasVelocity)
      decodeArray(g, leaf, leaf.velocity, d.velocity, d.types[d.velocity].second, mVelocities, mVelocityPage,
                  "velocity");
    mExtraValues.resize(mColumns.size());
    mExtraPages.resize(mColumns.size());
    for (std::size_t k = 0; k < mColumns.size(); ++k) {
      const ColumnSource& source = mColumnSources[mGrid][leaf.descriptor][k];
      const ArrayInfo& a = leaf.extras[mColumnSlots[k]];
      const AttributeCodec& codec = *source.codec;
      const std::byte* data =
          arrayBytes(g, leaf, a, source.index, codec.bytes, mExtraPages[k], "attribute " + quote(mColumns[k].name));
      const std::size_t values = std::size_t(a.storedValues());
      std::vector<float>& out = mExtraValues[k];
      out.resize(values * std::size_t(codec.arity));
      for (std::size_t i = 0; i < values; ++i) codec.decode(data + i * codec.bytes, out.data() + i * codec.arity);
    }
    mVoxel = 0;
    mPoint = 0;
    mLeafLoaded = true;
  }

  struct CachedPage {
    const PointGrid* grid = nullptr;
    std::size_t attribute = 0;
    std::uint32_t page = 0;
    std::vector<std::byte> bytes;
  };

  void decodeArray(const PointGrid& g, const Leaf& leaf, const ArrayInfo& a, std::size_t attribute,
                   const std::string& codecName, std::vector<Vec3f>& out, CachedPage& cache, const char* what) {
    const Vec3Codec* codec = findVec3Codec(codecName);
    FLIPSCOPE_CHECK(codec, codecName);
    const std::byte* data = arrayBytes(g, leaf, a, attribute, codec->bytes, cache, what);
    const std::size_t values = std::size_t(a.storedValues());
    out.resize(values);
    for (std::size_t i = 0; i < values; ++i) out[i] = codec->decode(data + i * codec->bytes);
  }

  /// The stored values of the leaf's array `a` (attribute index `attribute`), `valueBytes` each,
  /// read and decompressed: valid until the next call.
  const std::byte* arrayBytes(const PointGrid& g, const Leaf& leaf, const ArrayInfo& a, std::size_t attribute,
                              std::size_t valueBytes, CachedPage& cache, const std::string& what) {
    auto fail = [&](const std::string& text) { return leafError(g, leaf, what + ": " + text); };
    const std::size_t values = std::size_t(a.storedValues());
    const std::size_t bytes = values * valueBytes;
    const std::byte* data = nullptr;
    if (a.paged()) {
      const Page& page = g.pages[attribute][a.page];
      if (cache.grid != &g || cache.attribute != attribute || cache.page != a.page || cache.bytes.empty()) {
        cache.grid = nullptr;
        std::vector<std::byte>& stored = readBytes(page.offset, std::size_t(page.storedBytes()), mRaw);
        if (page.compressed > 0) {
          cache.bytes.resize(page.uncompressed);
          bloscDecompress(stored, cache.bytes.data(), page.uncompressed,
                          [&](const std::string& text) { return fail("page: " + text); });
        } else {
          cache.bytes.swap(stored);
        }
        cache.grid = &g;
        cache.attribute = attribute;
        cache.page = a.page;
      }
      data = cache.bytes.data() + a.location;  // location + bytes <= page size: checked when opened
    } else {
      std::uint8_t compressed = 0;
      std::uint64_t offset = a.location;
      if (!a.uniform()) {
        mInput->read(offset, &compressed, 1);
        ++offset;
      }
      std::vector<std::byte>& stored = readBytes(offset, std::size_t(a.bytes), mRaw);
      if (compressed == 1) {
        if (bytes > maxDecompressedBytes(stored.size()))
          throw fail("blosc buffer of " + std::to_string(stored.size()) + " bytes claims " + std::to_string(bytes));
        mDecoded.resize(bytes);
        bloscDecompress(stored, mDecoded.data(), bytes, fail);
        data = mDecoded.data();
      } else {
        if (stored.size() != bytes)
          throw fail(std::to_string(stored.size()) + " raw bytes for " + std::to_string(bytes) + " bytes of values");
        data = stored.data();
      }
    }
    return data;
  }

  /// Appends points of the loaded leaf from (mVoxel, mPoint) on; true when the leaf is finished.
  bool emitPoints(const PointGrid& g, const Leaf& leaf, ParticleChunk& chunk, std::size_t maxParticles) {
    const bool uniformP = leaf.position.uniform();
    const bool uniformV = leaf.velocity.uniform();
    for (; mVoxel < kLeafVoxels; ++mVoxel) {
      const std::uint32_t end = mOffsets[mVoxel];
      if (mPoint >= end) continue;
      const Vec3d voxel(leaf.origin[0] + std::int32_t(mVoxel >> 6), leaf.origin[1] + std::int32_t((mVoxel >> 3) & 7),
                        leaf.origin[2] + std::int32_t(mVoxel & 7));
      for (; mPoint < end; ++mPoint) {
        if (chunk.size() == maxParticles) return false;
        const Vec3f& p = mPositions[uniformP ? 0 : mPoint];
        const Vec3d world = g.transform.indexToWorld(voxel + Vec3d(p));
        chunk.positions.emplace_back(float(world.x()), float(world.y()), float(world.z()));
        if (mHasVelocity) {
          const Vec3f& v = mVelocities[uniformV ? 0 : mPoint];
          chunk.velocities.emplace_back(v.x(), v.y(), v.z());
        }
        for (std::size_t k = 0; k < mColumns.size(); ++k) {
          const std::size_t arity = std::size_t(mColumns[k].arity);
          const float* value = mExtraValues[k].data() + (leaf.extras[mColumnSlots[k]].uniform() ? 0 : mPoint) * arity;
          chunk.attributes[k].values.insert(chunk.attributes[k].values.end(), value, value + arity);
        }
      }
    }
    return true;
  }

  std::unique_ptr<ByteInput> mInput;
  std::filesystem::path mPath;
  ReadOptions mOptions;
  std::vector<PointGrid> mGrids;
  std::uint64_t mCount = 0;
  SpacingHint mSpacing;
  bool mHasVelocity = false;
  // Reading position, and the decoded current leaf.
  std::size_t mGrid = 0;
  std::size_t mLeaf = 0;
  bool mLeafLoaded = false;
  std::size_t mVoxel = 0;
  std::uint32_t mPoint = 0;
  std::array<std::uint32_t, kLeafVoxels> mOffsets{};
  std::vector<Vec3f> mPositions, mVelocities;
  std::uint32_t mFileVersion = 0;
  CachedPage mPositionPage, mVelocityPage;
  // Attributes: listed, and the columns read (ReadOptions::attributes).
  struct ColumnSource {
    std::size_t index = 0;  ///< attribute index in the descriptor
    const AttributeCodec* codec = nullptr;
  };
  std::vector<std::string> mExtraNames;                                ///< VdbParser::extraNames
  std::vector<AttributeDesc> mAttributes;                              ///< attributes()
  std::map<std::string, std::string> mUnknownTypes;                    ///< name -> value type flipscope does not know
  std::vector<AttributeColumn> mColumns;                               ///< the columns read, empty
  std::vector<std::size_t> mColumnSlots;                               ///< per column: its slot in Leaf::extras
  std::vector<std::vector<std::vector<ColumnSource>>> mColumnSources;  ///< [grid][descriptor][column]
  std::vector<std::vector<float>> mExtraValues;                        ///< per column: the loaded leaf's values
  std::vector<CachedPage> mExtraPages;
  std::vector<std::byte> mRaw, mDecoded, mScratch;
};

}  // namespace

bool isVdb(std::span<const std::byte> head) {
  // OPENVDB_MAGIC, 0x56444220, as a little-endian int32.
  constexpr std::array<std::byte, 4> kMagic{std::byte{0x20}, std::byte{0x42}, std::byte{0x44}, std::byte{0x56}};
  return head.size() >= 4 && std::equal(kMagic.begin(), kMagic.end(), head.begin());
}

std::unique_ptr<ParticleSource> openVdbPoints(InputFile file, const ReadOptions& options) {
  std::filesystem::path path = file.path();
  return std::make_unique<VdbPointsReader>(std::make_unique<InputFileInput>(std::move(file)), std::move(path), options);
}

}  // namespace flipscope::detail
