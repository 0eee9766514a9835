// The OpenVDB points writer, a module of its own (see preprocess/particles/VdbWriterModule.h):
// one PointDataGrid written through OpenVDB, as io::Stream writes it.
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointDataGrid.h>

#include <cmath>
#include <cstdio>
#include <mutex>
#include <string>
#include <type_traits>

#include "preprocess/particles/VdbWriterModule.h"

namespace flipscope::vdbwriter {
namespace {

/// Points a PointDataGrid can store: voxel coordinates must fit OpenVDB's 32-bit Coord.
constexpr double kMaxVoxelCoordinate = 1 << 30;
/// Average points per occupied voxel aimed at when the voxel size comes from the points.
constexpr std::uint32_t kPointsPerVoxel = 8;

/// x y z floats as OpenVDB's point conversion reads them (the interface of
/// points::PointAttributeVector), without copying them into a vector of its own.
class FloatTriples {
 public:
  using PosType = openvdb::Vec3f;
  using value_type = openvdb::Vec3f;
  FloatTriples(const float* data, std::size_t count) : mData(data), mCount(count) {}
  std::size_t size() const { return mCount; }
  void getPos(std::size_t n, openvdb::Vec3f& xyz) const { xyz = openvdb::Vec3f(mData + 3 * n); }
  void get(openvdb::Vec3f& value, std::size_t n) const { value = openvdb::Vec3f(mData + 3 * n); }
  void get(openvdb::Vec3f& value, std::size_t n, openvdb::Index) const { get(value, n); }

 private:
  const float* mData;
  std::size_t mCount;
};

void fail(const std::string& message, char* error, std::size_t errorBytes) {
  if (errorBytes > 0) std::snprintf(error, errorBytes, "%s", message.c_str());
}

bool write(const Points& in, std::ostream& out, char* error, std::size_t errorBytes) {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
  namespace points = openvdb::points;
  const FloatTriples positions(in.positions, in.count);
  double voxelSize = in.voxelSize;
  if (voxelSize <= 0) voxelSize = in.count == 0 ? 1.0 : points::computeVoxelSize(positions, kPointsPerVoxel);
  if (!(voxelSize > 0) || !std::isfinite(voxelSize)) voxelSize = 1.0;
  for (std::size_t i = 0; i < in.count; ++i) {
    openvdb::Vec3f p;
    positions.getPos(i, p);
    if (std::abs(p.x()) / voxelSize > kMaxVoxelCoordinate || std::abs(p.y()) / voxelSize > kMaxVoxelCoordinate ||
        std::abs(p.z()) / voxelSize > kMaxVoxelCoordinate) {
      char voxelSizeText[32];  // as core/NumberText's numberText: this module links OpenVDB alone
      std::snprintf(voxelSizeText, sizeof voxelSizeText, "%g", voxelSize);
      fail("position " + p.str() + " is too far from the origin for voxel size " + std::string(voxelSizeText), error,
           errorBytes);
      return false;
    }
  }
  auto transform = openvdb::math::Transform::createLinearTransform(voxelSize);
  auto index = openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(positions, *transform);
  auto grid = points::createPointDataGrid<points::NullCodec, points::PointDataGrid>(*index, positions, *transform);
  if (in.velocity) {
    points::appendAttribute<openvdb::Vec3f>(grid->tree(), "v");
    points::populateAttribute(grid->tree(), index->tree(), "v", FloatTriples(in.velocities, in.count));
  }
  grid->setName("particles");
  openvdb::io::Stream(out).write(openvdb::GridCPtrVec{grid});
  return true;
}

}  // namespace
}  // namespace flipscope::vdbwriter

/// The module's entry point (VdbWriterModule.h: WriteFunction). OpenVDB's errors come back as
/// false and a message; exceptions of the stream pass through.
extern "C" __attribute__((visibility("default"))) bool flipscopeWriteVdbPoints(
    const flipscope::vdbwriter::Points& points, std::ostream& out, char* error, std::size_t errorBytes) {
  try {
    return flipscope::vdbwriter::write(points, out, error, errorBytes);
  } catch (const openvdb::Exception& e) {
    flipscope::vdbwriter::fail(std::string("OpenVDB: ") + e.what(), error, errorBytes);
    return false;
  }
}

// The entry point has the type the host looks it up as.
static_assert(std::is_same_v<decltype(&flipscopeWriteVdbPoints), flipscope::vdbwriter::WriteFunction>);
