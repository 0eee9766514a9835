// Krakatoa PRT 1.0 writer (the layout PrtParticles.cpp reads; little-endian): the magic, the
// header length (56), "Extensible Particle Format", version 1, the particle count, then the
// reserved int32 (4), the channel count, the definition size (44) and the channels Position
// float32[3] at offset 0 (and Velocity float32[3] at offset 12), then the records as one zlib
// stream (RFC 1950). The count is written as 0 and patched at commit() with the real count (the
// format's -1, "unknown", is never written).
//
// Streaming, bounded memory: the records are deflated as the chunks arrive, interleaved a piece
// of kPieceParticles at a time (768 KiB) when there are velocities (positions alone are
// deflated straight from the chunk), through a 256 KiB output buffer, plus zlib's own state
// (about 256 KiB).
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <new>

#include "core/AtomicFile.h"
#include "core/Error.h"
#include "preprocess/particles/ParticleFormats.h"

namespace flipscope::detail {
namespace {

static_assert(std::endian::native == std::endian::little && sizeof(glm::vec3) == 12,
              "PRT fields and float32 channels are written as stored in memory");

constexpr unsigned char kMagic[8] = {0xc0, 'P', 'R', 'T', '\r', '\n', 0x1a, '\n'};
constexpr std::int32_t kHeaderBytes = 56;
constexpr std::uint64_t kCountOffset = 48;
constexpr std::int32_t kChannelBytes = 44;
constexpr std::int32_t kFloat32 = 4;
constexpr std::size_t kPieceParticles = 1 << 15;
constexpr std::size_t kOutputBytes = 256 << 10;
/// zlib's default level (6), as PRT writers commonly use, so the files inflate like theirs.
/// Float records compress little at any level (about 0.9 of their size): level 1 writes about
/// 20% faster, Z_HUFFMAN_ONLY about 2.5x faster, for a file 0.3% and 1.5% larger.
constexpr int kLevel = Z_DEFAULT_COMPRESSION;

class PrtWriter final : public ParticleWriter {
 public:
  PrtWriter(const std::filesystem::path& path, const WriteOptions& options)
      : mFile(path), mVelocity(options.velocity), mOutput(kOutputBytes) {
    writeHeader();
    std::memset(&mStream, 0, sizeof mStream);
    if (deflateInit(&mStream, kLevel) != Z_OK) throw std::bad_alloc();
    mStreamOpen = true;
  }
  ~PrtWriter() override {
    if (mStreamOpen) deflateEnd(&mStream);
  }

  void write(const ParticleChunk& chunk) override {
    FLIPSCOPE_CHECK(!mVelocity || chunk.velocities.size() == chunk.size(),
                    "velocities=" << chunk.velocities.size() << " positions=" << chunk.size());
    if (!mVelocity) {
      deflateBytes(chunk.positions.data(), chunk.size() * sizeof(glm::vec3), Z_NO_FLUSH);
    } else {
      for (std::size_t begin = 0; begin < chunk.size(); begin += kPieceParticles) {
        const std::size_t n = std::min(kPieceParticles, chunk.size() - begin);
        mRecords.resize(2 * n);
        for (std::size_t i = 0; i < n; ++i) {
          mRecords[2 * i] = chunk.positions[begin + i];
          mRecords[2 * i + 1] = chunk.velocities[begin + i];
        }
        deflateBytes(mRecords.data(), mRecords.size() * sizeof(glm::vec3), Z_NO_FLUSH);
      }
    }
    mCount += chunk.size();
  }

  void commit() override {
    deflateBytes(nullptr, 0, Z_FINISH);
    deflateEnd(&mStream);
    mStreamOpen = false;
    const auto count = std::int64_t(mCount);
    mFile.writeAt(kCountOffset, &count, sizeof count);
    mFile.commit();
  }

 private:
  template <class T>
  void put(T value) {
    mFile.write(&value, sizeof value);
  }

  void writeHeader() {
    mFile.write(kMagic, sizeof kMagic);
    put(kHeaderBytes);
    char signature[32] = "Extensible Particle Format";
    mFile.write(signature, sizeof signature);
    put(std::int32_t(1));  // PRT 1.0
    FLIPSCOPE_CHECK(mFile.offset() == kCountOffset);
    put(std::int64_t(0));  // the count: patched at commit()
    put(std::int32_t(4));  // reserved
    put(std::int32_t(mVelocity ? 2 : 1));
    put(kChannelBytes);
    channel("Position", 0);
    if (mVelocity) channel("Velocity", 12);
  }

  void channel(const char* name, std::int32_t offset) {
    char field[32] = {};
    std::strncpy(field, name, sizeof field - 1);
    mFile.write(field, sizeof field);
    put(kFloat32);
    put(std::int32_t(3));
    put(offset);
  }

  /// Deflates `bytes` (zlib takes at most 4 GiB a call: pieces) and writes what comes out.
  void deflateBytes(const void* data, std::size_t bytes, int flush) {
    const auto* in = static_cast<const Bytef*>(data);
    do {
      const std::size_t piece = std::min<std::size_t>(bytes, std::size_t(1) << 30);
      mStream.next_in = const_cast<Bytef*>(in);
      mStream.avail_in = uInt(piece);
      const int pieceFlush = piece == bytes ? flush : Z_NO_FLUSH;
      int status = Z_OK;
      do {
        mStream.next_out = mOutput.data();
        mStream.avail_out = uInt(mOutput.size());
        status = deflate(&mStream, pieceFlush);
        FLIPSCOPE_CHECK(status == Z_OK || status == Z_STREAM_END || status == Z_BUF_ERROR, "deflate " << status);
        mFile.write(mOutput.data(), mOutput.size() - mStream.avail_out);
      } while (mStream.avail_out == 0 || (pieceFlush == Z_FINISH && status != Z_STREAM_END));
      in += piece;
      bytes -= piece;
    } while (bytes > 0);
  }

  AtomicFile mFile;
  bool mVelocity;
  z_stream mStream;
  bool mStreamOpen = false;
  std::uint64_t mCount = 0;
  std::vector<glm::vec3> mRecords;  ///< a piece of interleaved position, velocity records
  std::vector<Bytef> mOutput;
};

}  // namespace

std::unique_ptr<ParticleWriter> createPrtWriter(const std::filesystem::path& path, const WriteOptions& options) {
  return std::make_unique<PrtWriter>(path, options);
}

}  // namespace flipscope::detail
