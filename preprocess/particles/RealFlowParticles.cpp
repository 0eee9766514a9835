// RealFlow particle cache (.bin, Next Limit; the layout as described by the readers and
// writers that exchange it, e.g. Thinkbox's RealFlow .bin streams, checked against a real
// sequence). Little-endian, packed.
//
// Header (356 bytes from version 7 on, 320 before): int32 magic 0x00FABADA, the fluid name
// (250 bytes, NUL-padded), int16 version, float scene scale, int32 fluid type, float elapsed
// time, int32 frame, int32 frames per second, int32 particle count, float radius, float[3]
// pressure (max min average), float[3] speed, float[3] temperature, and from version 7 the
// emitter position, rotation and scale (float[3] each).
//
// One record a particle: position, velocity, force (float[3] each), vorticity (float[3], from
// version 9), normal (float[3], from 3), neighbour count (int32, from 4), texture coordinates
// (float[3], from 5), info bits (int16, from 5), age, isolation time, viscosity, density,
// pressure, mass, temperature (float each), id (int32; int64 from version 12).
//
// A trailing section follows the particles (checked from version 9 on): int32 count of
// additional per-particle data, a byte flag "RF4 internal data", from version 10 a byte flag "RF5
// internal data", and when that is set an int32. Writers differ (Krakatoa writes 5 zero bytes,
// others 6, RealFlow itself 10), so it is checked as far as it is understood and taken on trust
// beyond (additional data, internal data that is not empty).
//
// The records are read in chunks, about 1 MiB of records at a time (readRecordBatches), decoded
// while they are in cache (memory: the chunk and that batch); the trailing section is checked
// once the last particle has been read.
#include <algorithm>
#include <bit>
#include <cstring>

#include "core/Error.h"
#include "preprocess/particles/BinaryColumns.h"
#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleFormats.h"

namespace flipscope::detail {
namespace {

static_assert(std::endian::native == std::endian::little, "fields are read as stored, little-endian");

constexpr std::uint32_t kMagic = 0x00FABADA;
constexpr std::size_t kNameBytes = 250;
constexpr int kMaxVersion = 12;

struct RealFlowField {
  const char* name;
  ValueType type;
  int arity;
  int since;  ///< first version with the field
};

// The record, in order; fields of later versions are absent from earlier files.
constexpr RealFlowField kFields[] = {
    {"position", ValueType::Float32, 3, 1},    {"velocity", ValueType::Float32, 3, 1},
    {"force", ValueType::Float32, 3, 1},       {"vorticity", ValueType::Float32, 3, 9},
    {"normal", ValueType::Float32, 3, 3},      {"neighbors", ValueType::Int32, 1, 4},
    {"texture", ValueType::Float32, 3, 5},     {"info", ValueType::Int16, 1, 5},
    {"age", ValueType::Float32, 1, 1},         {"isolation_time", ValueType::Float32, 1, 1},
    {"viscosity", ValueType::Float32, 1, 1},   {"density", ValueType::Float32, 1, 1},
    {"pressure", ValueType::Float32, 1, 1},    {"mass", ValueType::Float32, 1, 1},
    {"temperature", ValueType::Float32, 1, 1},
};

struct Column {
  ValueType type;
  int arity;
  std::size_t offset;
};

class RealFlowReader final : public ParticleSource {
 public:
  RealFlowReader(InputFile file, const ReadOptions& options) : mFile(std::move(file)) {
    const auto magic = field<std::uint32_t>("the magic number");
    if (magic != kMagic) throw FileError(mFile.path(), "bad magic: not a RealFlow particle .bin (expected 0xFABADA)");
    char name[kNameBytes];
    mFile.readExact(name, kNameBytes, "the fluid name");
    mFluidName.assign(name, strnlen(name, kNameBytes));
    mVersion = field<std::int16_t>("the version");
    if (mVersion < 1 || mVersion > kMaxVersion)
      throw fail("version " + std::to_string(mVersion) + " at byte 254 (this reader reads versions 1 to " +
                 std::to_string(kMaxVersion) + ")");
    mFile.seek(276);
    const auto count = field<std::int32_t>("the particle count");
    if (count < 0) throw fail("negative particle count " + std::to_string(count) + " at byte 276");
    mCount = std::uint64_t(count);
    mDataOffset = mVersion >= 7 ? 356 : 320;
    if (mFile.size() < mDataOffset)
      throw fail("truncated: the file ends inside the header (" + std::to_string(mFile.size()) + " of " +
                 std::to_string(mDataOffset) + " bytes)");

    std::size_t offset = 0;
    for (const RealFlowField& f : kFields) {
      if (mVersion < f.since) continue;
      const Column column{f.type, f.arity, offset};
      offset += valueTypeBytes(f.type) * std::size_t(f.arity);
      if (std::strcmp(f.name, "position") == 0) {
        mPosition = column;
        continue;
      }
      if (std::strcmp(f.name, "velocity") == 0) mVelocity = column;
      mExposed.push_back({f.name, f.type, f.arity});
      mSources.push_back(column);
    }
    const ValueType idType = mVersion >= 12 ? ValueType::Int64 : ValueType::Int32;
    mExposed.push_back({"id", idType, 1});
    mSources.push_back({idType, 1, offset});
    mStride = offset + valueTypeBytes(idType);

    const std::uint64_t available = (mFile.size() - mDataOffset) / mStride;
    if (available < mCount)
      throw fail("truncated: the file ends at particle " + std::to_string(available) + " of " + std::to_string(mCount) +
                 " (particles start at byte " + std::to_string(mDataOffset) + ", " + std::to_string(mStride) +
                 " bytes a particle, file size " + std::to_string(mFile.size()) + ")");
    mSelected = selectAttributes(mExposed, options, mFile.path());
    mColumns = makeColumns(mExposed, mSelected);
    mHasVelocity = options.velocity;
    rewind();
  }

  std::string name() const override { return mFile.path().string(); }
  std::string format() const override {
    return "RealFlow particle .bin version " + std::to_string(mVersion) + " (fluid '" + mFluidName + "')";
  }
  /// RealFlow's world is +y up.
  UpAxis upAxis() const override { return UpAxis::Y; }
  std::vector<AttributeDesc> attributes() const override { return mExposed; }
  bool hasVelocity() const override { return mHasVelocity; }
  std::optional<std::uint64_t> countHint() const override { return mCount; }

  bool read(ParticleChunk& chunk, std::size_t maxParticles) override {
    FLIPSCOPE_CHECK(maxParticles > 0);
    chunk.clear();
    const std::size_t n = std::size_t(std::min<std::uint64_t>(maxParticles, mCount - mNext));
    prepareColumns(chunk, mColumns, n);
    if (n == 0) {
      if (!mTailChecked) checkTail();  // an empty frame
      return false;
    }
    chunk.positions.resize(n);
    if (mHasVelocity) chunk.velocities.resize(n);
    readRecordBatches(
        mFile, mStride, n, mBuffer,
        [&](const std::byte* records, std::size_t count, std::size_t begin) {
          decodeVec3Column(mPosition.type, ByteOrder::Little, records + mPosition.offset, mStride, count,
                           chunk.positions.data() + begin);
          if (mHasVelocity)
            decodeVec3Column(mVelocity.type, ByteOrder::Little, records + mVelocity.offset, mStride, count,
                             chunk.velocities.data() + begin);
          for (std::size_t k = 0; k < mSelected.size(); ++k) {
            const Column& c = mSources[mSelected[k]];
            decodeColumn(c.type, ByteOrder::Little, records + c.offset, mStride, c.arity, count,
                         chunk.attributes[k].values.data() + begin * std::size_t(c.arity));
          }
        },
        [&](std::size_t inside) {
          return fail("the file ends inside particle " + std::to_string(mNext + inside) + " of " +
                      std::to_string(mCount) + " (was it truncated while being read?)");
        });
    mNext += n;
    if (mNext == mCount && !mTailChecked) checkTail();
    return true;
  }

  void rewind() override {
    mFile.seek(mDataOffset);
    mNext = 0;
  }

 private:
  FileError fail(const std::string& what) const { return FileError(mFile.path(), "RealFlow .bin: " + what); }

  template <class T>
  T field(const char* what) {
    T value;
    mFile.readExact(&value, sizeof value, what);
    return value;
  }

  /// The section after the particles (see the file comment); the file is at its start.
  void checkTail() {
    mTailChecked = true;
    const std::uint64_t start = mDataOffset + mCount * mStride;
    mFile.seek(start);
    if (mVersion < 9) return;  // what older versions put after the particles is not known here
    const auto additional = field<std::int32_t>("the trailing section's additional data count");
    if (additional < 0)
      throw fail("negative count " + std::to_string(additional) + " of additional particle data at byte " +
                 std::to_string(start));
    if (additional > 0) return;  // per-particle additional data: taken on trust
    auto flag = [&](const char* what) {
      const std::uint64_t at = mFile.offset();
      const auto value = field<std::uint8_t>(what);
      if (value > 1)
        throw fail(std::string(what) + " at byte " + std::to_string(at) + " is " + std::to_string(value) +
                   ", expected 0 or 1");
      return value == 1;
    };
    if (flag("the RF4 internal data flag")) return;  // internal data: taken on trust
    if (mFile.offset() == mFile.size() && mVersion < 10) return;
    if (flag("the RF5 internal data flag")) {
      const auto internal = field<std::int32_t>("the RF5 internal data");
      if (internal != 0) return;  // internal data: taken on trust
    }
    if (mFile.offset() != mFile.size())
      throw fail(std::to_string(mFile.size() - mFile.offset()) + " bytes of trailing garbage after the trailing " +
                 "section, which ends at byte " + std::to_string(mFile.offset()));
  }

  InputFile mFile;
  std::string mFluidName;
  int mVersion = 0;
  std::uint64_t mCount = 0;
  std::uint64_t mDataOffset = 0;
  std::size_t mStride = 0;
  Column mPosition{}, mVelocity{};
  std::vector<AttributeDesc> mExposed;
  std::vector<Column> mSources;  ///< one per exposed attribute
  std::vector<std::size_t> mSelected;
  std::vector<AttributeColumn> mColumns;
  bool mHasVelocity = false;
  std::uint64_t mNext = 0;
  bool mTailChecked = false;
  std::vector<std::byte> mBuffer;
};

}  // namespace

bool isRealFlowBin(std::span<const std::byte> head) {
  if (head.size() < 4) return false;
  std::uint32_t magic;
  std::memcpy(&magic, head.data(), 4);
  return magic == kMagic;
}

std::unique_ptr<ParticleSource> openRealFlowParticles(InputFile file, const ReadOptions& options) {
  return std::make_unique<RealFlowReader>(std::move(file), options);
}

}  // namespace flipscope::detail
