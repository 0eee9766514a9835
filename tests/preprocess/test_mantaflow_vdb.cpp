// The Blender Mantaflow sample (DESIGN.md, "Real data"): the reader's particle count against
// OpenVDB's own pointCount, positions inside each grid's world bounding box. The oracle needs
// the registration the reader does: Mantaflow's `U` attribute is int32 with the truncate codec.
#include <gtest/gtest.h>

#include <openvdb/openvdb.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>

#include <cmath>
#include <filesystem>

#include "ParticleTestSupport.h"
#include "TestSupport.h"

namespace flipscope {
namespace {

struct OpenVdbPoints {
  std::uint64_t count = 0;
  openvdb::BBoxd worldBounds;  ///< of every leaf, half a voxel wider (P lies in [-0.5, 0.5])
};

OpenVdbPoints openVdbOracle(const std::filesystem::path& path) {
  openvdb::initialize();
  using MantaflowInt = openvdb::points::TypedAttributeArray<std::int32_t, openvdb::points::TruncateCodec>;
  if (!MantaflowInt::isRegistered()) MantaflowInt::registerType();
  openvdb::io::File file(path.string());
  file.open(false);
  OpenVdbPoints result;
  openvdb::GridPtrVecPtr grids = file.getGrids();
  for (const auto& base : *grids) {
    auto grid = openvdb::gridPtrCast<openvdb::points::PointDataGrid>(base);
    if (!grid) continue;
    result.count += openvdb::points::pointCount(grid->tree());
    openvdb::CoordBBox leaves;
    grid->tree().evalLeafBoundingBox(leaves);
    openvdb::BBoxd index(leaves.min().asVec3d() - 0.5, leaves.max().asVec3d() + 0.5);
    result.worldBounds.expand(grid->transform().indexToWorld(index));
  }
  return result;
}

std::vector<std::filesystem::path> mantaflowFiles() {
  std::vector<std::filesystem::path> files;
  for (const char* folder : {"data", "particles"}) {
    std::filesystem::path dir = std::filesystem::path(FLIPSCOPE_DATA_DIR) / "mantaflow-dam64" / folder;
    if (!std::filesystem::is_directory(dir)) continue;
    for (const auto& entry : std::filesystem::directory_iterator(dir))
      if (entry.path().extension() == ".vdb") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(MantaflowVdb, CountsMatchOpenVdbAndPositionsLieInTheGrid) {
  auto files = mantaflowFiles();
  // 30 frames of FLIP and secondary particles in ../shared/data; frames 1, 2 and 30 in the
  // repository's tests/data when the shared folder is not beside the checkout.
  ASSERT_GE(files.size(), 6u) << "Mantaflow sample under " << FLIPSCOPE_DATA_DIR;
  EXPECT_EQ(files.size() % 2, 0u);
  std::uint64_t total = 0;
  for (const auto& path : files) {
    OpenVdbPoints oracle = openVdbOracle(path);
    auto source = openParticleFile(path);
    EXPECT_EQ(source->countHint(), oracle.count) << path;
    EXPECT_EQ(source->hasVelocity(), oracle.count > 0) << path;  // Mantaflow's particles_velocity*
    auto particles = testing::readAll(*source, 4096);
    ASSERT_EQ(particles.size(), oracle.count) << path;
    const double slack = 1e-4;
    for (std::size_t i = 0; i < particles.size(); ++i) {
      const glm::vec3& p = particles.positions[i];
      ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) << path << " particle " << i;
      for (int c = 0; c < 3; ++c) {
        ASSERT_GE(p[c], oracle.worldBounds.min()[c] - slack) << path << " particle " << i;
        ASSERT_LE(p[c], oracle.worldBounds.max()[c] + slack) << path << " particle " << i;
      }
      const glm::vec3& v = particles.velocities[i];
      ASSERT_TRUE(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z)) << path << " particle " << i;
    }
    total += particles.size();
  }
  EXPECT_GT(total, 0u);
}

TEST(MantaflowVdb, GridsSelectedByName) {
  auto path = flipscope::testing::mantaflowFile("data", "fluid_data_0030.vdb");
  ASSERT_TRUE(std::filesystem::exists(path)) << "no " << path;
  ReadOptions options;
  options.grids = {"particles"};
  EXPECT_EQ(openParticleFile(path, options)->countHint(), openVdbOracle(path).count);
  options.grids = {"velocity"};
  testing::expectFileError([&] { openParticleFile(path, options); },
                           {"fluid_data_0030.vdb", "'velocity'", "not a PointDataGrid"});
  options.grids = {"foam"};
  testing::expectFileError([&] { openParticleFile(path, options); },
                           {"no grid named 'foam'", "'particles'", "'velocity'"});
}

}  // namespace
}  // namespace flipscope
