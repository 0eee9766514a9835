// The VTK legacy reader (VtkLegacyParticles.cpp): the SPlisHSPlasH file of the real data, round
// trips of files written by VtkTestWriter.h in every variant (ASCII and BINARY, POLYDATA and
// UNSTRUCTURED_GRID, 4.x and 5.x cells, every array kind and type) over many chunks, datasets
// that are not particles, messages, and damage: every truncation and single-byte changes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>

#include "DamageTestSupport.h"
#include "ParticleTestSupport.h"
#include "VtkTestWriter.h"
#include "core/Elapsed.h"
#include "preprocess/particles/ParticleFormatRegistry.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;
using testing::bytesOf;
using testing::everyAttribute;
using testing::Everything;
using testing::expectFileError;
using testing::LegacyVtkOptions;
using testing::readEverything;
using testing::readsCompletely;
using testing::TempDir;
using testing::VtkTestArray;
using Kind = VtkTestArray::Kind;

// ---- The real file ----

TEST(VtkLegacyReader, SplishSplashBunny) {
  const fs::path path = fs::path(FLIPSCOPE_DATA_DIR) / "formats" / "vtk" / "bunny_frame_14_7705_particles.vtk";
  ASSERT_TRUE(fs::exists(path)) << path;
  auto source = openParticleFile(path, everyAttribute());
  EXPECT_EQ(source->format(), "VTK legacy 4.1 (binary, UNSTRUCTURED_GRID): 'SPlisHSPlasH particle data'");
  EXPECT_EQ(source->countHint(), 7706u);
  EXPECT_EQ(source->attributes(),
            (std::vector<AttributeDesc>{{"id", ValueType::UInt32, 1}, {"velocity", ValueType::Float32, 3}}));
  EXPECT_TRUE(source->hasVelocity());
  const Everything all = readEverything(*source, 1000);
  ASSERT_EQ(all.particles.size(), 7706u);
  EXPECT_EQ(all.particles.positions[0], glm::vec3(0.12854121625423431f, 0.8383985757827759f, 0.11624263226985931f));
  EXPECT_EQ(all.particles.positions[7705], glm::vec3(-0.19719751179218292f, 1.998595952987671f, -0.167732834815979f));
  EXPECT_EQ(all.particles.velocities[1], glm::vec3(-0.21234048902988434f, -1.5974106788635254f, 0.22138170897960663f));
  EXPECT_EQ(all.particles.velocities[7705], glm::vec3(-0.9889369010925293f, -2.328596353530884f, 0.9878049492835999f));
  ASSERT_EQ(all.columns.size(), 2u);
  EXPECT_EQ(all.columns[0][0], 4224.f);
  EXPECT_EQ(all.columns[0][1], 3602.f);
  EXPECT_EQ(all.columns[0][7705], 866.f);
  // The ids are a permutation of 0..7705.
  std::vector<float> ids = all.columns[0];
  std::sort(ids.begin(), ids.end());
  for (std::size_t i = 0; i < ids.size(); ++i) ASSERT_EQ(ids[i], float(i));
  EXPECT_EQ(all.columns[1][3], all.particles.velocities[1].x);
  // A second pass reads the same.
  source->rewind();
  EXPECT_EQ(readEverything(*source, 4096).particles.positions, all.particles.positions);
}

TEST(VtkLegacyReader, EveryRealFileReads) {
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(FLIPSCOPE_DATA_DIR) / "formats" / "vtk")) {
    auto source = openParticleFile(entry.path());
    const auto all = testing::readAll(*source, 5000);
    EXPECT_EQ(all.size(), source->countHint()) << entry.path();
    ++files;
  }
  EXPECT_GE(files, 1u);
}

// ---- Round trips ----

std::vector<VtkTestArray> legacyArrays(std::size_t n, bool binary) {
  std::vector<VtkTestArray> arrays = {
      testing::vtkTestArray("id", ValueType::UInt32, 1, n, 1, Kind::Scalars),
      testing::vtkTestArray("density", ValueType::Float32, 1, n, 2, Kind::Scalars),
      testing::vtkTestArray("Velocity", ValueType::Float32, 3, n, 3, Kind::Vectors),
      testing::vtkTestArray("Normals", ValueType::Float64, 3, n, 4, Kind::Normals),
      testing::vtkTestArray("uv", ValueType::Float32, 2, n, 5, Kind::TextureCoordinates),
      testing::vtkTestArray("pair", ValueType::Int16, 2, n, 6, Kind::Scalars),
      testing::vtkTestArray("mass", ValueType::Float64, 1, n, 7),
      testing::vtkTestArray("tag", ValueType::Int8, 1, n, 8),
      testing::vtkTestArray("big", ValueType::Int64, 1, n, 9),
      testing::vtkTestArray("ubig", ValueType::UInt64, 2, n, 10),
      testing::vtkTestArray("ushort", ValueType::UInt16, 1, n, 11),
      testing::vtkTestArray("int", ValueType::Int32, 4, n, 12),
      testing::vtkTestArray("uchar", ValueType::UInt8, 1, n, 13),
  };
  VtkTestArray color = testing::vtkTestArray("color", ValueType::UInt8, 4, n, 14, Kind::ColorScalars);
  if (!binary) {
    color.type = ValueType::Float32;
    for (double& v : color.values) v /= 256;
  }
  arrays.push_back(color);
  VtkTestArray flags = testing::vtkTestArray("flags", ValueType::UInt8, 1, n, 15);
  for (double& v : flags.values) v = double(int(v) & 1);
  flags.legacyTypeName = "bit";
  arrays.push_back(flags);
  VtkTestArray id = testing::vtkTestArray("vtk_id", ValueType::Int32, 1, n, 16);
  id.legacyTypeName = "vtkIdType";
  arrays.push_back(id);
  VtkTestArray longs = testing::vtkTestArray("longs", ValueType::Int64, 1, n, 17);
  longs.legacyTypeName = "long";
  arrays.push_back(longs);
  // The writer puts the FIELD arrays last, in one FIELD block.
  std::stable_partition(arrays.begin(), arrays.end(), [](const VtkTestArray& a) { return a.kind != Kind::Field; });
  return arrays;
}

void expectRoundTrip(const std::string& bytes, const std::vector<double>& xyz, const std::vector<VtkTestArray>& arrays,
                     const std::string& label, std::size_t chunkSize) {
  SCOPED_TRACE(label);
  auto source = openParticleBytes("round.vtk", bytesOf(bytes), everyAttribute());
  const std::size_t n = xyz.size() / 3;
  EXPECT_EQ(source->countHint(), n);
  const auto attributes = source->attributes();
  ASSERT_EQ(attributes.size(), arrays.size());
  for (std::size_t i = 0; i < arrays.size(); ++i) {
    EXPECT_EQ(attributes[i].name, arrays[i].name);
    EXPECT_EQ(attributes[i].arity, arrays[i].arity);
    EXPECT_EQ(attributes[i].type, arrays[i].type) << arrays[i].name;
  }
  for (int pass = 0; pass < 2; ++pass) {
    const Everything all = readEverything(*source, chunkSize);
    ASSERT_EQ(all.particles.size(), n);
    for (std::size_t i = 0; i < n; ++i)
      ASSERT_EQ(all.particles.positions[i], glm::vec3(float(xyz[3 * i]), float(xyz[3 * i + 1]), float(xyz[3 * i + 2])))
          << "particle " << i;
    ASSERT_EQ(all.columns.size(), arrays.size());
    for (std::size_t a = 0; a < arrays.size(); ++a) {
      ASSERT_EQ(all.columns[a].size(), arrays[a].values.size()) << arrays[a].name;
      for (std::size_t i = 0; i < arrays[a].values.size(); ++i)
        ASSERT_EQ(all.columns[a][i], float(arrays[a].values[i])) << arrays[a].name << " value " << i;
    }
    source->rewind();
  }
}

TEST(VtkLegacyReader, RoundTripsEveryVariant) {
  const std::size_t n = 5003;
  const auto xyz = testing::vtkTestPositions(n, 21);
  for (bool binary : {true, false})
    for (bool polydata : {false, true})
      for (const char* version : {"3.0", "4.2", "5.1"})
        for (ValueType pointType : {ValueType::Float32, ValueType::Float64}) {
          LegacyVtkOptions options;
          options.binary = binary;
          options.polydata = polydata;
          options.version = version;
          options.pointType = pointType;
          options.cellData = !polydata;
          options.datasetField = polydata;
          options.metadata = std::string(version) == "5.1";
          const auto arrays = legacyArrays(n, binary);
          const std::string label = std::string(binary ? "binary" : "ascii") + (polydata ? " POLYDATA " : " UG ") +
                                    version + (pointType == ValueType::Float64 ? " double" : " float");
          expectRoundTrip(testing::legacyVtk(xyz, arrays, options), xyz, arrays, label, 777);
        }
}

TEST(VtkLegacyReader, PointsOnlyAndNoCells) {
  const auto xyz = testing::vtkTestPositions(10, 22);
  for (bool binary : {true, false}) {
    LegacyVtkOptions options;
    options.binary = binary;
    options.polydata = true;
    options.cells = false;
    expectRoundTrip(testing::legacyVtk(xyz, {}, options), xyz, {}, binary ? "binary" : "ascii", 3);
  }
  // No points at all is a valid, empty file.
  LegacyVtkOptions options;
  const std::string empty = testing::legacyVtk({}, {}, options);  // outlives the source
  auto source = openParticleBytes("empty.vtk", bytesOf(empty));
  ParticleChunk chunk;
  EXPECT_FALSE(source->read(chunk, 10));
  EXPECT_EQ(source->countHint(), 0u);
}

TEST(VtkLegacyReader, VelocityByName) {
  const std::size_t n = 50;
  const auto xyz = testing::vtkTestPositions(n, 23);
  for (const char* name : {"velocity", "Velocities", "V", "vel", "VELOCITY"}) {
    auto v = testing::vtkTestArray(name, ValueType::Float32, 3, n, 24, Kind::Vectors);
    auto other = testing::vtkTestArray("w", ValueType::Float32, 3, n, 25, Kind::Vectors);
    const std::string bytes = testing::legacyVtk(xyz, {other, v}, LegacyVtkOptions{});
    auto source = openParticleBytes("v.vtk", bytesOf(bytes));
    ASSERT_TRUE(source->hasVelocity()) << name;
    const auto all = testing::readAll(*source, 7);
    ASSERT_EQ(all.velocities.size(), n);
    EXPECT_EQ(all.velocities[9], glm::vec3(float(v.values[27]), float(v.values[28]), float(v.values[29])));
    ReadOptions without;
    without.velocity = false;
    EXPECT_FALSE(openParticleBytes("v.vtk", bytesOf(bytes), without)->hasVelocity());
  }
  // 'velocity' is preferred over 'v'; a scalar 'v' is no velocity.
  auto v = testing::vtkTestArray("v", ValueType::Float32, 3, n, 26, Kind::Vectors);
  auto velocity = testing::vtkTestArray("velocity", ValueType::Float64, 3, n, 27);
  const std::string both = testing::legacyVtk(xyz, {v, velocity}, LegacyVtkOptions{});  // outlives the source
  auto source = openParticleBytes("v.vtk", bytesOf(both));
  EXPECT_EQ(testing::readAll(*source, 100).velocities[0],
            glm::vec3(velocity.values[0], velocity.values[1], velocity.values[2]));
  auto scalar = testing::vtkTestArray("v", ValueType::Float32, 1, n, 28, Kind::Scalars);
  EXPECT_FALSE(
      openParticleBytes("v.vtk", bytesOf(testing::legacyVtk(xyz, {scalar}, LegacyVtkOptions{})))->hasVelocity());
}

TEST(VtkLegacyReader, SelectedAttributesInTheOrderAsked) {
  const std::size_t n = 30;
  const auto xyz = testing::vtkTestPositions(n, 29);
  auto a = testing::vtkTestArray("a", ValueType::Float32, 1, n, 30, Kind::Scalars);
  auto b = testing::vtkTestArray("b", ValueType::Int32, 2, n, 31);
  const std::string bytes = testing::legacyVtk(xyz, {a, b}, LegacyVtkOptions{});
  ReadOptions options;
  options.attributes = {"b", "a", "b"};
  auto source = openParticleBytes("s.vtk", bytesOf(bytes), options);
  ParticleChunk chunk;
  ASSERT_TRUE(source->read(chunk, 100));
  ASSERT_EQ(chunk.attributes.size(), 3u);
  EXPECT_EQ(chunk.attributes[0].name, "b");
  EXPECT_EQ(chunk.attributes[0].values[5], float(b.values[5]));
  EXPECT_EQ(chunk.attributes[1].values[7], float(a.values[7]));
  EXPECT_EQ(chunk.attributes[2].values, chunk.attributes[0].values);
  options.attributes = {"nope"};
  expectFileError([&] { openParticleBytes("s.vtk", bytesOf(bytes), options); },
                  {"s.vtk", "no attribute 'nope'", "it holds: a, b"});
}

TEST(VtkLegacyReader, NamesAreDecodedAndKeywordsAnyCase) {
  const std::string text =
      "# vtk DataFile Version 2.0\n\nascii\ndataset polydata\npoints 2 Float\n0 1 2\n3 4 5\n"
      "point_data 2\nscalars my%20name double\nlookup_table default\n1.5\n+2.5\n";
  auto source = openParticleBytes("n.vtk", bytesOf(text), everyAttribute());
  EXPECT_EQ(source->attributes(), (std::vector<AttributeDesc>{{"my name", ValueType::Float64, 1}}));
  const Everything all = readEverything(*source, 1);
  ASSERT_EQ(all.particles.size(), 2u);
  EXPECT_EQ(all.particles.positions[1], glm::vec3(3, 4, 5));
  EXPECT_EQ(all.columns[0], (std::vector<float>{1.5f, 2.5f}));
}

TEST(VtkLegacyReader, CarriageReturnLineBreaks) {
  const auto xyz = testing::vtkTestPositions(40, 36);
  const auto id = testing::vtkTestArray("id", ValueType::UInt32, 1, 40, 37, Kind::Scalars);
  for (bool binary : {false, true}) {
    LegacyVtkOptions options;
    options.binary = binary;
    std::string text = testing::legacyVtk(xyz, {id}, options);
    if (!binary) {  // every line break
      std::string crlf;
      for (char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
      text = crlf;
    } else {  // the header lines, where a writer on Windows would put them
      for (const char* line : {"BINARY\n", "DATASET UNSTRUCTURED_GRID\n", "POINT_DATA 40\n", "LOOKUP_TABLE default\n"})
        text.replace(text.find(line) + std::strlen(line) - 1, 1, "\r\n");
    }
    expectRoundTrip(text, xyz, {id}, binary ? "binary" : "ascii", 16);
  }
}

TEST(VtkLegacyReader, LookupTablesTensorsAndIds) {
  const std::string text =
      "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 2 double\n0 1 2 3 4 5\n"
      "CELLS 1 3\n2 0 1\nCELL_TYPES 1\n3\nCELL_DATA 1\nSCALARS c float\nLOOKUP_TABLE default\n7\n"
      "POINT_DATA 2\nSCALARS s float 1\nLOOKUP_TABLE colors\n0.5 1\nLOOKUP_TABLE colors 2\n0 0 0 1\n1 1 1 1\n"
      "TENSORS stress double\n1 2 3 4 5 6 7 8 9\n9 8 7 6 5 4 3 2 1\nGLOBAL_IDS gid vtkIdType\n10 11\n"
      "METADATA\nINFORMATION 0\n\nCOLOR_SCALARS rgb 3\n0 0.5 1\n1 1 1\nFIELD f 2\nNULL_ARRAY\nm 1 2 float\n-1 -2\n";
  auto source = openParticleBytes("t.vtk", bytesOf(text), everyAttribute());
  EXPECT_EQ(source->attributes(), (std::vector<AttributeDesc>{{"s", ValueType::Float32, 1},
                                                              {"stress", ValueType::Float64, 9},
                                                              {"gid", ValueType::Int32, 1},
                                                              {"rgb", ValueType::Float32, 3},
                                                              {"m", ValueType::Float32, 1}}));
  const Everything all = readEverything(*source, 1);
  ASSERT_EQ(all.particles.size(), 2u);
  EXPECT_EQ(all.columns[0], (std::vector<float>{0.5f, 1.f}));
  EXPECT_EQ(all.columns[1][17], 1.f);
  EXPECT_EQ(all.columns[2], (std::vector<float>{10.f, 11.f}));
  EXPECT_EQ(all.columns[3][1], 0.5f);
  EXPECT_EQ(all.columns[4], (std::vector<float>{-1.f, -2.f}));
}

// ---- Not particles, and messages ----

TEST(VtkLegacyReader, GridsAreNotParticles) {
  for (const char* dataset : {"STRUCTURED_POINTS", "STRUCTURED_GRID", "RECTILINEAR_GRID"}) {
    const std::string text = std::string("# vtk DataFile Version 3.0\ngrid\nASCII\nDATASET ") + dataset +
                             "\nDIMENSIONS 2 2 2\nORIGIN 0 0 0\nSPACING 1 1 1\n";
    expectFileError([&] { openParticleBytes("g.vtk", bytesOf(text)); },
                    {"g.vtk", std::string("dataset type is ") + dataset, "a grid", "not particles"});
  }
  expectFileError([&] { openParticleBytes("f.vtk", bytesOf("# vtk DataFile Version 3.0\nf\nASCII\nFIELD F 0\n")); },
                  {"f.vtk", "FIELD data object", "no points"});
  expectFileError(
      [&] { openParticleBytes("p.vtk", bytesOf("# vtk DataFile Version 3.0\np\nASCII\nDATASET POLYDATA\n")); },
      {"p.vtk", "POLYDATA dataset has no POINTS"});
  expectFileError([&] { openParticleBytes("t.vtk", bytesOf("# vtk DataFile Version 3.0\nt\nASCII\n")); },
                  {"t.vtk", "no DATASET"});
}

TEST(VtkLegacyReader, MessagesNameTheProblem) {
  const auto xyz = testing::vtkTestPositions(20, 32);
  const std::string good = testing::legacyVtk(xyz, {}, LegacyVtkOptions{});
  // BINARY points cut short: the declared size, the offset, what is left.
  const std::size_t pointsAt = good.find("POINTS");
  expectFileError(
      [&] { openParticleBytes("c.vtk", bytesOf(good.substr(0, pointsAt + 100))); },
      {"c.vtk", "truncated", "POINTS", "declares 60 values (240 bytes) at byte " + std::to_string(pointsAt + 16)});
  const std::string header = "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\n";
  // ASCII values are parsed as they are read.
  expectFileError(
      [&] { testing::readAll(*openParticleBytes("m.vtk", bytesOf(header + "POINTS 2 float\n0 1 2\n3 x 5\n")), 10); },
      {"m.vtk", "malformed number 'x' at byte 75 (value 4 of 6 of POINTS at byte 52)"});
  expectFileError([&] { openParticleBytes("m.vtk", bytesOf(header + "POINTS 2 float\n0 1 2\n3 4\n")); },
                  {"m.vtk", "truncated", "ends after 5 of 6 values"});
  expectFileError([&] { openParticleBytes("m.vtk", bytesOf(header + "POINTS 2 float\n0 1 2\n3 4 5")); },
                  {"m.vtk", "truncated", "no line break"});
  expectFileError([&] { openParticleBytes("m.vtk", bytesOf(header + "POINTS 2 quaternion\n")); },
                  {"m.vtk", "unknown data type 'quaternion'"});
  expectFileError([&] { openParticleBytes("m.vtk", bytesOf(header + "POINTS 1 float\n0 1 2\nPOINT_DATA 2\n")); },
                  {"m.vtk", "POINT_DATA", "declares 2 points, POINTS 1"});
  expectFileError([&] { openParticleBytes("m.vtk", bytesOf(header + "POINTS 1 float\n0 1 2\nBOGUS 1\n")); },
                  {"m.vtk", "unknown keyword 'BOGUS'"});
  expectFileError(
      [&] { openParticleBytes("m.vtk", bytesOf(header + "POINTS 1 float\n0 1 2\nPOINT_DATA 1\nSCALARS s string\n")); },
      {"m.vtk", "string values"});
  expectFileError(
      [&] {
        openParticleBytes("m.vtk", bytesOf(header + "POINTS 1 float\n0 1 2\nPOINT_DATA 1\n"
                                                    "FIELD f 1\na 1 3 float\n1 2 3\n"));
      },
      {"m.vtk", "FIELD array 'a'", "has 3 tuples, POINT_DATA 1"});
  expectFileError([&] { openParticleBytes("m.vtk", bytesOf(header + "POINTS 18446744073709551615 double\n")); },
                  {"m.vtk", "more values than fit in 64 bits"});
  expectFileError(
      [&] {
        openParticleBytes("b.vtk", bytesOf("# vtk DataFile Version 3.0\nx\nBINARY\nDATASET POLYDATA\n"
                                           "POINTS 1000000000000 double\n"));
      },
      {"b.vtk", "truncated", "declares 3000000000000 values"});
  expectFileError([&] { openParticleBytes("x.vtk", bytesOf("# vtk DataFile Version 3.0\nx\nUTF8\n")); },
                  {"x.vtk", "line 3: expected ASCII or BINARY, found 'utf8'"});
  expectFileError([&] { openParticleBytes("y.vtk", bytesOf("# vtk DataFile V\n")); },
                  {"y.vtk", "not a legacy VTK file"});
}

// ---- Damage ----

bool isSpaceByte(char c) { return c == ' ' || (c >= '\t' && c <= '\r'); }

struct Damage {
  std::size_t tries = 0, refused = 0;
};

/// Reads `bytes` completely with every attribute: false if refused with a FileError naming the
/// file; any other exception fails the test.
void expectDamageRefused(const std::string& full, const std::string& label) {
  SCOPED_TRACE(label);
  Everything whole;
  ASSERT_TRUE(readsCompletely("damaged.vtk", full, &whole));
  // Truncation: refused, or (cut between sections, or only whitespace lost) a valid shorter file
  // that reads the same points and a prefix of the same attributes.
  std::size_t accepted = 0;
  for (std::size_t cut = 0; cut < full.size(); ++cut) {
    Everything part;
    if (!readsCompletely("damaged.vtk", full.substr(0, cut), &part)) continue;
    ++accepted;
    ASSERT_EQ(part.particles.positions, whole.particles.positions) << "cut at " << cut;
    ASSERT_LE(part.columns.size(), whole.columns.size());
    for (std::size_t i = 0; i < part.columns.size(); ++i) ASSERT_EQ(part.columns[i], whole.columns[i]) << "cut " << cut;
    ASSERT_TRUE(isSpaceByte(full[cut]) || (cut > 0 && full[cut - 1] == '\n' && std::isupper(full[cut])))
        << "a cut at byte " << cut << " of " << full.size() << " reads as a valid file";
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_LT(accepted, 40u);
  // Single-byte changes: refused or read, never a crash or another exception.
  Damage damage;
  for (std::size_t at = 0; at < full.size(); at += testing::damageSweepStride())
    for (unsigned flip : {0x01u, 0x20u, 0x80u, 0xffu}) {
      std::string bad = full;
      bad[at] = char(static_cast<unsigned char>(bad[at]) ^ flip);
      ++damage.tries;
      if (!readsCompletely("damaged.vtk", bad)) ++damage.refused;
      if (::testing::Test::HasFailure()) return;
    }
  std::printf("%s: %zu bytes, %zu truncations valid, %zu of %zu changes refused\n", label.c_str(), full.size(),
              accepted, damage.refused, damage.tries);
}

TEST(VtkLegacyReader, DamagedFilesAreRefused) {
  const std::size_t n = 12;
  const auto xyz = testing::vtkTestPositions(n, 33);
  std::vector<VtkTestArray> arrays = {testing::vtkTestArray("id", ValueType::UInt32, 1, n, 34, Kind::Scalars),
                                      testing::vtkTestArray("velocity", ValueType::Float32, 3, n, 35)};
  for (bool binary : {true, false}) {
    LegacyVtkOptions options;
    options.binary = binary;
    options.title = "SPlisHSPlasH particle data";
    expectDamageRefused(testing::legacyVtk(xyz, arrays, options), binary ? "binary" : "ascii");
  }
  LegacyVtkOptions v5;
  v5.version = "5.1";
  v5.polydata = true;
  v5.metadata = true;
  expectDamageRefused(testing::legacyVtk(xyz, arrays, v5), "binary 5.1 POLYDATA");
}

// ---- Throughput (run by hand: --gtest_also_run_disabled_tests) ----

TEST(VtkLegacyReader, DISABLED_Throughput) {
  const std::size_t n = 5'000'000;
  TempDir dir("vtk-throughput");
  std::vector<double> xyz(3 * n), v(3 * n);
  for (std::size_t i = 0; i < 3 * n; ++i) {
    xyz[i] = float(i % 1000) * 0.01f;
    v[i] = float(i % 77) * 0.1f;
  }
  VtkTestArray velocity{"velocity", ValueType::Float32, 3, v, Kind::Field, {}};
  testing::writeBytes(dir / "big.vtk", testing::legacyVtk(xyz, {velocity}, LegacyVtkOptions{}));
  {
    WriteOptions raw;
    raw.velocity = false;
    ParticleChunk chunk;
    for (std::size_t i = 0; i < n; ++i) chunk.positions.emplace_back(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    testing::writeFile(dir / "big.bin", chunk, raw, 1 << 20);
  }
  // Best of 5, by wall time and by CPU time (user + system: the machine may be shared).
  auto rate = [&](const char* label, const fs::path& path, bool withVelocity) {
    double bestWall = 1e30, bestCpu = 1e30;
    for (int run = 0; run < 5; ++run) {
      ReadOptions options;
      options.velocity = withVelocity;
      const auto start = std::chrono::steady_clock::now();
      const std::clock_t cpuStart = std::clock();
      auto source = openParticleFile(path, options);
      ParticleChunk chunk;
      std::size_t total = 0;
      while (source->read(chunk, 1 << 20)) total += chunk.size();
      EXPECT_EQ(total, n);
      bestCpu = std::min(bestCpu, double(std::clock() - cpuStart) / CLOCKS_PER_SEC);
      bestWall = std::min(bestWall, secondsSince(start));
    }
    std::printf("%-28s %7.1f M particles/s wall, %7.1f M particles/s CPU\n", label, double(n) / bestWall / 1e6,
                double(n) / bestCpu / 1e6);
  };
  rate("raw float xyz", dir / "big.bin", false);
  rate("binary .vtk, positions", dir / "big.vtk", false);
  rate("binary .vtk, + velocity", dir / "big.vtk", true);
  LegacyVtkOptions ascii;
  ascii.binary = false;
  testing::writeBytes(dir / "ascii.vtk", testing::legacyVtk(xyz, {velocity}, ascii));
  rate("ASCII .vtk, + velocity", dir / "ascii.vtk", true);
}

}  // namespace
}  // namespace flipscope
