// OpenVDB point files written through OpenVDB: one PointDataGrid 'particles' with P (and the
// velocity `v` when asked), stored as io::Stream writes it. Reading is VdbPointsReader.cpp, our
// own bounds-checked decoder; OpenVDB's reader is only the oracle of its tests.
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointDataGrid.h>

#include <cmath>
#include <mutex>
#include <ostream>
#include <streambuf>

#include "core/AtomicFile.h"
#include "core/Error.h"
#include "preprocess/particles/ParticleFormats.h"

namespace flipscope::detail {
namespace {

using openvdb::points::PointDataGrid;

/// Initializes OpenVDB once (thread safe).
void initializeOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

/// Unbuffered std::streambuf that appends to an AtomicFile (which buffers itself).
class AtomicFileStreamBuffer final : public std::streambuf {
 public:
  explicit AtomicFileStreamBuffer(AtomicFile& file) : mFile(file) {}

 protected:
  std::streamsize xsputn(const char* data, std::streamsize count) override {
    mFile.write(data, static_cast<std::size_t>(count));
    return count;
  }
  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    char byte = traits_type::to_char_type(c);
    mFile.write(&byte, 1);
    return c;
  }

 private:
  AtomicFile& mFile;
};

/// Points a PointDataGrid can store: voxel coordinates must fit OpenVDB's 32-bit Coord.
constexpr double kMaxVoxelCoordinate = 1 << 30;
/// Average points per occupied voxel aimed at when the voxel size comes from the points.
constexpr std::uint32_t kPointsPerVoxel = 8;

class VdbPointsWriter final : public ParticleWriter {
 public:
  VdbPointsWriter(const std::filesystem::path& path, const WriteOptions& options) : mFile(path), mOptions(options) {
    initializeOpenVdb();
  }

  void write(const ParticleChunk& chunk) override {
    FLIPSCOPE_CHECK(!mOptions.velocity || chunk.velocities.size() == chunk.size(),
                    "velocities=" << chunk.velocities.size() << " positions=" << chunk.size());
    for (std::size_t k = 0; k < chunk.size(); ++k) {
      const glm::vec3& p = chunk.positions[k];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw InputError(mFile.destination().string() +
                         ": OpenVDB points cannot store the non-finite position of particle " +
                         std::to_string(mPositions.size()));
      mPositions.emplace_back(p.x, p.y, p.z);
      if (mOptions.velocity) {
        const glm::vec3& v = chunk.velocities[k];
        mVelocities.emplace_back(v.x, v.y, v.z);
      }
    }
  }

  void commit() override {
    namespace points = openvdb::points;
    points::PointAttributeVector<openvdb::Vec3f> positions(mPositions);
    double voxelSize = mOptions.vdbVoxelSize;
    if (voxelSize <= 0) voxelSize = mPositions.empty() ? 1.0 : points::computeVoxelSize(positions, kPointsPerVoxel);
    if (!(voxelSize > 0) || !std::isfinite(voxelSize)) voxelSize = 1.0;
    for (const auto& p : mPositions)
      if (std::abs(p.x()) / voxelSize > kMaxVoxelCoordinate || std::abs(p.y()) / voxelSize > kMaxVoxelCoordinate ||
          std::abs(p.z()) / voxelSize > kMaxVoxelCoordinate)
        throw InputError(mFile.destination().string() + ": position " + p.str() +
                         " is too far from the origin for voxel size " + std::to_string(voxelSize));
    auto transform = openvdb::math::Transform::createLinearTransform(voxelSize);
    auto index = openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(positions, *transform);
    auto grid = points::createPointDataGrid<points::NullCodec, PointDataGrid>(*index, positions, *transform);
    if (mOptions.velocity) {
      points::appendAttribute<openvdb::Vec3f>(grid->tree(), "v");
      points::PointAttributeVector<openvdb::Vec3f> velocities(mVelocities);
      points::populateAttribute(grid->tree(), index->tree(), "v", velocities);
    }
    grid->setName("particles");
    AtomicFileStreamBuffer buffer(mFile);
    std::ostream stream(&buffer);
    stream.exceptions(std::ios::badbit | std::ios::failbit);
    openvdb::io::Stream(stream).write(openvdb::GridCPtrVec{grid});
    stream.flush();
    mFile.commit();
  }

 private:
  AtomicFile mFile;
  WriteOptions mOptions;
  std::vector<openvdb::Vec3f> mPositions;
  std::vector<openvdb::Vec3f> mVelocities;
};

}  // namespace

std::unique_ptr<ParticleWriter> createVdbWriter(const std::filesystem::path& path, const WriteOptions& options) {
  return std::make_unique<VdbPointsWriter>(path, options);
}

}  // namespace flipscope::detail
