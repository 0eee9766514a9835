// Maya particle disk cache (.pdb): the layout of Maya's Gifts/readpdb structures, which partio
// also reads and writes. Little-endian. The file is those C structs as written, so its pointer
// fields are 4 or 8 bytes wide as the writing build's were; nothing in the file says which. The
// layout is the one under which the channels end exactly at the file's last byte (32-bit first:
// partio writes it).
//
// Header (60 or 64 bytes): int32 magic 670, uint16 swap, 2 bytes of alignment, float version,
// float time, uint32 particle count, uint32 channel count, 32 bytes of padding, a pointer.
// Then each channel:
//   an I/O header (6 bytes: char magic, 1 byte of alignment, uint16 swap, char encoding,
//   char type);
//   the channel (36 or 56 bytes: pointer name, int32 type, uint32 size, uint32 active start and
//   end, char hide, char disconnect, alignment, pointers data, link, next);
//   its name, NUL-terminated;
//   its data header (20 or 24 bytes: int32 type, uint32 bytes a particle, uint32 block size,
//   int32 block count, a pointer);
//   then its values, particle after particle.
// Channel types: 1 vector (3 float32), 2 real (float32s), 3 long (int32s), 4 char (bytes),
// 5 pointer (not exposed: the values are addresses).
//
// The positions are the vector channel "position"; the velocity is the vector channel named as
// velocityAttributeByName() prefers ("velocity" in Maya, "v" as partio names it). Values are
// read a channel at a time, 1 MiB at most at once.
#include <algorithm>
#include <bit>
#include <cstdio>
#include <cstring>

#include "core/Error.h"
#include "preprocess/particles/BinaryColumns.h"
#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleFormats.h"

namespace flipscope::detail {
namespace {

static_assert(std::endian::native == std::endian::little, "fields are read as stored, little-endian");

constexpr std::int32_t kMagic = 670;
constexpr std::size_t kIoHeaderBytes = 6;
constexpr std::size_t kMaxNameBytes = 1024;  ///< a longer name is damage
/// A particle's values in one channel, at most (a larger count is damage): 256 K reals.
constexpr std::uint32_t kMaxParticleBytes = std::uint32_t(1) << 20;

/// The struct sizes of one pointer width.
struct PdbLayout {
  const char* name;
  std::size_t pointerBytes;
  std::size_t headerBytes;
  std::size_t channelBytes;
  std::size_t dataHeaderBytes;
};
constexpr PdbLayout kLayouts[] = {{"32-bit", 4, 60, 36, 20}, {"64-bit", 8, 64, 56, 24}};

enum PdbType : std::int32_t { kVector = 1, kReal = 2, kLong = 3, kChar = 4, kPointer = 5 };

struct PdbChannel {
  std::string name;
  std::int32_t type = 0;
  std::uint32_t particleBytes = 0;  ///< bytes of values a particle
  std::uint64_t offset = 0;         ///< of the first particle's values
  AttributeDesc desc;               ///< its values' type and arity (pointers: not exposed, never read)
};

struct PdbContents {
  const PdbLayout* layout = nullptr;
  float version = 0;
  float time = 0;
  std::uint64_t count = 0;
  std::vector<PdbChannel> channels;
};

std::string typeName(std::int32_t type) {
  switch (type) {
    case kVector: return "vector";
    case kReal: return "real";
    case kLong: return "long";
    case kChar: return "char";
    case kPointer: return "pointer";
  }
  return "type " + std::to_string(type);
}

/// Whether `bytes` a particle hold whole values of channel type `type` (any for pointers).
bool fitsType(std::int32_t type, std::uint32_t bytes) {
  switch (type) {
    case kVector:
      return bytes == 12;
    case kReal:
    case kLong:
      return bytes > 0 && bytes % 4 == 0;
    case kChar:
      return bytes > 0;
    case kPointer:
      return true;
  }
  return false;
}

/// The channels of `file` under `layout`, or what is wrong with them under it (`error`).
std::optional<PdbContents> walkChannels(InputFile& file, const PdbLayout& layout, std::string& error) {
  const std::uint64_t size = file.size();
  auto readAt = [&](std::uint64_t at, void* out, std::size_t bytes) {
    return at + bytes <= size && file.readAt(at, out, bytes) == bytes;
  };
  auto number = [&](std::uint64_t at, auto value) {
    readAt(at, &value, sizeof value);
    return value;
  };
  PdbContents pdb;
  pdb.layout = &layout;
  if (size < layout.headerBytes) {
    error = "the file ends inside the " + std::to_string(layout.headerBytes) + "-byte header";
    return std::nullopt;
  }
  pdb.version = number(8, 0.0f);
  pdb.time = number(12, 0.0f);
  pdb.count = number(16, std::uint32_t(0));
  const std::uint32_t channels = number(20, std::uint32_t(0));
  // Each channel takes at least its headers and a name's NUL.
  const std::uint64_t leastChannelBytes = kIoHeaderBytes + layout.channelBytes + 1 + layout.dataHeaderBytes;
  if (channels > (size - layout.headerBytes) / leastChannelBytes) {
    error = "the header's " + std::to_string(channels) + " channels cannot fit the file's " + std::to_string(size) +
            " bytes";
    return std::nullopt;
  }
  std::uint64_t at = layout.headerBytes;
  for (std::uint32_t i = 0; i < channels; ++i) {
    const std::string which = "channel " + std::to_string(i);
    PdbChannel channel;
    const std::uint64_t channelAt = at + kIoHeaderBytes;
    if (channelAt + layout.channelBytes > size) {
      error = "the file ends inside " + which + "'s header (byte " + std::to_string(at) + ")";
      return std::nullopt;
    }
    channel.type = number(channelAt + layout.pointerBytes, std::int32_t(0));
    const std::uint64_t nameAt = channelAt + layout.channelBytes;
    char name[kMaxNameBytes] = {};
    const std::size_t available = std::size_t(std::min<std::uint64_t>(kMaxNameBytes, size - nameAt));
    readAt(nameAt, name, available);
    const std::size_t length = strnlen(name, available);
    if (length == available) {
      error = "the name of " + which + " at byte " + std::to_string(nameAt) + " has no end within " +
              std::to_string(available) + " bytes";
      return std::nullopt;
    }
    channel.name.assign(name, length);
    const std::string named = which + " ('" + channel.name + "', " + typeName(channel.type) + ")";
    const std::uint64_t dataAt = nameAt + length + 1;
    if (dataAt + layout.dataHeaderBytes > size) {
      error = "the file ends inside the data header of " + named;
      return std::nullopt;
    }
    channel.particleBytes = number(dataAt + 4, std::uint32_t(0));
    const std::uint32_t n = channel.particleBytes;
    const bool sized = n <= kMaxParticleBytes && fitsType(channel.type, n);
    if (!sized) {
      error = named + " at byte " + std::to_string(at) + ": " +
              (channel.type < kVector || channel.type > kPointer
                   ? std::string("not a channel type (1 vector, 2 real, 3 long, 4 char, 5 pointer)")
                   : std::to_string(n) + " bytes a particle do not fit its type" +
                         (n > kMaxParticleBytes ? " (at most 1 MiB)" : ""));
      return std::nullopt;
    }
    channel.offset = dataAt + layout.dataHeaderBytes;
    const std::uint64_t bytes = pdb.count * n;  // < 2^64: both are 32-bit
    if (bytes > size - channel.offset) {
      error = named + ": " + std::to_string(pdb.count) + " particles of " + std::to_string(n) + " bytes from byte " +
              std::to_string(channel.offset) + " go beyond the end of the file (" + std::to_string(size) + " bytes)";
      return std::nullopt;
    }
    at = channel.offset + bytes;
    switch (channel.type) {
      case kVector: channel.desc = {channel.name, ValueType::Float32, 3}; break;
      case kReal: channel.desc = {channel.name, ValueType::Float32, int(n / 4)}; break;
      case kLong: channel.desc = {channel.name, ValueType::Int32, int(n / 4)}; break;
      case kChar: channel.desc = {channel.name, ValueType::Int8, int(n)}; break;
      default: break;
    }
    pdb.channels.push_back(std::move(channel));
  }
  if (at != size) {
    error = std::to_string(size - at) + " bytes follow the last channel, which ends at byte " + std::to_string(at);
    return std::nullopt;
  }
  return pdb;
}

class PdbReader final : public ParticleSource {
 public:
  PdbReader(InputFile file, const ReadOptions& options) : mFile(std::move(file)) {
    std::int32_t magic = 0;
    if (mFile.readAt(0, &magic, 4) != 4 || magic != kMagic)
      throw fail(std::int32_t(__builtin_bswap32(std::uint32_t(magic))) == kMagic ? "a big-endian file (from an IRIX or PowerPC Maya), which is not read"
                                                : "bad magic: not a Maya .pdb (expected 670)");
    std::string errors;
    for (const PdbLayout& layout : kLayouts) {
      std::string error;
      if (auto pdb = walkChannels(mFile, layout, error)) {
        mPdb = std::move(*pdb);
        break;
      }
      errors += std::string(errors.empty() ? "" : "; ") + layout.name + " layout: " + error;
    }
    if (!mPdb.layout) throw fail("damaged, in either pointer width (" + errors + ")");
    std::optional<std::size_t> position;
    for (std::size_t i = 0; i < mPdb.channels.size(); ++i) {
      const PdbChannel& c = mPdb.channels[i];
      if (c.name == "position" && c.type == kVector && !position) {
        position = i;
      } else if (c.type != kPointer) {
        mExposed.push_back(c.desc);
        mSources.push_back(i);
      }
    }
    if (!position) {
      std::string list;
      for (const PdbChannel& c : mPdb.channels) list += (list.empty() ? "" : ", ") + c.name + " (" + typeName(c.type) + ")";
      throw fail("no vector channel 'position' (channels: " + (list.empty() ? "none" : list) + ")");
    }
    mSelected = selectAttributes(mExposed, options, mFile.path());
    std::optional<std::size_t> velocity;
    if (options.velocity) velocity = velocityAttributeByName(mExposed);
    mStreams.push_back(*position);
    if (velocity) mVelocityStream = addStream(mSources[*velocity]);
    mHasVelocity = velocity.has_value();
    for (std::size_t index : mSelected) mColumnStreams.push_back(addStream(mSources[index]));
  }

  std::string name() const override { return mFile.path().string(); }
  std::string format() const override {
    char version[32];
    std::snprintf(version, sizeof version, "%g", double(mPdb.version));
    return std::string("Maya particle disk cache (.pdb) version ") + version + ", " + mPdb.layout->name + " layout";
  }
  /// Maya's world is +y up.
  UpAxis upAxis() const override { return UpAxis::Y; }
  std::vector<AttributeDesc> attributes() const override { return mExposed; }
  bool hasVelocity() const override { return mHasVelocity; }
  std::optional<std::uint64_t> countHint() const override { return mPdb.count; }

  bool read(ParticleChunk& chunk, std::size_t maxParticles) override {
    FLIPSCOPE_CHECK(maxParticles > 0);
    const std::uint64_t n = std::min<std::uint64_t>(maxParticles, mPdb.count - mNext);
    if (n == 0) {
      chunk.clear();
      chunk.attributes.clear();
      return false;
    }
    const FloatStreams streams{mStreams.size(), mHasVelocity, mVelocityStream, mColumnStreams};
    fillFromFloatStreams(
        chunk, std::size_t(n), streams, mExposed, mSelected,
        [&](std::size_t stream) { return mPdb.channels[mStreams[stream]].desc.arity; },
        [&](std::size_t stream, std::size_t count, float* out) {
          readChannel(mPdb.channels[mStreams[stream]], count, out);
        });
    mNext += n;
    return true;
  }

  void rewind() override { mNext = 0; }

 private:
  FileError fail(const std::string& what) const { return FileError(mFile.path(), "Maya .pdb: " + what); }

  /// The stream of channel `channel`, shared by every use of it.
  std::size_t addStream(std::size_t channel) {
    for (std::size_t i = 1; i < mStreams.size(); ++i)
      if (mStreams[i] == channel) return i;
    mStreams.push_back(channel);
    return mStreams.size() - 1;
  }

  /// The values of particles [mNext, mNext + count) of `c` into `out`.
  void readChannel(const PdbChannel& c, std::size_t count, float* out) {
    const int arity = c.desc.arity;
    const std::size_t perPiece = std::max<std::size_t>(1, kRecordBatchBytes / c.particleBytes);
    for (std::size_t done = 0; done < count;) {
      const std::size_t particles = std::min(perPiece, count - done);
      const std::uint64_t at = c.offset + (mNext + done) * c.particleBytes;
      mBytes.resize(particles * c.particleBytes);
      if (mFile.readAt(at, mBytes.data(), mBytes.size()) != mBytes.size())
        throw fail("the file ends inside channel '" + c.name + "' (byte " + std::to_string(at + mBytes.size()) +
                   "; it shrank since it was opened?)");
      decodeColumn(c.desc.type, ByteOrder::Little, mBytes.data(), c.particleBytes, arity, particles,
                   out + done * std::size_t(arity));
      done += particles;
    }
  }

  InputFile mFile;
  PdbContents mPdb;
  std::vector<AttributeDesc> mExposed;
  std::vector<std::size_t> mSources;  ///< the channel of each exposed attribute
  std::vector<std::size_t> mSelected;
  bool mHasVelocity = false;
  std::vector<std::size_t> mStreams;  ///< channels read: [0] the positions
  std::size_t mVelocityStream = 0;
  std::vector<std::size_t> mColumnStreams;
  std::uint64_t mNext = 0;
  std::vector<std::byte> mBytes;
};

}  // namespace

bool isPdb(std::span<const std::byte> head) {
  if (head.size() < 8) return false;
  std::int32_t magic;
  std::uint16_t swap;
  std::memcpy(&magic, head.data(), 4);
  std::memcpy(&swap, head.data() + 4, 2);
  return magic == kMagic && swap <= 1;
}

std::unique_ptr<ParticleSource> openPdbParticles(InputFile file, const ReadOptions& options) {
  return std::make_unique<PdbReader>(std::move(file), options);
}

}  // namespace flipscope::detail
