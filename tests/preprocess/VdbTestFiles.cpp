#include "VdbTestFiles.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "VdbOracle.h"

namespace flipscope::testing {

std::vector<VdbTestFile> vdbTestFiles(const std::filesystem::path& dir, double scale, bool large, bool compact) {
  using namespace vdbfiles;
  namespace pts = openvdb::points;
  using openvdb::math::Transform;
  initializeOpenVdbOracle();
  constexpr std::uint32_t kBlosc = openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK;
  constexpr std::uint32_t kZip = openvdb::io::COMPRESS_ZIP | openvdb::io::COMPRESS_ACTIVE_MASK;
  constexpr std::uint32_t kNone = openvdb::io::COMPRESS_NONE;
  auto count = [&](std::size_t n) { return std::max<std::size_t>(3, std::size_t(double(n) * scale)); };
  std::vector<VdbTestFile> files;
  auto add = [&](const std::string& name, const openvdb::GridPtrVec& grids, std::uint32_t compression, bool stream,
                 std::vector<std::string> pointGrids, const std::string& what) {
    const auto path = dir / name;
    if (stream)
      writeStream(path, grids, compression);
    else
      writeFile(path, grids, compression);
    files.push_back({path, std::move(pointGrids), what});
  };
  auto linear = [](double voxel) { return Transform::createLinearTransform(voxel); };
  auto squeeze = [&](Points p) {
    if (compact)
      for (auto& x : p.positions) x = Vec3f(std::abs(x.x()), std::abs(x.y()), std::abs(x.z())) * 0.25f;
    return p;
  };

  const Points a = squeeze(randomPoints(count(2000), 1.0f, false, 1));
  add("null_stream.vdb", {makeGrid<pts::NullCodec, pts::NullCodec>(a, linear(0.1), "particles", "")}, kBlosc, true,
      {"particles"}, "null P, no velocity, blosc, stream");
  add("null_v_file.vdb", {makeGrid<pts::NullCodec, pts::NullCodec>(a, linear(0.1), "particles", "v")}, kBlosc, false,
      {"particles"}, "null P and v, blosc, file with offsets");
  add("fxpt16_trnc_zip.vdb",
      {makeGrid<pts::FixedPointCodec<false, pts::PositionRange>, pts::TruncateCodec>(a, linear(0.07), "p", "v")}, kZip,
      false, {"p"}, "fxpt16 P, trnc v, zip");
  add("fxpt8_ufxpt16_none.vdb",
      {makeGrid<pts::FixedPointCodec<true, pts::PositionRange>, pts::FixedPointCodec<false, pts::UnitRange>>(
          a, linear(0.2), "p", "v")},
      kNone, true, {"p"}, "fxpt8 P, ufxpt16 v, no compression, stream");
  const Points unit = squeeze(randomPoints(count(1500), 2.0f, true, 2));
  add("trnc_uvec_blosc.vdb", {makeGrid<pts::TruncateCodec, pts::UnitVecCodec>(unit, linear(0.15), "p", "v")},
      openvdb::io::COMPRESS_BLOSC, false, {"p"}, "trnc P, uvec v, blosc without mask compression");
  add("ufxpt8_fxpt8_none_file.vdb",
      {makeGrid<pts::FixedPointCodec<true, pts::UnitRange>, pts::FixedPointCodec<true, pts::PositionRange>>(
          unit, linear(0.3), "p", "v")},
      kNone, false, {"p"}, "ufxpt8 P, fxpt8 v, no compression, file");
  add("uniform_velocity.vdb",
      {makeGrid<pts::NullCodec, pts::NullCodec>(a, linear(0.1), "particles", "particles_velocity", true)}, kBlosc,
      false, {"particles"}, "uniform particles_velocity (Mantaflow's name), blosc");
  add("uniform_velocity_zip.vdb",
      {makeGrid<pts::NullCodec, pts::TruncateCodec>(a, linear(0.1), "particles", "v", true)}, kZip, true, {"particles"},
      "uniform v, zip, stream");

  // Transforms: scale and translate, and an affine map (rotation).
  auto shifted = linear(0.1);
  shifted->postTranslate(openvdb::Vec3d(3.5, -2.25, 100.0));
  add("scale_translate.vdb", {makeGrid<pts::NullCodec, pts::NullCodec>(a, shifted, "particles", "v")}, kBlosc, false,
      {"particles"}, "scale and translate transform");
  auto rotated = linear(0.1);
  rotated->preRotate(0.3, openvdb::math::Y_AXIS);
  rotated->postTranslate(openvdb::Vec3d(1, 2, 3));
  add("affine.vdb", {makeGrid<pts::NullCodec, pts::NullCodec>(a, rotated, "particles", "v")}, kBlosc, false,
      {"particles"}, "affine transform");
  auto nonUniform =
      std::make_shared<Transform>(std::make_shared<openvdb::math::ScaleMap>(openvdb::Vec3d(0.1, 0.2, 0.05)));
  add("scale_map.vdb", {makeGrid<pts::NullCodec, pts::NullCodec>(a, nonUniform, "particles", "")}, kBlosc, false,
      {"particles"}, "non-uniform scale transform");

  // Several grids, one of them not points; half-float; empty.
  const Points b = squeeze(randomPoints(count(700), 0.5f, false, 3));
  auto density = openvdb::FloatGrid::create(0.0f);
  density->setName("density");
  density->tree().setValue(openvdb::Coord(1, 2, 3), 1.5f);
  density->tree().setValue(compact ? openvdb::Coord(10, 20, 3) : openvdb::Coord(100, -20, 3), 2.5f);
  auto halfGrid = makeGrid<pts::NullCodec, pts::NullCodec>(b, linear(0.05), "half", "v");
  halfGrid->setSaveFloatAsHalf(true);
  add("three_grids.vdb", {makeGrid<pts::NullCodec, pts::NullCodec>(a, linear(0.1), "flip", "v"), density, halfGrid},
      kBlosc, false, {"flip", "half"}, "two point grids around a float grid, file with offsets");
  add("stream_float_last.vdb",
      {makeGrid<pts::NullCodec, pts::NullCodec>(a, linear(0.1), "flip", "v"),
       makeGrid<pts::NullCodec, pts::NullCodec>(b, linear(0.05), "spray", "v"), density},
      kBlosc, true, {"flip", "spray"}, "two point grids, then a float grid, stream");
  files.back().unreadTail = true;
  add("empty_grid.vdb", {makeGrid<pts::NullCodec, pts::NullCodec>(Points{}, linear(0.1), "particles", "v")}, kBlosc,
      false, {"particles"}, "empty point grid");
  add("empty_and_full.vdb",
      {makeGrid<pts::NullCodec, pts::NullCodec>(Points{}, linear(0.1), "nothing", "v"),
       makeGrid<pts::NullCodec, pts::NullCodec>(b, linear(0.1), "particles", "v")},
      kBlosc, true, {"nothing", "particles"}, "an empty and a full point grid, stream");

  if (large) {
    // 120k points in one voxel: one leaf whose P array (1.4 MB) is a page of its own.
    Points dense;
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> inVoxel(0.01f, 0.09f);
    for (int i = 0; i < 120000; ++i) {
      dense.positions.emplace_back(inVoxel(rng), inVoxel(rng), inVoxel(rng));
      dense.velocities.emplace_back(inVoxel(rng), 0.f, 1.f);
    }
    add("big_leaf.vdb", {makeGrid<pts::NullCodec, pts::NullCodec>(dense, linear(0.1), "particles", "v")}, kBlosc, false,
        {"particles"}, "one leaf larger than a page");
    // 200k points: P spans several 1 MiB pages.
    const Points many = randomPoints(200000, 5.0f, false, 5);
    add("many_pages.vdb", {makeGrid<pts::NullCodec, pts::NullCodec>(many, linear(0.05), "particles", "v")}, kBlosc,
        true, {"particles"}, "many leaves over several pages, stream");
  }
  return files;
}

}  // namespace flipscope::testing
