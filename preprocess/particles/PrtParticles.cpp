// Krakatoa PRT particle files, versions 1.0 and 1.1 (Thinkbox, "PRT File Format v1.1";
// little-endian throughout). The header: the magic c0 'P' 'R' 'T' \r \n 1a \n, the header
// length, the signature "Extensible Particle Format" (32 bytes), the header version (1, or 2 for
// PRT 1.1), the particle count (int64; -1 when the writer never came back to fill it in). PRT 1.1
// adds metadata chunks ("Meta" and a length, ..., "Stop") up to the header length. Then a
// reserved int32 (4), the channel count, the size of a channel definition (44), and the
// channels: name[32], type (0 int16, 1 int32, 2 int64, 3 float16, 4 float32, 5 float64, 6
// uint16, 7 uint32, 8 uint64, 9 int8, 10 uint8), arity, byte offset in a particle. The
// particles follow as one zlib stream (RFC 1950, not gzip) of packed records.
//
// The stream is inflated a batch of records at a time (1 MiB, decoded while it is in cache) into
// the chunk (memory: the chunk, the batch and 256 KiB of input). "Position" (3 floats of any
// width) gives the positions, "Velocity" (3 values) the velocities; every channel but Position
// is an attribute. A count of -1 is read as "until the stream ends" (countHint() is then
// unknown); a known count must match the stream exactly.
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <new>

#include "core/Error.h"
#include "preprocess/particles/BinaryColumns.h"
#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleFormats.h"

namespace flipscope::detail {
namespace {

static_assert(std::endian::native == std::endian::little, "fields are read as stored, little-endian");

constexpr unsigned char kMagic[8] = {0xc0, 'P', 'R', 'T', '\r', '\n', 0x1a, '\n'};
constexpr char kSignature[] = "Extensible Particle Format";
constexpr std::uint64_t kBaseHeaderBytes = 56;
constexpr std::uint64_t kChannelBytes = 44;
constexpr std::int32_t kMaxChannels = 1 << 16;
constexpr std::size_t kMaxRecordBytes = std::size_t(1) << 24;
constexpr std::size_t kInputBytes = 256 * 1024;

constexpr ValueType kPrtTypes[] = {ValueType::Int16,   ValueType::Int32,   ValueType::Int64,  ValueType::Float16,
                                   ValueType::Float32, ValueType::Float64, ValueType::UInt16, ValueType::UInt32,
                                   ValueType::UInt64,  ValueType::Int8,    ValueType::UInt8};

bool isFloatType(ValueType type) {
  return type == ValueType::Float16 || type == ValueType::Float32 || type == ValueType::Float64;
}

struct PrtChannel {
  std::string name;
  ValueType type = ValueType::Float32;
  int arity = 1;
  std::size_t offset = 0;
  std::size_t bytes() const { return valueTypeBytes(type) * std::size_t(arity); }
};

/// A zlib inflater (RFC 1950 stream) that ends itself.
struct Inflater {
  z_stream stream;
  Inflater() {
    std::memset(&stream, 0, sizeof stream);
    if (inflateInit(&stream) != Z_OK) throw std::bad_alloc();
  }
  ~Inflater() { inflateEnd(&stream); }
  Inflater(const Inflater&) = delete;
  Inflater& operator=(const Inflater&) = delete;
};

class PrtReader final : public ParticleSource {
 public:
  PrtReader(InputFile file, const ReadOptions& options) : mFile(std::move(file)), mInput(kInputBytes) {
    readHeader();
    for (std::size_t i = 0; i < mChannels.size(); ++i) {
      const PrtChannel& c = mChannels[i];
      if (c.name == "Position") {
        if (c.arity != 3 || !isFloatType(c.type))
          throw fail("the Position channel is " + std::string(valueTypeName(c.type)) + "[" + std::to_string(c.arity) +
                     "], expected 3 floats (float16, float32 or float64)");
        mPosition = i;
        continue;
      }
      if (c.name == "Velocity" && c.arity == 3 && !mVelocity) mVelocity = i;
      mExposed.push_back({c.name, c.type, c.arity});
      mExposedSource.push_back(i);
    }
    if (!mPosition) throw fail("has no Position channel (channels: " + channelList() + ")");
    mSelected = selectAttributes(mExposed, options, mFile.path());
    mColumns = makeColumns(mExposed, mSelected);
    mHasVelocity = options.velocity && mVelocity.has_value();
    rewind();
  }
  std::string name() const override { return mFile.path().string(); }
  std::string format() const override {
    return "Krakatoa PRT " + std::string(mVersion == 1 ? "1.0" : "1.1") + " (header version " +
           std::to_string(mVersion) + ")";
  }
  std::vector<AttributeDesc> attributes() const override { return mExposed; }
  bool hasVelocity() const override { return mHasVelocity; }
  std::optional<std::uint64_t> countHint() const override {
    return mCount < 0 ? std::nullopt : std::optional<std::uint64_t>(std::uint64_t(mCount));
  }

  bool read(ParticleChunk& chunk, std::size_t maxParticles) override {
    FLIPSCOPE_CHECK(maxParticles > 0);
    chunk.clear();
    prepareColumns(chunk, mColumns, 0);
    std::size_t n = maxParticles;
    if (mCount >= 0) n = std::size_t(std::min<std::uint64_t>(n, std::uint64_t(mCount) - mNext));
    const std::size_t batch = std::max<std::size_t>(1, kRecordBatchBytes / mStride);
    std::size_t done = 0;
    while (done < n && !mEnded) {
      const std::size_t count = std::min(batch, n - done);
      mBuffer.resize(count * mStride);
      const std::size_t got = inflateRecords(mBuffer.data(), mBuffer.size());
      const std::size_t records = got / mStride;
      if (got % mStride != 0)
        throw fail("the particle data ends inside particle " + std::to_string(mNext + done + records) + " (" +
                   std::to_string(got % mStride) + " of its " + std::to_string(mStride) + " bytes)");
      if (records < count && mCount >= 0)
        throw fail("the particle data ends after " + std::to_string(mNext + done + records) + " of the " +
                   std::to_string(mCount) + " particles the header declares");
      decode(records, done, chunk);
      done += records;
    }
    mNext += done;
    if (mCount >= 0 && mNext == std::uint64_t(mCount) && !mEnded) expectStreamEnd();
    chunk.positions.resize(done);
    if (mHasVelocity) chunk.velocities.resize(done);
    for (auto& column : chunk.attributes) column.values.resize(done * std::size_t(column.arity));
    return done > 0;
  }

  void rewind() override {
    if (inflateReset(&mStream) != Z_OK) throw fail("cannot restart the zlib decoder");
    mStream.avail_in = 0;
    mStream.next_in = nullptr;
    mInputOffset = mDataOffset;
    mInputFill = 0;
    mEnded = false;
    mNext = 0;
  }

 private:
  FileError fail(const std::string& what) const { return FileError(mFile.path(), "PRT: " + what); }

  std::string channelList() const {
    std::string list;
    for (const auto& c : mChannels)
      list += (list.empty() ? "" : ", ") + c.name + " " + std::string(valueTypeName(c.type)) + "[" +
              std::to_string(c.arity) + "]";
    return list.empty() ? "none" : list;
  }

  template <class T>
  T field(const char* what) {
    T value;
    mFile.readExact(&value, sizeof value, what);
    return value;
  }

  void readHeader() {
    unsigned char magic[8] = {};
    if (mFile.read(magic, 8) != 8 || std::memcmp(magic, kMagic, 8) != 0)
      throw FileError(mFile.path(), "bad magic: not a Krakatoa PRT file (expected c0 50 52 54 0d 0a 1a 0a)");
    const auto headerLength = field<std::int32_t>("the header length");
    char signature[32];
    mFile.readExact(signature, 32, "the signature");
    if (std::strncmp(signature, kSignature, 32) != 0)
      throw fail("bad signature at byte 12: expected '" + std::string(kSignature) + "', found '" +
                 std::string(signature, strnlen(signature, 32)) + "'");
    mVersion = field<std::int32_t>("the version");
    if (mVersion != 1 && mVersion != 2)
      throw fail("header version " + std::to_string(mVersion) + " (this reader reads 1 and 2: PRT 1.0 and 1.1)");
    mCount = field<std::int64_t>("the particle count");
    if (mCount < -1) throw fail("negative particle count " + std::to_string(mCount) + " at byte 48");
    if (headerLength < std::int32_t(kBaseHeaderBytes) || std::uint64_t(headerLength) > mFile.size())
      throw fail("header length " + std::to_string(headerLength) + " at byte 8 is not between " +
                 std::to_string(kBaseHeaderBytes) + " and the file size " + std::to_string(mFile.size()));
    if (mVersion == 2) readChunks(std::uint64_t(headerLength));
    mFile.seek(std::uint64_t(headerLength));
    (void)field<std::int32_t>("the reserved field");
    const std::uint64_t countAt = mFile.offset();
    const auto channels = field<std::int32_t>("the channel count");
    const auto definitionBytes = field<std::int32_t>("the channel definition size");
    if (channels < 1 || channels > kMaxChannels)
      throw fail("channel count " + std::to_string(channels) + " at byte " + std::to_string(countAt) +
                 " (expected 1 to " + std::to_string(kMaxChannels) + ")");
    if (definitionBytes < std::int32_t(kChannelBytes) || definitionBytes > 4096)
      throw fail("channel definition size " + std::to_string(definitionBytes) + " at byte " +
                 std::to_string(countAt + 4) + " (expected " + std::to_string(kChannelBytes) + ")");
    if (std::uint64_t(channels) * std::uint64_t(definitionBytes) > mFile.size() - mFile.offset())
      throw fail("truncated: " + std::to_string(channels) + " channel definitions of " +
                 std::to_string(definitionBytes) + " bytes do not fit in the " +
                 std::to_string(mFile.size() - mFile.offset()) + " bytes left at byte " +
                 std::to_string(mFile.offset()));
    for (std::int32_t i = 0; i < channels; ++i) readChannel(i, std::uint64_t(definitionBytes));
    checkLayout();
    mDataOffset = mFile.offset();
  }

  /// PRT 1.1 metadata chunks from byte 56 to the header length; each is skipped.
  void readChunks(std::uint64_t headerLength) {
    std::uint64_t at = kBaseHeaderBytes;
    for (;;) {
      if (at + 8 > headerLength)
        throw fail("no 'Stop' chunk before the end of the header at byte " + std::to_string(headerLength) +
                   " (metadata chunk expected at byte " + std::to_string(at) + ")");
      char tag[4];
      mFile.seek(at);
      mFile.readExact(tag, 4, "a metadata chunk name");
      const auto length = field<std::int32_t>("a metadata chunk length");
      const std::string name = std::string(tag, 4);
      if (length < 0 || at + 8 + std::uint64_t(length) > headerLength)
        throw fail("metadata chunk '" + name + "' at byte " + std::to_string(at) + " has length " +
                   std::to_string(length) + ", which does not fit in the header (length " +
                   std::to_string(headerLength) + ")");
      at += 8 + std::uint64_t(length);
      if (name == "Stop") {
        if (at != headerLength)
          throw fail("the 'Stop' chunk ends at byte " + std::to_string(at) + ", but the header length is " +
                     std::to_string(headerLength));
        return;
      }
    }
  }

  void readChannel(std::int32_t index, std::uint64_t definitionBytes) {
    const std::uint64_t at = mFile.offset();
    char name[32];
    mFile.readExact(name, 32, "a channel name");
    const auto type = field<std::int32_t>("a channel type");
    const auto arity = field<std::int32_t>("a channel arity");
    const auto offset = field<std::int32_t>("a channel offset");
    mFile.seek(at + definitionBytes);
    const std::size_t length = strnlen(name, 32);
    const std::string where = "channel " + std::to_string(index) + " (definition at byte " + std::to_string(at) + ")";
    if (length == 0 || length == 32) throw fail(where + " has " + (length ? "an unterminated" : "an empty") + " name");
    PrtChannel c;
    c.name.assign(name, length);
    if (type < 0 || type >= std::int32_t(std::size(kPrtTypes)))
      throw fail(where + " '" + c.name + "' has unknown data type " + std::to_string(type) + " (expected 0 to 10)");
    c.type = kPrtTypes[type];
    if (arity < 1 || std::size_t(arity) * valueTypeBytes(c.type) > kMaxRecordBytes)
      throw fail(where + " '" + c.name + "' has arity " + std::to_string(arity));
    c.arity = arity;
    if (offset < 0) throw fail(where + " '" + c.name + "' has negative offset " + std::to_string(offset));
    c.offset = std::size_t(offset);
    for (const auto& other : mChannels)
      if (other.name == c.name) throw fail(where + ": a second channel named '" + c.name + "'");
    mChannels.push_back(std::move(c));
  }

  /// The channels tile the particle record: its size is their total, none overlaps another.
  void checkLayout() {
    mStride = 0;
    for (const auto& c : mChannels) mStride += c.bytes();
    if (mStride > kMaxRecordBytes) throw fail("particle records of " + std::to_string(mStride) + " bytes");
    std::vector<const PrtChannel*> sorted;
    for (const auto& c : mChannels) sorted.push_back(&c);
    std::sort(sorted.begin(), sorted.end(), [](auto* a, auto* b) { return a->offset < b->offset; });
    std::size_t end = 0;
    for (const PrtChannel* c : sorted) {
      if (c->offset < end || c->offset + c->bytes() > mStride)
        throw fail("channel '" + c->name + "' (bytes " + std::to_string(c->offset) + " to " +
                   std::to_string(c->offset + c->bytes()) + ") overlaps another or lies outside the " +
                   std::to_string(mStride) + "-byte particle (channels: " + channelList() + ")");
      end = c->offset + c->bytes();
    }
  }

  /// Inflates up to `bytes` bytes of records into `out`; fewer only at the end of the stream.
  std::size_t inflateRecords(std::byte* out, std::size_t bytes) {
    std::size_t done = 0;
    while (done < bytes && !mEnded) {
      const std::size_t want = std::min<std::size_t>(bytes - done, std::numeric_limits<uInt>::max());
      mStream.next_out = reinterpret_cast<Bytef*>(out + done);
      mStream.avail_out = uInt(want);
      while (mStream.avail_out > 0 && !mEnded) {
        if (mStream.avail_in == 0) refill();
        const int status = inflate(&mStream, Z_NO_FLUSH);
        if (status == Z_STREAM_END)
          streamEnded();
        else if (status != Z_OK)
          throw fail("damaged zlib particle data near byte " + std::to_string(compressedOffset()) +
                     " (zlib: " + (mStream.msg ? std::string(mStream.msg) : "error " + std::to_string(status)) + ")");
      }
      done += want - mStream.avail_out;
    }
    return done;
  }

  void refill() {
    mInputOffset += mInputFill;
    mInputFill = mFile.readAt(mInputOffset, mInput.data(), mInput.size());
    if (mInputFill == 0)
      throw fail("truncated: the file ends at byte " + std::to_string(mInputOffset) +
                 " inside the zlib particle data (which starts at byte " + std::to_string(mDataOffset) + ", " +
                 std::to_string(mNext) + " particles read before this chunk)");
    mStream.next_in = mInput.data();
    mStream.avail_in = uInt(mInputFill);
  }

  std::uint64_t compressedOffset() const { return mInputOffset + (mInputFill - mStream.avail_in); }

  /// After the declared count: the zlib stream must end here.
  void expectStreamEnd() {
    std::byte extra[16];
    if (inflateRecords(extra, sizeof extra) > 0)
      throw fail("the particle data holds more than the " + std::to_string(mCount) + " particles the header declares");
  }

  /// The zlib stream (its checksum verified) ends the file.
  void streamEnded() {
    mEnded = true;
    const std::uint64_t end = compressedOffset();
    if (end != mFile.size())
      throw fail(std::to_string(mFile.size() - end) + " bytes of trailing garbage after the zlib particle data, " +
                 "which ends at byte " + std::to_string(end));
  }

  void decode(std::size_t records, std::size_t at, ParticleChunk& chunk) {
    chunk.positions.resize(at + records);
    if (mHasVelocity) chunk.velocities.resize(at + records);
    prepareColumns(chunk, mColumns, at + records);
    const std::byte* base = mBuffer.data();
    const PrtChannel& p = mChannels[*mPosition];
    decodeVec3Column(p.type, ByteOrder::Little, base + p.offset, mStride, records, chunk.positions.data() + at);
    if (mHasVelocity) {
      const PrtChannel& v = mChannels[*mVelocity];
      decodeVec3Column(v.type, ByteOrder::Little, base + v.offset, mStride, records, chunk.velocities.data() + at);
    }
    for (std::size_t k = 0; k < mSelected.size(); ++k) {
      const PrtChannel& c = mChannels[mExposedSource[mSelected[k]]];
      decodeColumn(c.type, ByteOrder::Little, base + c.offset, mStride, c.arity, records,
                   chunk.attributes[k].values.data() + at * std::size_t(c.arity));
    }
  }

  InputFile mFile;
  std::int32_t mVersion = 1;
  std::int64_t mCount = 0;
  std::vector<PrtChannel> mChannels;
  std::size_t mStride = 0;
  std::uint64_t mDataOffset = 0;
  std::optional<std::size_t> mPosition, mVelocity;  ///< into mChannels
  std::vector<AttributeDesc> mExposed;
  std::vector<std::size_t> mExposedSource;  ///< into mChannels
  std::vector<std::size_t> mSelected;       ///< into mExposed
  std::vector<AttributeColumn> mColumns;
  bool mHasVelocity = false;

  Inflater mInflater;
  z_stream& mStream = mInflater.stream;
  std::vector<Bytef> mInput;
  std::uint64_t mInputOffset = 0;
  std::size_t mInputFill = 0;
  bool mEnded = false;
  std::uint64_t mNext = 0;
  std::vector<std::byte> mBuffer;
};

}  // namespace

bool isPrt(std::span<const std::byte> head) { return head.size() >= 8 && std::memcmp(head.data(), kMagic, 8) == 0; }

std::unique_ptr<ParticleSource> openPrtParticles(InputFile file, const ReadOptions& options) {
  return std::make_unique<PrtReader>(std::move(file), options);
}

}  // namespace flipscope::detail
