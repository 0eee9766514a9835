// gzip container (RFC 1952) around any particle file (".bgeo.gz", ".ply.gz", ...): a ByteSource
// that presents the decoded bytes, inflated by zlib in gzip mode. Concatenated members
// (`cat a.gz b.gz`) decode as one stream, as gzip(1) does; anything else after the last member
// is refused as trailing garbage. Each member's CRC-32 and length are checked by zlib.
//
// Memory stays bounded (a 256 KiB input buffer and zlib's 32 KiB window) whatever the decoded
// size: nothing is ever inflated whole into memory, so a decompression bomb costs time, not
// memory. size() needs the decoded size before anything is read, so the constructor inflates the
// whole file once (which also finds damage and truncation up front). Reads that follow each
// other are the fast path; reading ahead inflates and discards up to the offset; going back
// (rewind, a second conversion pass) inflates again from the start of the file.
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>
#include <vector>

#include "core/Error.h"
#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleFormats.h"

namespace flipscope::detail {
namespace {

constexpr std::size_t kInputBytes = 256 * 1024;
constexpr std::size_t kSkipBytes = 64 * 1024;
constexpr unsigned char kGzipMagic[3] = {0x1f, 0x8b, 0x08};  // ID1 ID2, CM = deflate

class GzipByteSource final : public ByteSource {
 public:
  explicit GzipByteSource(InputFile file) : mFile(std::move(file)), mInput(kInputBytes), mSkip(kSkipBytes) {
    std::memset(&mStream, 0, sizeof mStream);
    if (inflateInit2(&mStream, 16 + MAX_WBITS) != Z_OK)
      throw FileError(mFile.path(), "cannot start the gzip decoder (zlib: out of memory?)");
    try {
      while (inflateSome(mSkip.data(), mSkip.size()) != 0) {
      }
      mSize = mDecoded;
      restart();
    } catch (...) {
      inflateEnd(&mStream);
      throw;
    }
  }
  ~GzipByteSource() override { inflateEnd(&mStream); }
  GzipByteSource(const GzipByteSource&) = delete;
  GzipByteSource& operator=(const GzipByteSource&) = delete;

  std::uint64_t size() const override { return mSize; }

  std::size_t readAt(std::uint64_t offset, void* data, std::size_t bytes) override {
    if (offset >= mSize || bytes == 0) return 0;
    if (offset < mDecoded) restart();  // backwards: inflate again from the start
    while (mDecoded < offset) {
      const std::size_t skip = std::size_t(std::min<std::uint64_t>(mSkip.size(), offset - mDecoded));
      if (inflateSome(mSkip.data(), skip) == 0) throw changed();
    }
    auto* out = static_cast<unsigned char*>(data);
    std::size_t done = 0;
    while (done < bytes) {
      const std::size_t n = inflateSome(out + done, bytes - done);
      if (n == 0) break;
      done += n;
    }
    if (done < bytes && offset + done < mSize) throw changed();
    return done;
  }

 private:
  FileError changed() const {
    return FileError(mFile.path(), "gzip data changed while being read (decoded size was " + std::to_string(mSize) +
                                       " bytes when the file was opened)");
  }

  /// File offset of the next compressed byte zlib will consume.
  std::uint64_t compressedOffset() const { return mInputOffset + (mInputFill - mStream.avail_in); }

  void restart() {
    if (inflateReset(&mStream) != Z_OK) throw FileError(mFile.path(), "cannot restart the gzip decoder");
    mStream.avail_in = 0;
    mStream.next_in = nullptr;
    mInputOffset = 0;
    mInputFill = 0;
    mMemberStart = 0;
    mDecoded = 0;
    mFinished = false;
  }

  /// Inflates up to `bytes` bytes into `out`; returns how many (0 only after the last member).
  std::size_t inflateSome(void* out, std::size_t bytes) {
    if (mFinished) return 0;
    mStream.next_out = static_cast<Bytef*>(out);
    mStream.avail_out = uInt(std::min<std::size_t>(bytes, std::numeric_limits<uInt>::max()));
    const uInt asked = mStream.avail_out;
    while (mStream.avail_out > 0 && !mFinished) {
      if (mStream.avail_in == 0) {
        mInputOffset += mInputFill;
        mInputFill = mFile.readAt(mInputOffset, mInput.data(), mInput.size());
        if (mInputFill == 0)
          throw FileError(mFile.path(), "truncated gzip data: the file ends at byte " + std::to_string(mInputOffset) +
                                            " inside the gzip member that starts at byte " +
                                            std::to_string(mMemberStart) + " (" +
                                            std::to_string(mDecoded + (asked - mStream.avail_out)) + " bytes decoded)");
        mStream.next_in = mInput.data();
        mStream.avail_in = uInt(mInputFill);
      }
      const int status = inflate(&mStream, Z_NO_FLUSH);
      if (status == Z_STREAM_END) {
        nextMember();
      } else if (status != Z_OK) {
        const std::string reason = status == Z_MEM_ERROR ? "out of memory"
                                   : mStream.msg         ? mStream.msg
                                                         : "error " + std::to_string(status);
        throw FileError(mFile.path(), "damaged gzip data near compressed byte " + std::to_string(compressedOffset()) +
                                          " (member starting at byte " + std::to_string(mMemberStart) +
                                          ", zlib: " + reason + ")");
      }
    }
    const std::size_t produced = asked - mStream.avail_out;
    mDecoded += produced;
    return produced;
  }

  /// After a member's end: another member follows (concatenated gzip), or the file ends.
  void nextMember() {
    const std::uint64_t end = compressedOffset();
    if (end == mFile.size()) {
      mFinished = true;
      return;
    }
    std::array<unsigned char, 3> magic{};
    const std::size_t got = mFile.readAt(end, magic.data(), magic.size());
    if (got < 2 || magic[0] != kGzipMagic[0] || magic[1] != kGzipMagic[1])
      throw FileError(mFile.path(), std::to_string(mFile.size() - end) + " bytes of trailing garbage after the gzip " +
                                        "member that ends at byte " + std::to_string(end) +
                                        " (neither the end of the file nor another gzip member)");
    if (inflateReset(&mStream) != Z_OK) throw FileError(mFile.path(), "cannot restart the gzip decoder");
    mMemberStart = end;
  }

  InputFile mFile;
  z_stream mStream;
  std::vector<Bytef> mInput;
  std::vector<Bytef> mSkip;
  std::uint64_t mInputOffset = 0;  ///< file offset of mInput[0]
  std::size_t mInputFill = 0;      ///< valid bytes in mInput
  std::uint64_t mMemberStart = 0;
  std::uint64_t mDecoded = 0;  ///< decoded offset of the next byte inflate() produces
  std::uint64_t mSize = 0;
  bool mFinished = false;
};

}  // namespace

bool isGzip(InputFile& file) {
  const std::vector<std::byte> head = file.peekHead(3);
  return head.size() == 3 && std::memcmp(head.data(), kGzipMagic, 3) == 0;
}

std::unique_ptr<ByteSource> decodeGzip(InputFile file) { return std::make_unique<GzipByteSource>(std::move(file)); }

}  // namespace flipscope::detail
