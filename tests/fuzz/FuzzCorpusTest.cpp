// Writes the fuzz seed corpus: small valid inputs for every target (FuzzTargets.h), made by
// flipscope itself (particle writers, `flipscope synth` and `convert`, encodeBrick, saveCamera),
// by OpenVDB in every way it writes points (tests/preprocess/VdbTestFiles.h), and the Mantaflow
// sample. Skipped unless asked:
//   FLIPSCOPE_WRITE_FUZZ_CORPUS=$PWD/tests/fuzz/corpus build/tests/test_fuzz --gtest_filter=FuzzCorpus.Write
// FuzzCorpus.EverySeedIsAccepted (FuzzRegressionTest.cpp) then checks the seeds.
#include <gtest/gtest.h>

#include <zstd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

#include "FuzzTargets.h"
#include "TestSupport.h"
#include "preprocess/BgeoTestWriter.h"
#include "preprocess/ClassicBgeoTestWriter.h"
#include "preprocess/GzipTestWriter.h"
#include "preprocess/PdbTestWriter.h"
#include "preprocess/PrtTestWriter.h"
#include "preprocess/RealFlowTestWriter.h"
#include "preprocess/VdbTestFiles.h"
#include "preprocess/VtkTestWriter.h"
#include "preprocess/particles/ParticleWriter.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;

void writeSeed(const fs::path& path, std::span<const std::byte> bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}
void writeSeed(const fs::path& path, const std::string& text) {
  writeSeed(path, std::as_bytes(std::span(text.data(), text.size())));
}
std::vector<std::byte> bytesOf(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto bytes = std::as_bytes(std::span(text.data(), text.size()));
  return {bytes.begin(), bytes.end()};
}

/// `count` particles in [0, 1)^3, velocities in [-2, 2)^3, seeded.
ParticleChunk particles(std::size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.f, 1.f), speed(-2.f, 2.f);
  ParticleChunk chunk;
  for (std::size_t i = 0; i < count; ++i) {
    chunk.positions.emplace_back(unit(rng), unit(rng), unit(rng));
    chunk.velocities.emplace_back(speed(rng), speed(rng), speed(rng));
  }
  return chunk;
}

void writeParticles(const fs::path& path, const ParticleChunk& chunk, const WriteOptions& options) {
  auto writer = createParticleWriter(path, options);
  ParticleChunk copy = chunk;
  if (!options.velocity) copy.velocities.clear();
  writer->write(copy);
  writer->commit();
}

TEST(FuzzCorpus, Write) {
  const char* out = std::getenv("FLIPSCOPE_WRITE_FUZZ_CORPUS");
  if (!out) GTEST_SKIP() << "set FLIPSCOPE_WRITE_FUZZ_CORPUS to the corpus folder to write it";
  const fs::path corpus = out;
  for (const fuzz::Target& target : fuzz::kTargets) {
    fs::remove_all(corpus / target.name);
    fs::create_directories(corpus / target.name);
  }
  testing::TempDir tmp("fuzz-corpus");

  // Particle files.
  for (bool velocity : {false, true}) {
    WriteOptions options;
    options.velocity = velocity;
    const std::string v = velocity ? "_v" : "";
    for (auto [encoding, name] : {std::pair{PlyEncoding::Ascii, "ascii"},
                                  {PlyEncoding::BinaryLittleEndian, "le"},
                                  {PlyEncoding::BinaryBigEndian, "be"}}) {
      options.plyEncoding = encoding;
      writeParticles(corpus / "ply" / (std::string(name) + v + ".ply"), particles(40, 1), options);
    }
    writeParticles(corpus / "vdb_points" / ("flipscope" + v + ".vdb"), particles(60, 2), options);
  }
  writeParticles(corpus / "raw" / "particles.bin", particles(80, 3), WriteOptions{});
  writeSeed(corpus / "raw" / "one.bin", std::string(12, '\0'));
  writeSeed(corpus / "ply" / "types.ply",
            "ply\nformat ascii 1.0\ncomment every scalar type\nelement vertex 3\nproperty double x\n"
            "property int y\nproperty uchar z\nproperty short nx\nproperty float vx\nproperty float vy\n"
            "property float vz\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
            "0.5 1 2 -3 0.25 1e-3 -7\n-1e30 -2147483648 255 32767 0 0 0\n+3.25 0 0 0 1 2 3\n3 0 1 2\n");
  writeSeed(corpus / "ply" / "double_be.ply",
            std::string("ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty double x\nproperty double y\n"
                        "property double z\nend_header\n") +
                std::string("\x3f\xf0\0\0\0\0\0\0\x40\0\0\0\0\0\0\0\xc0\x08\0\0\0\0\0\0", 24));

  // VTK legacy and XML files (tests/preprocess/VtkTestWriter.h): every data format, small.
  {
    using testing::VtkTestArray;
    using Kind = VtkTestArray::Kind;
    const std::size_t n = 12;
    const auto xyz = testing::vtkTestPositions(n, 4);
    const std::vector<VtkTestArray> splash = {testing::vtkTestArray("id", ValueType::UInt32, 1, n, 5, Kind::Scalars),
                                              testing::vtkTestArray("velocity", ValueType::Float32, 3, n, 6)};
    testing::LegacyVtkOptions legacy;
    legacy.title = "SPlisHSPlasH particle data";
    writeSeed(corpus / "vtk" / "binary_splash.vtk", testing::legacyVtk(xyz, splash, legacy));
    std::vector<VtkTestArray> kinds = {
        testing::vtkTestArray("density", ValueType::Float64, 1, n, 7, Kind::Scalars),
        testing::vtkTestArray("v", ValueType::Float32, 3, n, 8, Kind::Vectors),
        testing::vtkTestArray("n", ValueType::Int16, 3, n, 9, Kind::Normals),
        testing::vtkTestArray("uv", ValueType::Float32, 2, n, 10, Kind::TextureCoordinates),
        testing::vtkTestArray("big", ValueType::Int64, 1, n, 11),
        testing::vtkTestArray("tag", ValueType::Int8, 2, n, 12)};
    VtkTestArray flags = testing::vtkTestArray("flags", ValueType::UInt8, 1, n, 13);
    for (double& v : flags.values) v = double(int(v) & 1);
    flags.legacyTypeName = "bit";
    kinds.push_back(flags);
    VtkTestArray longs = testing::vtkTestArray("longs", ValueType::Int64, 1, n, 14);
    longs.legacyTypeName = "long";
    kinds.push_back(longs);
    legacy.title = "every kind";
    legacy.polydata = true;
    legacy.datasetField = true;
    writeSeed(corpus / "vtk" / "binary_polydata_kinds.vtk", testing::legacyVtk(xyz, kinds, legacy));
    legacy.binary = false;
    writeSeed(corpus / "vtk" / "ascii_polydata_kinds.vtk", testing::legacyVtk(xyz, kinds, legacy));
    testing::LegacyVtkOptions v5;
    v5.version = "5.1";
    v5.metadata = true;
    v5.cellData = true;
    v5.pointType = ValueType::Float64;
    writeSeed(corpus / "vtk" / "binary_v5_cells.vtk", testing::legacyVtk(xyz, splash, v5));
    v5.binary = false;
    writeSeed(corpus / "vtk" / "ascii_v5_cells.vtk", testing::legacyVtk(xyz, splash, v5));

    using Data = testing::VtuOptions::Data;
    struct Variant {
      const char* name;
      Data data;
      bool zlib, header64, bigEndian, polyData;
      int pieces;
    };
    for (const Variant& v : {Variant{"ascii.vtu", Data::Ascii, false, false, false, false, 1},
                             Variant{"binary.vtu", Data::Binary, false, false, false, false, 1},
                             Variant{"binary_zlib.vtu", Data::Binary, true, false, false, false, 2},
                             Variant{"appended_raw.vtu", Data::AppendedRaw, false, true, false, false, 1},
                             Variant{"appended_raw_zlib.vtu", Data::AppendedRaw, true, false, true, false, 1},
                             Variant{"appended_base64_zlib.vtp", Data::AppendedBase64, true, true, false, true, 2},
                             Variant{"appended_base64.vtp", Data::AppendedBase64, false, false, true, true, 1}}) {
      testing::VtuOptions options;
      options.data = v.data;
      options.zlib = v.zlib;
      options.header64 = v.header64;
      options.bigEndian = v.bigEndian;
      options.polyData = v.polyData;
      options.pieces = v.pieces;
      options.blockSize = 100;
      options.pointType = v.bigEndian ? ValueType::Float64 : ValueType::Float32;
      writeSeed(corpus / "vtu" / v.name, testing::vtu(xyz, splash, options));
    }
  }

  // Houdini: a few real files (also in tests/data), and synthetic ones (BgeoTestWriter.h): pages
  // of 8 points, packing 3+1 with a constant w, constant pages, tuples, arrays, every encoding.
  const fs::path formats = fs::path(FLIPSCOPE_DATA_DIR) / "formats";
  for (const char* name :
       {"points_noprim_15.bgeo", "points_noprim_15.geo", "simple_partanim.0017.bgeo", "simple_partanim.0017.geo"})
    fs::copy_file(formats / "houdini-modern" / name, corpus / "bgeo" / name);
  for (const char* name : {"labs_star.1.bgeo.sc", "labs_wfc.1.bgeo.sc"})
    fs::copy_file(formats / "houdini-bgeo-sc" / name, corpus / "bgeo_sc" / name);
  namespace bgeo = testing::bgeo;
  for (bool uniform : {true, false}) {
    bgeo::Geometry g;
    g.points = 50;
    g.tokenStrings = uniform;
    auto add = [&](const char* name, const char* storage, int arity, bgeo::Layout layout,
                   std::function<double(std::uint64_t, int)> value) {
      bgeo::Attribute a;
      a.name = name;
      a.storage = storage;
      a.arity = arity;
      a.layout = layout;
      a.pageSize = 8;
      a.uniform = uniform;
      a.value = std::move(value);
      g.attributes.push_back(std::move(a));
    };
    add("P", "fpreal32", 4, bgeo::Layout::Paged, [](std::uint64_t p, int c) { return c == 3 ? 1.0 : 0.1 * double(p) + c; });
    g.attributes.back().packing = {3, 1};
    add("v", "fpreal64", 3, bgeo::Layout::Tuples, [](std::uint64_t p, int c) { return double(p % 5) - c; });
    add("pscale", "fpreal16", 1, bgeo::Layout::Paged, [](std::uint64_t p, int) { return p < 16 ? 0.5 : 0.25; });
    add("id", "int32", 1, bgeo::Layout::Arrays, [](std::uint64_t p, int) { return double(p); });
    const std::string binary = bgeo::geometryBytes(g, bgeo::Encoding::Binary);
    const std::string v = uniform ? "uniform" : "tokens";
    writeSeed(corpus / "bgeo" / ("synthetic_" + v + ".bgeo"), binary);
    if (uniform) {
      writeSeed(corpus / "bgeo" / "synthetic.geo", bgeo::geometryBytes(g, bgeo::Encoding::Ascii));
      writeSeed(corpus / "bgeo_sc" / "synthetic_chunks.bgeo.sc", bgeo::scfContainer(binary, 700));
    }
  }

  // Houdini classic geometry, Krakatoa PRT, RealFlow .bin, Maya .pdb: small real files and the test
  // writers' files with every feature; gzip: some of each gzipped, one in two members.
  for (const char* name : {"test.bgeo", "test.geo", "base.bgeo", "scatter.bgeo"})
    writeSeed(corpus / "classic_bgeo" / name, bytesOf(formats / "houdini-classic" / name));
  const std::vector<testing::BgeoAttributeSpec> bgeoAttributes = {
      {"v", 5, 3, {}}, {"id", 1, 1, {}}, {"name", 4, 1, {"a", "b"}}, {"uv", 0, 2, {}}};
  auto bgeoPosition = [](std::size_t p, int c) { return float(p) * 0.5f + float(c); };
  auto bgeoValue = [](std::size_t p, std::size_t a, int c) { return double(p % 2) + double(a) + c * 0.25; };
  const std::string writtenBgeo = testing::makeClassicBgeo(6, bgeoAttributes, bgeoPosition, bgeoValue, {true, true});
  writeSeed(corpus / "classic_bgeo" / "written.bgeo", writtenBgeo);
  writeSeed(corpus / "classic_bgeo" / "written.geo",
            testing::makeClassicGeo(6, bgeoAttributes, bgeoPosition, bgeoValue, {true, true}));
  writeSeed(corpus / "prt" / "fractal.prt", bytesOf(formats / "krakatoa-prt" / "prt_fractal_for_krscene.prt"));
  std::vector<testing::PrtChannelSpec> prtChannels = {{"Position", testing::PrtType::Float16, 3},
                                                      {"Velocity", testing::PrtType::Float64, 3}};
  for (int type = 0; type <= 10; ++type)
    prtChannels.push_back({"c" + std::to_string(type), testing::PrtType(type), 1 + type % 4});
  auto prtValue = [](std::size_t p, std::size_t i, int c) { return double((p + i + std::size_t(c)) % 50); };
  const std::string typesPrt = testing::makePrt(prtChannels, 12, prtValue, {.piece = 100});
  writeSeed(corpus / "prt" / "types.prt", typesPrt);
  writeSeed(corpus / "prt" / "unknown_count.prt",
            testing::makePrt({{"Position", testing::PrtType::Float32, 3}}, 9, prtValue, {.version = 1, .unknownCount = true}));
  for (const char* name : {"Circle01_00000.bin", "Circle01_00001.bin"})
    writeSeed(corpus / "realflow_bin" / name, bytesOf(formats / "realflow-bin" / name));
  const std::string v12 = testing::makeRealFlowBin(12, 3);
  writeSeed(corpus / "realflow_bin" / "v12.bin", v12);
  writeSeed(corpus / "realflow_bin" / "v9.bin", testing::makeRealFlowBin(9, 2, testing::kRealFlowTail5));
  writeSeed(corpus / "realflow_bin" / "v4.bin", testing::makeRealFlowBin(4, 2, ""));
  writeSeed(corpus / "pdb" / "test.pdb", bytesOf(formats / "maya-pdb" / "test.pdb"));
  const std::string writtenPdb = testing::makePdb(
      {{"position", 1, 3}, {"velocity", 1, 3}, {"life", 2, 2}, {"id", 3, 1}, {"flags", 4, 1}, {"owner", 5, 1}}, 5,
      true);
  writeSeed(corpus / "pdb" / "every_type_64.pdb", writtenPdb);
  auto text = [](const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  writeSeed(corpus / "gzip" / "test.bgeo.gz", testing::gzip(text(formats / "houdini-classic" / "test.bgeo")));
  writeSeed(corpus / "gzip" / "le_v.ply.gz", testing::gzip(text(corpus / "ply" / "le_v.ply"), 2));
  writeSeed(corpus / "gzip" / "types.prt.gz", testing::gzip(typesPrt));
  writeSeed(corpus / "gzip" / "v12.bin.gz", testing::gzip(v12));
  writeSeed(corpus / "gzip" / "every_type_64.pdb.gz", testing::gzip(writtenPdb));
  writeSeed(corpus / "gzip" / "written.bgeo.gz.gz", testing::gzip(testing::gzip(writtenBgeo)));

  // OpenVDB files: every codec, compression and layout (compact: a few KB each), and Mantaflow.
  // (Not the uncompressed ones: 158 KB of internal node values, and libFuzzer's -max_len follows
  // the largest seed.)
  for (const auto& file : testing::vdbTestFiles(tmp.path(), 0.02, false, true))
    if (fs::file_size(file.path) < 64 * 1024) fs::copy_file(file.path, corpus / "vdb_points" / file.path.filename());
  const fs::path mantaflow = fs::path(FLIPSCOPE_DATA_DIR) / "mantaflow-dam64" / "particles";
  for (const char* name : {"fluid_particles_0001.vdb", "fluid_particles_0002.vdb"})
    fs::copy_file(mantaflow / name, corpus / "vdb_points" / ("mantaflow_" + std::string(name)));

  // Stores: flipscope synth and convert, with and without the speed attribute, two brick sizes.
  ASSERT_EQ(testing::runFlipscope("synth -o s.ply --particles 1k --velocity", tmp.path()).exitCode, 0);
  struct Store {
    const char* name;
    std::string options;
  };
  // And Blender Mantaflow's FLIP and secondary files: a store with particle kinds.
  const std::string flipAndSecondary = "'" + (mantaflow.parent_path() / "data" / "fluid_data_0030.vdb").string() +
                                       "' '" + (mantaflow / "fluid_particles_0030.vdb").string() + "'";
  // A version 6 store too (its attribute values as they are, AttributeCoding::Values): the
  // header of speed32 at version 6, appended to.
  for (const Store& store : {Store{"speed32", "s.ply --resolution 24 --brick-size 32"},
                             Store{"none64", "s.ply --resolution 48 --brick-size 64 --attribute none"},
                             Store{"kinds32", flipAndSecondary + " --resolution 24 --brick-size 32 --attribute none"},
                             Store{"speed32_v6", "s.ply --append"}}) {
    if (std::string(store.name) == "speed32_v6") {
      StoreHeader v6 = parseStoreHeader(bytesOf(tmp / "speed32" / kStoreHeaderName), "speed32");
      v6.version = 6;
      fs::create_directories(tmp / store.name);
      writeSeed(tmp / store.name / kStoreHeaderName, serializeStoreHeader(v6));
    }
    const auto run =
        testing::runFlipscope("convert " + store.options + " -o " + store.name + " -q", tmp.path());
    ASSERT_EQ(run.exitCode, 0) << run.output;
    const auto header = bytesOf(tmp / store.name / kStoreHeaderName);
    writeSeed(corpus / "store_header" / (std::string(store.name) + ".fsh"), header);
    for (const auto& entry : fs::directory_iterator(tmp / store.name)) {
      if (entry.path().extension() != ".fsf") continue;
      const auto frame = bytesOf(entry.path());
      std::vector<std::byte> seed(4);
      const auto length = std::uint32_t(header.size());
      std::memcpy(seed.data(), &length, 4);
      seed.insert(seed.end(), header.begin(), header.end());
      seed.insert(seed.end(), frame.begin(), frame.end());
      writeSeed(corpus / "frame_index" / (std::string(store.name) + ".seed"), seed);
    }
  }

  // Brick payloads: random bricks of each size, with and without attributes (and kinds), in both
  // forms: the fuzz target's 9-byte prefix (particles, cells, flags), then the payload.
  const auto writePayloadSeeds = [&](const DecodedBrick& brick, std::uint32_t sizeIndex, std::uint8_t flags,
                                     const std::string& name) {
    const std::vector<std::byte> payload =
        encodeBrick(brick, 3, flags & 32 ? AttributeCoding::Values : AttributeCoding::CellDeltas);
    for (bool rawForm : {false, true}) {
      std::vector<std::byte> body = payload;
      if (rawForm) {
        body.resize(ZSTD_getFrameContentSize(payload.data(), payload.size()));
        ASSERT_EQ(ZSTD_decompress(body.data(), body.size(), payload.data(), payload.size()), body.size());
      }
      std::vector<std::byte> seed(9);
      const auto particles = std::uint32_t(brick.particleCount()), occupied = std::uint32_t(brick.cells.size());
      std::memcpy(seed.data(), &particles, 4);
      std::memcpy(seed.data() + 4, &occupied, 4);
      seed[8] = std::byte(std::uint8_t(flags | sizeIndex << 1 | (rawForm ? 8 : 0)));
      seed.insert(seed.end(), body.begin(), body.end());
      writeSeed(corpus / "brick_payload" / (name + (rawForm ? "_raw" : "") + ".seed"), seed);
    }
  };
  std::mt19937 rng(7);
  for (std::uint32_t sizeIndex = 0; sizeIndex < 3; ++sizeIndex)
    for (bool attribute : {false, true}) {
      const std::uint32_t brickSize = 32u << sizeIndex, cells = brickSize * brickSize * brickSize;
      DecodedBrick brick;
      for (std::uint32_t cell = std::uint32_t(rng() % 50); cell < cells; cell += 1 + std::uint32_t(rng() % 3000)) {
        brick.cells.push_back(cell);
        brick.counts.push_back(1 + std::uint32_t(rng() % (sizeIndex == 0 ? 200 : 9)));
        for (std::uint32_t i = 0; attribute && i < brick.counts.back(); ++i)
          brick.attributes.push_back(std::uint16_t(rng()));
      }
      writePayloadSeeds(brick, sizeIndex, attribute ? 1 : 0,
                        "b" + std::to_string(brickSize) + (attribute ? "_speed" : ""));
    }

  // Brick payloads with a kind per cell (flag 16; a generator of their own, so that the seeds
  // above stay as they are).
  std::mt19937 kindRng(13);
  for (std::uint32_t sizeIndex = 0; sizeIndex < 2; ++sizeIndex)
    for (bool attribute : {false, true}) {
      const std::uint32_t brickSize = 32u << sizeIndex, cells = brickSize * brickSize * brickSize;
      DecodedBrick brick;
      for (std::uint32_t cell = kindRng() % 50; cell < cells; cell += 1 + std::uint32_t(kindRng() % 3000)) {
        brick.cells.push_back(cell);
        brick.counts.push_back(1 + std::uint32_t(kindRng() % 9));
        brick.kinds.push_back(kindRng() % 2 ? ParticleKind::Liquid : ParticleKind(kindRng() % kParticleKindCount));
        for (std::uint32_t i = 0; attribute && i < brick.counts.back(); ++i)
          brick.attributes.push_back(std::uint16_t(kindRng()));
      }
      writePayloadSeeds(brick, sizeIndex, std::uint8_t((attribute ? 1 : 0) | 16),
                        "b" + std::to_string(brickSize) + (attribute ? "_speed" : "") + "_kinds");
    }

  // Brick payloads whose attribute values are laid out as versions 3 to 6 lay them out (flag 32,
  // AttributeCoding::Values).
  std::mt19937 valuesRng(19);
  for (std::uint32_t sizeIndex = 0; sizeIndex < 2; ++sizeIndex) {
    DecodedBrick brick;
    const std::uint32_t brickSize = 32u << sizeIndex, cells = brickSize * brickSize * brickSize;
    for (std::uint32_t cell = valuesRng() % 50; cell < cells; cell += 1 + std::uint32_t(valuesRng() % 3000)) {
      brick.cells.push_back(cell);
      brick.counts.push_back(1 + std::uint32_t(valuesRng() % 9));
      for (std::uint32_t i = 0; i < brick.counts.back(); ++i) brick.attributes.push_back(std::uint16_t(valuesRng()));
    }
    writePayloadSeeds(brick, sizeIndex, 1 | 32, "b" + std::to_string(brickSize) + "_speed_values");
  }

  // Cameras.
  saveCamera(corpus / "camera" / "full.json", Camera{{2, 1.5, 3}, {0.5, 0.2, 0.5}, {0, 1, 0}, 35});
  saveCamera(corpus / "camera" / "z_up.json", Camera{{-4e3, 2e-3, 10}, {0, 0, 0}, {0, 0, 1}, 90});
  writeSeed(corpus / "camera" / "minimal.json", std::string(R"({"eye": [0, 0, 5], "target": [0, 0, 0]})"));
  writeSeed(corpus / "camera" / "spaced.json",
            std::string("{\n  \"fov\" : 1.5e1 , \"up\":[1,0,0],\n  \"eye\":[-1,-2.5,-3], \"target\":[1e0,2,3]}\n"));
}

}  // namespace
}  // namespace flipscope
