// Raw particle files: little-endian float32 x y z, 12 bytes a particle, no header; the count
// follows from the file size. Positions only.
#include <algorithm>
#include <bit>

#include "core/AtomicFile.h"
#include "core/Error.h"
#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleFormats.h"

namespace flipscope::detail {
namespace {

static_assert(sizeof(glm::vec3) == 12 && std::endian::native == std::endian::little,
              "raw files are read straight into glm::vec3");
constexpr std::uint64_t kRawParticleBytes = 12;

class RawReader final : public ParticleSource {
 public:
  explicit RawReader(InputFile file) : mFile(std::move(file)) {
    if (mFile.size() % kRawParticleBytes != 0)
      throw FileError(mFile.path(), "raw particle file size " + std::to_string(mFile.size()) +
                                " bytes is not a multiple of 12 (float32 x y z)");
    mCount = mFile.size() / kRawParticleBytes;
  }
  std::string name() const override { return mFile.path().string(); }
  std::string format() const override { return "raw little-endian float32 xyz"; }
  bool hasVelocity() const override { return false; }
  std::optional<std::uint64_t> countHint() const override { return mCount; }
  bool read(ParticleChunk& chunk, std::size_t maxParticles) override {
    FLIPSCOPE_CHECK(maxParticles > 0);
    std::uint64_t n = std::min<std::uint64_t>(maxParticles, mCount - mNext);
    if (n == 0) {
      chunk.clear();
      return false;
    }
    chunk.resizeForOverwrite(n, false);
    chunk.attributes.clear();  // a chunk read into before may hold a column added after (TypedSource)
    std::size_t bytes = n * kRawParticleBytes;
    if (mFile.read(chunk.positions.data(), bytes) != bytes)
      throw FileError(mFile.path(), "file ends at byte " + std::to_string(mFile.offset()) + ", particle " +
                                        std::to_string(mNext) + " of " + std::to_string(mCount) +
                                        " (was it truncated while being read?)");
    mNext += n;
    return true;
  }
  void rewind() override {
    mFile.seek(0);
    mNext = 0;
  }
  bool readPositionsAt(std::span<const std::uint64_t> indices, std::vector<glm::vec3>& positions) override {
    std::vector<std::uint64_t> offsets(indices.size());
    for (std::size_t i = 0; i < indices.size(); ++i) {
      FLIPSCOPE_CHECK(indices[i] < mCount);
      offsets[i] = indices[i] * kRawParticleBytes;
    }
    std::vector<glm::vec3> read(indices.size());
    if (!mFile.readScattered(offsets, kRawParticleBytes, reinterpret_cast<std::byte*>(read.data()))) return false;
    positions = std::move(read);
    return true;
  }
  bool readPositionRange(std::uint64_t first, std::size_t count, std::vector<glm::vec3>& positions) override {
    if (!mFile.randomAccess()) return false;
    FLIPSCOPE_CHECK(first + count <= mCount);
    positions.resize(count);
    const std::size_t bytes = count * kRawParticleBytes;
    if (mFile.readAt(first * kRawParticleBytes, positions.data(), bytes) != bytes)
      throw FileError(mFile.path(), "file ends inside particles " + std::to_string(first) + " to " +
                                        std::to_string(first + count) + " of " + std::to_string(mCount) +
                                        " (was it truncated while being read?)");
    return true;
  }

 private:
  InputFile mFile;
  std::uint64_t mCount = 0;
  std::uint64_t mNext = 0;
};

class RawWriter final : public ParticleWriter {
 public:
  explicit RawWriter(const std::filesystem::path& path) : mFile(path) {}
  void write(const ParticleChunk& chunk) override {
    mFile.write(chunk.positions.data(), chunk.positions.size() * kRawParticleBytes);
  }
  void commit() override { mFile.commit(); }

 private:
  AtomicFile mFile;
};

}  // namespace

std::unique_ptr<ParticleSource> openRawParticles(InputFile file, const ReadOptions& options) {
  (void)selectAttributes({}, options, file.path());  // raw files hold positions only
  return std::make_unique<RawReader>(std::move(file));
}

std::unique_ptr<ParticleWriter> createRawWriter(const std::filesystem::path& path, const WriteOptions&) {
  return std::make_unique<RawWriter>(path);
}

}  // namespace flipscope::detail
