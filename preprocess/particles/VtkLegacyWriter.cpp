// VTK legacy writer (.vtk; the "Simple Legacy Formats" of the VTK User's Guide, as
// VtkLegacyParticles.cpp reads them): version 3.0, BINARY (big-endian), a POLYDATA dataset of
// POINTS float and, with velocities, POINT_DATA with VECTORS velocity float. No cells: the
// points are the particles.
//
// The point count comes before the points, and is known only at commit(): it is written as a
// fixed-width field of zero-padded decimal digits (countField) and patched in place (legacy
// readers read the count as a decimal integer, leading zeros included). Velocities come after
// every point, so they are kept, already big-endian, in a SpillFile (an unnamed temporary file
// beside the output, 12 bytes a particle) and appended at commit(). Memory: a byte-swapped
// piece of kPieceParticles (384 KiB) and the spill's 1 MiB buffer.
#include <algorithm>
#include <bit>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "core/AtomicFile.h"
#include "core/Error.h"
#include "preprocess/particles/ParticleFormats.h"
#include "preprocess/particles/SpillFile.h"

namespace flipscope::detail {
namespace {

static_assert(sizeof(glm::vec3) == 12 && std::endian::native == std::endian::little,
              "points are packed float triples, swapped to big-endian");

constexpr std::size_t kPieceParticles = 1 << 15;

class VtkLegacyWriter final : public ParticleWriter {
 public:
  VtkLegacyWriter(const std::filesystem::path& path, const WriteOptions& options) : mFile(path) {
    if (options.velocity) mVelocities.emplace(path.parent_path());
    std::string header = "# vtk DataFile Version 3.0\nflipscope particles\nBINARY\nDATASET POLYDATA\nPOINTS ";
    mCountOffset = header.size();
    header += std::string(kCountFieldDigits, '0') + " float\n";
    mFile.write(header.data(), header.size());
  }

  void write(const ParticleChunk& chunk) override {
    FLIPSCOPE_CHECK(!mVelocities || chunk.velocities.size() == chunk.size(),
                    "velocities=" << chunk.velocities.size() << " positions=" << chunk.size());
    for (std::size_t begin = 0; begin < chunk.size(); begin += kPieceParticles) {
      const std::size_t n = std::min(kPieceParticles, chunk.size() - begin);
      bigEndian(chunk.positions.data() + begin, n);
      mFile.write(mSwapped.data(), mSwapped.size() * 4);
      if (mVelocities) {
        bigEndian(chunk.velocities.data() + begin, n);
        mVelocities->write(mSwapped.data(), mSwapped.size() * 4);
      }
    }
    mCount += chunk.size();
  }

  void commit() override {
    const std::string count = countField(mCount);
    mFile.writeAt(mCountOffset, count.data(), count.size());
    if (mVelocities) {
      const std::string pointData = "\nPOINT_DATA " + std::to_string(mCount) + "\nVECTORS velocity float\n";
      mFile.write(pointData.data(), pointData.size());
      mVelocities->readBack([&](std::span<const std::byte> bytes) { mFile.write(bytes); });
    }
    mFile.write("\n", 1);
    mFile.commit();
  }

 private:
  /// `n` vectors as big-endian float32 in mSwapped.
  void bigEndian(const glm::vec3* vectors, std::size_t n) {
    mSwapped.resize(3 * n);
    std::memcpy(mSwapped.data(), vectors, n * sizeof(glm::vec3));
    for (std::uint32_t& word : mSwapped) word = __builtin_bswap32(word);
  }

  AtomicFile mFile;
  std::optional<SpillFile> mVelocities;
  std::uint64_t mCountOffset = 0;
  std::uint64_t mCount = 0;
  std::vector<std::uint32_t> mSwapped;
};

}  // namespace

std::unique_ptr<ParticleWriter> createVtkLegacyWriter(const std::filesystem::path& path, const WriteOptions& options) {
  return std::make_unique<VtkLegacyWriter>(path, options);
}

}  // namespace flipscope::detail
