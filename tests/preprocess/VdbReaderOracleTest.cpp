// The VDB points reader (our own decoder, VdbPointsReader.cpp) against OpenVDB's reader, bit for
// bit: positions, velocities, counts and the spacing hint, for files OpenVDB writes in every
// way we can make it (each vec3s codec, uniform attributes, blosc / zip / no compression, with
// and without grid offsets, pages larger than OpenVDB's page size, several grids, linear
// transforms) and for the Blender Mantaflow sample.
#include <gtest/gtest.h>

#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "ParticleTestSupport.h"
#include "VdbOracle.h"
#include "VdbTestFiles.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

/// What OpenVDB reads: every point of each named grid (all PointDataGrids when `grids` is
/// empty, in the order of `order`), leaf by leaf, voxel by voxel, as the reader promises.
ParticleChunk oracleRead(const fs::path& path, const std::vector<std::string>& names, bool velocity) {
  testing::initializeOpenVdbOracle();
  openvdb::io::File file(path.string());
  file.open(false);
  ParticleChunk out;
  for (const auto& name : names) {
    auto grid = openvdb::gridPtrCast<openvdb::points::PointDataGrid>(file.readGrid(name));
    if (!grid) continue;
    for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) {
      const auto& descriptor = leaf->attributeSet().descriptor();
      openvdb::points::AttributeHandle<openvdb::Vec3f> p(leaf->constAttributeArray("P"));
      std::optional<openvdb::points::AttributeHandle<openvdb::Vec3f>> v;
      if (velocity) v.emplace(leaf->constAttributeArray(testing::oracleVelocityAttribute(descriptor)));
      openvdb::Index point = 0;
      for (openvdb::Index voxel = 0; voxel < 512; ++voxel) {
        const openvdb::Vec3d ijk = leaf->offsetToGlobalCoord(voxel).asVec3d();
        for (; point < leaf->getValue(voxel); ++point) {
          const openvdb::Vec3d world = grid->transform().indexToWorld(ijk + openvdb::Vec3d(p.get(point)));
          out.positions.emplace_back(float(world.x()), float(world.y()), float(world.z()));
          if (v) {
            const openvdb::Vec3f value = v->get(point);
            out.velocities.emplace_back(value.x(), value.y(), value.z());
          }
        }
      }
    }
  }
  file.close();
  return out;
}

/// OpenVDB's own count of active voxels and points of the named grids.
std::pair<std::uint64_t, double> oracleVoxels(const fs::path& path, const std::vector<std::string>& names) {
  testing::initializeOpenVdbOracle();
  openvdb::io::File file(path.string());
  file.open(false);
  std::uint64_t points = 0;
  double volume = 0;
  for (const auto& name : names) {
    auto grid = openvdb::gridPtrCast<openvdb::points::PointDataGrid>(file.readGrid(name));
    if (!grid || openvdb::points::pointCount(grid->tree()) == 0) continue;
    points += openvdb::points::pointCount(grid->tree());
    volume += double(grid->tree().activeVoxelCount()) * grid->transform().voxelVolume();
  }
  return {points, volume};
}

/// Whether OpenVDB finds a velocity attribute in every grid that holds points (the reader's own
/// hasVelocity() must agree: the comparison below must not take the reader's word for it).
bool oracleHasVelocity(const fs::path& path, const std::vector<std::string>& names) {
  testing::initializeOpenVdbOracle();
  openvdb::io::File file(path.string());
  file.open(false);
  bool any = false, all = true;
  for (const auto& name : names) {
    auto grid = openvdb::gridPtrCast<openvdb::points::PointDataGrid>(file.readGrid(name));
    if (!grid) continue;
    auto leaf = grid->tree().cbeginLeaf();
    if (!leaf) continue;
    any = true;
    all = all && !testing::oracleVelocityAttribute(leaf->attributeSet().descriptor()).empty();
  }
  return any && all;
}

void expectSameAsOracle(const fs::path& path, const std::vector<std::string>& pointGrids, const std::string& what) {
  SCOPED_TRACE(what + ": " + path.filename().string());
  auto source = openParticleFile(path);
  const bool velocity = oracleHasVelocity(path, pointGrids);
  EXPECT_EQ(source->hasVelocity(), velocity);
  const ParticleChunk expected = oracleRead(path, pointGrids, velocity);
  const ParticleChunk got = testing::readAll(*source, 777);
  ASSERT_EQ(got.size(), expected.size());
  EXPECT_EQ(source->countHint(), expected.size());
  if (std::getenv("FLIPSCOPE_ORACLE_VERBOSE"))
    std::printf("%s: %zu particles, velocity %d\n", what.c_str(), got.size(), int(velocity));
  ASSERT_EQ(got.velocities.size(), expected.velocities.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    ASSERT_TRUE(testing::sameBits(got.positions[i], expected.positions[i])) << "particle " << i;
    if (velocity) {
      ASSERT_TRUE(testing::sameBits(got.velocities[i], expected.velocities[i])) << "velocity " << i;
    }
  }
  const auto [points, volume] = oracleVoxels(path, pointGrids);
  const auto hint = source->spacingHint();
  if (points == 0) {
    EXPECT_FALSE(hint);
  } else {
    ASSERT_TRUE(hint);
    EXPECT_EQ(hint->points, points);
    EXPECT_DOUBLE_EQ(hint->volume, std::abs(volume));
  }
  // Rewinding reads the same particles again.
  source->rewind();
  const ParticleChunk again = testing::readAll(*source, 100000);
  ASSERT_EQ(again.size(), got.size());
  for (std::size_t i = 0; i < got.size(); ++i) ASSERT_TRUE(testing::sameBits(again.positions[i], got.positions[i]));
}

TEST(VdbReaderOracle, EveryWayOpenVdbWritesPoints) {
  TempDir dir("vdb-oracle");
  const auto cases = testing::vdbTestFiles(dir.path());
  ASSERT_GE(cases.size(), 10u);
  for (const auto& file : cases) expectSameAsOracle(file.path, file.pointGrids, file.what);
}

TEST(VdbReaderOracle, GridsSelectedByNameMatchOpenVdb) {
  TempDir dir("vdb-oracle-names");
  for (const auto& file : testing::vdbTestFiles(dir.path())) {
    if (file.pointGrids.size() < 2) continue;
    for (const auto& name : file.pointGrids) {
      SCOPED_TRACE(file.what + ", grid " + name);
      ReadOptions options;
      options.grids = {name};
      auto source = openParticleFile(file.path, options);
      const ParticleChunk expected = oracleRead(file.path, {name}, source->hasVelocity());
      const ParticleChunk got = testing::readAll(*source, 1000);
      ASSERT_EQ(got.size(), expected.size());
      for (std::size_t i = 0; i < got.size(); ++i)
        ASSERT_TRUE(testing::sameBits(got.positions[i], expected.positions[i]));
    }
  }
}

TEST(VdbReaderOracle, MantaflowSample) {
  std::size_t files = 0;
  for (const char* folder : {"data", "particles"}) {
    const fs::path dir = fs::path(FLIPSCOPE_DATA_DIR) / "mantaflow-dam64" / folder;
    if (!fs::is_directory(dir)) continue;
    for (const auto& entry : fs::directory_iterator(dir)) {
      if (entry.path().extension() != ".vdb") continue;
      const std::string grid = std::string(folder) == "data" ? "particles" : "particles_secondary";
      expectSameAsOracle(entry.path(), {grid}, "Mantaflow");
      ++files;
    }
  }
  EXPECT_GE(files, 6u);
}

}  // namespace
}  // namespace flipscope
