// The scene's up axis (store version 6, StoreHeader::upAxis): what the input files' conventions
// say (Blender's fluid caches z, Houdini, RealFlow and Maya y, others nothing), what `--up` asks,
// what an append keeps, and the store header's field, round trip and damage.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

#include "ParticleTestSupport.h"
#include "TestSupport.h"
#include "core/Hash.h"
#include "preprocess/Convert.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

const fs::path kData = FLIPSCOPE_DATA_DIR;
const fs::path kMantaflowFlip = testing::mantaflowFile("data", "fluid_data_0030.vdb");
const fs::path kMantaflowSecondary = testing::mantaflowFile("particles", "fluid_particles_0030.vdb");

fs::path writePly(const fs::path& path) {
  testing::writeBytes(path,
                      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                      "property float z\nend_header\n0.5 0.5 0.5\n1.5 0.5 0.5\n2.5 3.5 1.5\n");
  return path;
}

ConvertOptions quiet() {
  ConvertOptions options;
  options.progress = Progress::Mode::Silent;
  options.resolution = 16;
  return options;
}

TEST(UpAxis, FilesSayWhatTheirConventionsImply) {
  EXPECT_EQ(openParticleFile(kMantaflowFlip)->upAxis(), UpAxis::Z);
  EXPECT_EQ(openParticleFile(kMantaflowSecondary)->upAxis(), UpAxis::Z);
  EXPECT_EQ(openParticleFile(kData / "formats" / "houdini-classic" / "test.bgeo")->upAxis(), UpAxis::Y);
  EXPECT_EQ(openParticleFile(kData / "formats" / "houdini-bgeo-sc" / "labs_star.1.bgeo.sc")->upAxis(), UpAxis::Y);
  EXPECT_EQ(openParticleFile(kData / "formats" / "realflow-bin" / "Circle01_00000.bin")->upAxis(), UpAxis::Y);
  EXPECT_EQ(openParticleFile(kData / "formats" / "maya-pdb" / "test.pdb")->upAxis(), UpAxis::Y);
  TempDir dir("up-axis-files");
  EXPECT_EQ(openParticleFile(writePly(dir / "a.ply"))->upAxis(), UpAxis::Unknown);
}

TEST(UpAxis, ConvertRecordsTheFilesAxisOrTheOneAskedFor) {
  TempDir dir("up-axis-convert");
  ConvertReport report = convert({{0, {kMantaflowFlip, kMantaflowSecondary}}}, dir / "dam", quiet());
  EXPECT_EQ(report.header.upAxis, UpAxis::Z);
  EXPECT_NE(report.upAxisOrigin.find("fluid_data_0030.vdb"), std::string::npos) << report.upAxisOrigin;
  EXPECT_EQ(BrickStore::open(dir / "dam").header().upAxis, UpAxis::Z);
  EXPECT_EQ(BrickStore::open(dir / "dam").header().version, kStoreVersion);

  const fs::path ply = writePly(dir / "a.ply");
  EXPECT_EQ(convert({{0, {ply}}}, dir / "plain", quiet()).header.upAxis, UpAxis::Unknown);
  ConvertOptions asked = quiet();
  asked.upAxis = UpAxis::X;
  report = convert({{0, {ply}}}, dir / "asked", asked);
  EXPECT_EQ(report.upAxisOrigin, "--up");
  EXPECT_EQ(BrickStore::open(dir / "asked").header().upAxis, UpAxis::X);

  // Files that disagree: the first file's, with a warning naming both.
  report =
      convert({{0, {kData / "formats" / "houdini-classic" / "test.bgeo", kMantaflowFlip}}}, dir / "mixed", quiet());
  EXPECT_EQ(report.header.upAxis, UpAxis::Y);
  ASSERT_FALSE(report.warnings.empty());
  EXPECT_NE(report.warnings.back().find("disagree on the up axis"), std::string::npos) << report.warnings.back();
  EXPECT_NE(report.warnings.back().find("fluid_data_0030.vdb is z up"), std::string::npos) << report.warnings.back();
}

TEST(UpAxis, AnAppendKeepsTheStoresAxisAndRefusesAnother) {
  TempDir dir("up-axis-append");
  const fs::path ply = writePly(dir / "a.ply");
  ConvertOptions options = quiet();
  options.upAxis = UpAxis::Z;
  convert({{0, {ply}}}, dir / "store", options);
  // The files say nothing; the store keeps z.
  const ConvertReport kept = convert({{1, {ply}}}, dir / "store", quiet());
  EXPECT_EQ(kept.header.upAxis, UpAxis::Z);
  EXPECT_EQ(kept.upAxisOrigin, "the existing store");
  options.upAxis = UpAxis::Y;
  try {
    convert({{2, {ply}}}, dir / "store", options);
    FAIL() << "appended with another up axis";
  } catch (const InputError& e) {
    EXPECT_NE(
        std::string(e.what()).find("records z up (store version " + std::to_string(kStoreVersion) + "), not y (--up)"),
        std::string::npos)
        << e.what();
  }
  EXPECT_EQ(BrickStore::open(dir / "store").frames(), (std::vector<int>{0, 1}));
}

TEST(UpAxis, VersionFiveStoresAreAppendedToWithoutOne) {
  TempDir dir("up-axis-v5");
  const fs::path ply = writePly(dir / "a.ply");
  ConvertOptions options = quiet();
  options.cellSize = 1;
  options.domain = Box{{0, 0, 0}, {4, 4, 4}};
  StoreHeader header = makeStoreHeader(*options.domain, options);
  header.version = 5;
  header.id = randomStoreId();
  fs::create_directories(dir / "store");
  const auto bytes = serializeStoreHeader(header);
  testing::writeBytes(dir / "store" / kStoreHeaderName,
                      std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  // A Blender file appended to it: the store stays version 5, with no up axis.
  options.append = true;  // (a store without frames is otherwise started anew)
  const ConvertReport report = convert({{0, {kMantaflowFlip}}}, dir / "store", options);
  options.append = false;
  EXPECT_EQ(report.header.version, 5u);
  EXPECT_EQ(report.header.upAxis, UpAxis::Unknown);
  const BrickStore store = BrickStore::open(dir / "store");
  EXPECT_EQ(store.header().version, 5u);
  EXPECT_EQ(store.header().upAxis, UpAxis::Unknown);
  EXPECT_EQ(store.frames(), std::vector<int>{0});
  options.upAxis = UpAxis::Z;
  EXPECT_THROW(convert({{1, {ply}}}, dir / "store", options), InputError);
}

TEST(UpAxis, StoreHeaderFieldRoundTripsAndAnUnknownValueIsRefused) {
  StoreHeader h;
  h.cellSize = 1;
  h.brickGrid = {1, 1, 1};
  for (UpAxis axis : {UpAxis::Unknown, UpAxis::X, UpAxis::Y, UpAxis::Z}) {
    h.upAxis = axis;
    EXPECT_EQ(parseStoreHeader(serializeStoreHeader(h), "store.fsh").upAxis, axis);
  }
  // Version 5 has no field: four bytes shorter, read back as unknown.
  h.upAxis = UpAxis::Unknown;
  StoreHeader v5 = h;
  v5.version = 5;
  EXPECT_EQ(serializeStoreHeader(v5).size() + 4, serializeStoreHeader(h).size());
  EXPECT_EQ(parseStoreHeader(serializeStoreHeader(v5), "store.fsh").upAxis, UpAxis::Unknown);
  // A value past z, with a valid checksum: named. The field lies before the run count and the
  // checksum (no frames).
  auto bytes = serializeStoreHeader(h);
  const std::uint32_t bad = 4;
  std::memcpy(bytes.data() + bytes.size() - 16, &bad, 4);
  const std::uint64_t sum = checksum64(std::span(bytes).first(bytes.size() - 8));
  std::memcpy(bytes.data() + bytes.size() - 8, &sum, 8);
  try {
    parseStoreHeader(bytes, "s/store.fsh");
    FAIL() << "accepted up axis 4";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("s/store.fsh"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("unknown up axis 4"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace flipscope
