// OpenVDB as the oracle of the VDB reader's tests: initialisation with Mantaflow's attribute
// type, the reader's velocity rule, and helpers that build point grids and write them as files
// (io::File, with grid offsets) or streams (io::Stream, without). Only the tests that compare
// with OpenVDB include this; the rest use VdbTestFiles.h, which includes no OpenVDB.
#pragma once

#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointDataGrid.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <random>
#include <string>
#include <vector>

namespace flipscope::testing {

/// OpenVDB initialized for reading, with the type of Blender Mantaflow's `U` attribute (int32,
/// truncate codec) registered: stock OpenVDB cannot read Mantaflow files without it.
inline void initializeOpenVdbOracle() {
  static std::once_flag once;
  std::call_once(once, [] {
    openvdb::initialize();
    using MantaflowInt = openvdb::points::TypedAttributeArray<std::int32_t, openvdb::points::TruncateCodec>;
    if (!MantaflowInt::isRegistered()) MantaflowInt::registerType();
  });
}

/// The reader's velocity rule: `v` if it is vec3s, else the first `particles_velocity*` by name.
inline std::string oracleVelocityAttribute(const openvdb::points::AttributeSet::Descriptor& descriptor) {
  const std::string vec3s = openvdb::typeNameAsString<openvdb::Vec3f>();
  if (std::size_t v = descriptor.find("v");
      v != openvdb::points::AttributeSet::INVALID_POS && descriptor.valueType(v) == vec3s)
    return "v";
  for (const auto& [name, index] : descriptor.map())
    if (name.rfind("particles_velocity", 0) == 0 && descriptor.valueType(index) == vec3s) return name;
  return "";
}


namespace vdbfiles {

using openvdb::Vec3f;
using openvdb::points::PointDataGrid;

struct Points {
  std::vector<Vec3f> positions, velocities;
};

inline Points randomPoints(std::size_t count, float extent, bool unitVelocity, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> position(-extent, extent), speed(-3.f, 3.f);
  Points p;
  for (std::size_t i = 0; i < count; ++i) {
    p.positions.emplace_back(position(rng), position(rng), position(rng));
    Vec3f v(speed(rng), speed(rng), speed(rng));
    if (unitVelocity) v = v.length() > 0 ? v / v.length() : Vec3f(1, 0, 0);
    p.velocities.push_back(v);
  }
  return p;
}

/// A PointDataGrid of `points` with P in `PCodec`; velocity `velocityName` in `VCodec` unless
/// the name is empty; `uniformVelocity`: a uniform attribute instead of the values.
template <class PCodec, class VCodec>
PointDataGrid::Ptr makeGrid(const Points& points, const openvdb::math::Transform::Ptr& transform,
                            const std::string& name, const std::string& velocityName, bool uniformVelocity = false) {
  namespace pts = openvdb::points;
  pts::PointAttributeVector<Vec3f> positions(points.positions);
  auto index = openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(positions, *transform);
  auto grid = pts::createPointDataGrid<PCodec, PointDataGrid>(*index, positions, *transform);
  if (!velocityName.empty()) {
    if (uniformVelocity) {
      pts::appendAttribute<Vec3f, VCodec>(grid->tree(), velocityName, Vec3f(0.5f, -1.25f, 2.0f));
    } else {
      pts::appendAttribute<Vec3f, VCodec>(grid->tree(), velocityName);
      pts::PointAttributeVector<Vec3f> velocities(points.velocities);
      pts::populateAttribute(grid->tree(), index->tree(), velocityName, velocities);
    }
  }
  grid->setName(name);
  return grid;
}

inline void writeFile(const std::filesystem::path& path, const openvdb::GridPtrVec& grids, std::uint32_t compression) {
  openvdb::io::File file(path.string());
  file.setCompression(compression);
  file.write(grids);
  file.close();
}

inline void writeStream(const std::filesystem::path& path, const openvdb::GridPtrVec& grids,
                        std::uint32_t compression) {
  std::ofstream out(path, std::ios::binary);
  openvdb::io::Stream stream(out);
  stream.setCompression(compression);
  stream.write(grids);
}

}  // namespace vdbfiles

}  // namespace flipscope::testing
