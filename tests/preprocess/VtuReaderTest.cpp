// The VTK XML reader (VtuParticles.cpp): round trips of .vtu/.vtp files written by
// VtkTestWriter.h in every variant (ascii, inline base64, appended raw and base64; zlib or
// not; UInt32 and UInt64 headers; float32 and float64 points; both byte orders; several
// pieces), datasets that are not particles, messages, and damage: every truncation and
// single-byte changes of small files.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>

#include "DamageTestSupport.h"
#include "ParticleTestSupport.h"
#include "VtkTestWriter.h"
#include "core/Elapsed.h"
#include "preprocess/particles/ParticleFormatRegistry.h"

namespace flipscope {
namespace {

using testing::bytesOf;
using testing::everyAttribute;
using testing::Everything;
using testing::expectFileError;
using testing::readEverything;
using testing::readsCompletely;
using testing::VtkTestArray;
using testing::VtuOptions;
using Data = VtuOptions::Data;

std::vector<VtkTestArray> vtuArrays(std::size_t n) {
  return {testing::vtkTestArray("velocity", ValueType::Float32, 3, n, 1),
          testing::vtkTestArray("id", ValueType::UInt32, 1, n, 2),
          testing::vtkTestArray("density", ValueType::Float64, 1, n, 3),
          testing::vtkTestArray("flags", ValueType::UInt8, 1, n, 4),
          testing::vtkTestArray("pair", ValueType::Int16, 2, n, 5),
          testing::vtkTestArray("big", ValueType::Int64, 1, n, 6),
          testing::vtkTestArray("ubig", ValueType::UInt64, 1, n, 7),
          testing::vtkTestArray("tiny", ValueType::Int8, 1, n, 8),
          testing::vtkTestArray("ushort", ValueType::UInt16, 1, n, 9),
          testing::vtkTestArray("int", ValueType::Int32, 4, n, 10)};
}

std::string describe(const VtuOptions& o) {
  const char* data[] = {"ascii", "binary", "appended raw", "appended base64"};
  return std::string(data[int(o.data)]) + (o.zlib ? " zlib" : "") + (o.header64 ? " UInt64" : " UInt32") +
         (o.bigEndian ? " BE" : " LE") + (o.pointType == ValueType::Float64 ? " float64" : " float32") + " " +
         std::to_string(o.pieces) + " pieces" + (o.headerApart ? "" : " joint-base64") +
         (o.polyData ? " PolyData" : "");
}

void expectRoundTrip(const std::vector<double>& xyz, const std::vector<VtkTestArray>& arrays, const VtuOptions& o,
                     std::size_t chunkSize) {
  const std::string label = describe(o);
  SCOPED_TRACE(label);
  const std::string bytes = testing::vtu(xyz, arrays, o);
  auto source = openParticleBytes(o.polyData ? "round.vtp" : "round.vtu", bytesOf(bytes), everyAttribute());
  const std::size_t n = xyz.size() / 3;
  EXPECT_EQ(source->countHint(), n);
  EXPECT_TRUE(source->hasVelocity());
  EXPECT_NE(source->format().find(o.polyData ? "VTK XML PolyData 1.0" : "VTK XML UnstructuredGrid 1.0"),
            std::string::npos)
      << source->format();
  const auto attributes = source->attributes();
  ASSERT_EQ(attributes.size(), arrays.size());
  for (std::size_t i = 0; i < arrays.size(); ++i)
    EXPECT_EQ(attributes[i], (AttributeDesc{arrays[i].name, arrays[i].type, arrays[i].arity}));
  for (int pass = 0; pass < 2; ++pass) {
    const Everything all = readEverything(*source, chunkSize);
    ASSERT_EQ(all.particles.size(), n);
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(all.particles.positions[i], glm::vec3(float(xyz[3 * i]), float(xyz[3 * i + 1]), float(xyz[3 * i + 2])))
          << "particle " << i;
      ASSERT_EQ(all.particles.velocities[i],
                glm::vec3(float(arrays[0].values[3 * i]), float(arrays[0].values[3 * i + 1]),
                          float(arrays[0].values[3 * i + 2])));
    }
    ASSERT_EQ(all.columns.size(), arrays.size());
    for (std::size_t a = 0; a < arrays.size(); ++a) {
      ASSERT_EQ(all.columns[a].size(), arrays[a].values.size()) << arrays[a].name;
      for (std::size_t i = 0; i < arrays[a].values.size(); ++i)
        ASSERT_EQ(all.columns[a][i], float(arrays[a].values[i])) << arrays[a].name << " value " << i;
    }
    source->rewind();
  }
}

TEST(VtuReader, RoundTripsEveryVariant) {
  const std::size_t n = 3001;
  const auto xyz = testing::vtkTestPositions(n, 41);
  const auto arrays = vtuArrays(n);
  std::size_t variants = 0;
  for (Data data : {Data::Ascii, Data::Binary, Data::AppendedRaw, Data::AppendedBase64})
    for (bool zlib : {false, true})
      for (bool header64 : {false, true})
        for (ValueType pointType : {ValueType::Float32, ValueType::Float64}) {
          if (data == Data::Ascii && (zlib || header64)) continue;  // no headers in ascii
          VtuOptions o;
          o.data = data;
          o.zlib = zlib;
          o.header64 = header64;
          o.pointType = pointType;
          o.blockSize = 4096;  // many blocks
          o.pieces = header64 ? 3 : 1;
          o.bigEndian = pointType == ValueType::Float64 && zlib;
          o.headerApart = !(header64 && pointType == ValueType::Float64);
          o.fieldData = header64;
          expectRoundTrip(xyz, arrays, o, 700);
          ++variants;
        }
  EXPECT_EQ(variants, 26u);
}

TEST(VtuReader, PolyDataAndBlockShapes) {
  const auto xyz = testing::vtkTestPositions(1000, 42);
  const auto arrays = vtuArrays(1000);
  for (std::size_t blockSize : {std::size_t(1), std::size_t(7), std::size_t(12000), std::size_t(1) << 20}) {
    VtuOptions o;
    o.polyData = true;
    o.zlib = true;
    o.blockSize = blockSize;
    o.data = blockSize == 7 ? Data::Binary : Data::AppendedRaw;
    expectRoundTrip(xyz, arrays, o, 999);
  }
  // No cells, one point, many pieces (some empty).
  VtuOptions o;
  o.cells = false;
  o.pieces = 5;
  expectRoundTrip(testing::vtkTestPositions(3, 43), vtuArrays(3), o, 1);
}

TEST(VtuReader, RecognisedByContent) {
  const auto xyz = testing::vtkTestPositions(10, 44);
  const std::string bytes = testing::vtu(xyz, {}, VtuOptions{});
  auto source = openParticleBytes("particles.dat", bytesOf(bytes));
  EXPECT_EQ(testing::readAll(*source, 100).size(), 10u);
  EXPECT_FALSE(source->hasVelocity());
  // Without the XML declaration, and with a BOM.
  const std::string bare = bytes.substr(bytes.find("<VTKFile"));
  EXPECT_EQ(testing::readAll(*openParticleBytes("p.dat", bytesOf(bare)), 100).size(), 10u);
  EXPECT_EQ(testing::readAll(*openParticleBytes("p.dat", bytesOf("\xef\xbb\xbf" + bytes)), 100).size(), 10u);
  // Other XML is not VTK.
  expectFileError([&] { openParticleBytes("p.dat", bytesOf("<?xml version=\"1.0\"?>\n<svg/>\n")); },
                  {"p.dat", "unknown particle file format"});
}

TEST(VtuReader, SpacesCommentsAndInformationKeys) {
  const std::string text =
      "<?xml version=\"1.0\"?>\n<!-- written by hand -->\n<VTKFile type='UnstructuredGrid' version=\"0.1\">\n"
      "<UnstructuredGrid><Piece NumberOfPoints=\"2\" NumberOfCells=\"0\">\n"
      "<PointData Scalars=\"s\"><DataArray type=\"Float32\" Name=\"a&amp;b\" format=\"ascii\" RangeMin=\"1\">\n"
      "  <InformationKey name=\"L2_NORM_RANGE\" location=\"vtkDataArray\" length=\"2\">\n"
      "    <Value index=\"0\">1</Value>\n  </InformationKey>\n  1.5 \n -2e1\n</DataArray>\n"
      "<DataArray type=\"String\" Name=\"names\" format=\"ascii\">97 0 98 0</DataArray></PointData>\n"
      "<Points><!-- the points --><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">"
      "0 1 2 3 4 5</DataArray></Points>\n<Cells/></Piece></UnstructuredGrid>\n</VTKFile>\n<!-- end -->\n";
  auto source = openParticleBytes("h.vtu", bytesOf(text), everyAttribute());
  EXPECT_EQ(source->attributes(), (std::vector<AttributeDesc>{{"a&b", ValueType::Float32, 1}}));
  EXPECT_EQ(source->format(), "VTK XML UnstructuredGrid 0.1 (ascii, UInt32 headers, LittleEndian, 1 piece)");
  const Everything all = readEverything(*source, 10);
  ASSERT_EQ(all.particles.size(), 2u);
  EXPECT_EQ(all.particles.positions[1], glm::vec3(3, 4, 5));
  EXPECT_EQ(all.columns[0], (std::vector<float>{1.5f, -20.f}));
}

TEST(VtuReader, WrappedBase64) {
  const auto xyz = testing::vtkTestPositions(500, 49);
  const auto arrays = vtuArrays(500);
  for (bool zlib : {false, true}) {
    VtuOptions o;
    o.data = Data::Binary;
    o.zlib = zlib;
    o.blockSize = 1000;
    std::string text = testing::vtu(xyz, arrays, o);
    // Lines of 76 characters (and a few spaces), as other writers wrap base64.
    std::string wrapped;
    std::size_t column = 0;
    bool inside = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
      if (text.compare(i, 17, "format=\"binary\">\n") == 0) {
        wrapped += text.substr(i, 17);
        i += 16;
        inside = true;
        continue;
      }
      if (text[i] == '<' && inside && text.compare(i, 12, "</DataArray>") == 0) inside = false;
      wrapped += text[i];
      if (inside && text[i] != '\n' && ++column % 76 == 0) wrapped += column % 760 == 0 ? " \r\n\t" : "\n";
    }
    auto source = openParticleBytes("w.vtu", bytesOf(wrapped), everyAttribute());
    const Everything all = readEverything(*source, 128);
    ASSERT_EQ(all.particles.size(), 500u);
    EXPECT_EQ(all.particles.positions[499], glm::vec3(float(xyz[1497]), float(xyz[1498]), float(xyz[1499])));
    EXPECT_EQ(all.columns[2][321], float(arrays[2].values[321]));
  }
}

// ---- Not particles, and messages ----

TEST(VtuReader, GridsAndParallelFilesAreRefused) {
  for (const char* type : {"ImageData", "RectilinearGrid", "StructuredGrid"})
    expectFileError(
        [&] {
          openParticleBytes("g.vtu", bytesOf(std::string("<VTKFile type=\"") + type + "\"><" + type + "/></VTKFile>"));
        },
        {"g.vtu", std::string("dataset type is ") + type, "a grid", "not particles"});
  expectFileError([&] { openParticleBytes("p.vtu", bytesOf("<VTKFile type=\"PUnstructuredGrid\"></VTKFile>")); },
                  {"p.vtu", "parallel PUnstructuredGrid", "names piece files"});
  expectFileError([&] { openParticleBytes("e.vtu", bytesOf("<VTKFile type=\"PolyData\"><PolyData/></VTKFile>")); },
                  {"e.vtu", "holds no <Piece>"});
}

TEST(VtuReader, MessagesNameTheProblem) {
  const auto xyz = testing::vtkTestPositions(20, 45);
  VtuOptions o;
  o.data = Data::AppendedRaw;
  const std::string good = testing::vtu(xyz, vtuArrays(20), o);
  std::string wrong = good;
  wrong.replace(wrong.find("NumberOfPoints=\"20\""), 19, "NumberOfPoints=\"21\"");
  expectFileError([&] { testing::readAll(*openParticleBytes("w.vtu", bytesOf(wrong)), 100); },
                  {"w.vtu", "the points of the <Piece> at byte", "declares 240 bytes in its header, expected 252"});
  std::string compressor = good;
  compressor.replace(compressor.find("header_type"), 11, "compressor=\"vtkLZ4DataCompressor\" header_type");
  expectFileError([&] { openParticleBytes("c.vtu", bytesOf(compressor)); },
                  {"c.vtu", "compressor 'vtkLZ4DataCompressor' is not supported"});
  expectFileError([&] { openParticleBytes("t.vtu", bytesOf(good.substr(0, good.size() - 30))); },
                  {"t.vtu", "truncated", "</AppendedData></VTKFile>"});
  VtuOptions inlineBinary;
  inlineBinary.data = Data::Binary;
  const std::string binary = testing::vtu(xyz, {}, inlineBinary);
  expectFileError([&] { openParticleBytes("i.vtu", bytesOf(binary.substr(0, binary.size() / 2))); },
                  {"i.vtu", "truncated"});
  std::string badChar = binary;
  badChar[binary.find("format=\"binary\">", binary.find("Name=\"Points\"")) + 30] = '%';
  expectFileError([&] { testing::readAll(*openParticleBytes("b.vtu", bytesOf(badChar)), 100); },
                  {"b.vtu", "malformed base64", "is '%'"});
  VtuOptions zlib;
  zlib.zlib = true;
  zlib.data = Data::AppendedRaw;
  zlib.cells = false;
  std::string damaged = testing::vtu(xyz, {}, zlib);
  damaged[damaged.find("   _") + 4 + 16 + 5] ^= 0x55;  // inside the zlib stream of the points
  expectFileError([&] { testing::readAll(*openParticleBytes("z.vtu", bytesOf(damaged)), 100); },
                  {"z.vtu", "zlib block 0 of 1", "damaged"});
  expectFileError(
      [&] {
        openParticleBytes("x.vtu", bytesOf("<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid>"
                                           "<Piece NumberOfPoints=\"1\"></Piece></Unstructured>"));
      },
      {"x.vtu", "</Unstructured> at byte", "closes <UnstructuredGrid>"});
  expectFileError(
      [&] {
        openParticleBytes("n.vtu", bytesOf("<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid>"
                                           "<Piece NumberOfPoints=\"1\"></Piece></UnstructuredGrid>"
                                           "</VTKFile>"));
      },
      {"n.vtu", "1 points but no <Points> DataArray"});
}

// ---- Damage ----

bool blank(const std::string& text) {
  return std::all_of(text.begin(), text.end(), [](char c) { return c == ' ' || (c >= '\t' && c <= '\r'); });
}

TEST(VtuReader, DamagedFilesAreRefused) {
  const std::size_t n = 10;
  const auto xyz = testing::vtkTestPositions(n, 46);
  std::vector<VtkTestArray> arrays = {testing::vtkTestArray("velocity", ValueType::Float32, 3, n, 47),
                                      testing::vtkTestArray("id", ValueType::Int64, 1, n, 48)};
  for (auto [data, zlib] : {std::pair{Data::Ascii, false},
                            {Data::Binary, false},
                            {Data::Binary, true},
                            {Data::AppendedRaw, false},
                            {Data::AppendedRaw, true},
                            {Data::AppendedBase64, true}}) {
    VtuOptions o;
    o.data = data;
    o.zlib = zlib;
    o.blockSize = 64;
    o.pieces = 2;
    const std::string full = testing::vtu(xyz, arrays, o);
    SCOPED_TRACE(describe(o));
    ASSERT_TRUE(readsCompletely("damaged.vtu", full));
    // Every truncation is refused, except one that cuts trailing whitespace only.
    for (std::size_t cut = 0; cut < full.size(); ++cut)
      if (readsCompletely("damaged.vtu", full.substr(0, cut))) {
        ASSERT_TRUE(blank(full.substr(cut))) << "cut at " << cut;
      }
    std::size_t refused = 0, tries = 0;
    for (std::size_t at = 0; at < full.size(); at += testing::damageSweepStride())
      for (unsigned flip : {0x01u, 0x20u, 0x80u, 0xffu}) {
        std::string bad = full;
        bad[at] = char(static_cast<unsigned char>(bad[at]) ^ flip);
        ++tries;
        if (!readsCompletely("damaged.vtu", bad)) ++refused;
        if (::testing::Test::HasFailure()) return;
      }
    std::printf("%s: %zu bytes, %zu of %zu changes refused\n", describe(o).c_str(), full.size(), refused, tries);
  }
}

// ---- Throughput (run by hand: --gtest_also_run_disabled_tests) ----

TEST(VtuReader, DISABLED_Throughput) {
  const std::size_t n = 5'000'000;
  testing::TempDir dir("vtu-throughput");
  std::vector<double> xyz(3 * n), v(3 * n);
  for (std::size_t i = 0; i < 3 * n; ++i) {
    xyz[i] = float(i % 1000) * 0.01f;
    v[i] = float(i % 77) * 0.1f;
  }
  const std::vector<VtkTestArray> arrays = {{"velocity", ValueType::Float32, 3, v, VtkTestArray::Kind::Field, {}}};
  for (auto [data, zlib, label] : {std::tuple{Data::AppendedRaw, false, "appended raw"},
                                   {Data::Binary, false, "inline base64"},
                                   {Data::AppendedRaw, true, "appended raw, zlib"}}) {
    VtuOptions o;
    o.data = data;
    o.zlib = zlib;
    o.cells = false;
    testing::writeBytes(dir / "big.vtu", testing::vtu(xyz, arrays, o));
    double bestWall = 1e30, bestCpu = 1e30;
    for (int run = 0; run < 3; ++run) {
      const auto start = std::chrono::steady_clock::now();
      const std::clock_t cpuStart = std::clock();
      auto source = openParticleFile(dir / "big.vtu");
      ParticleChunk chunk;
      std::size_t total = 0;
      while (source->read(chunk, 1 << 20)) total += chunk.size();
      EXPECT_EQ(total, n);
      bestCpu = std::min(bestCpu, double(std::clock() - cpuStart) / CLOCKS_PER_SEC);
      bestWall = std::min(bestWall, secondsSince(start));
    }
    std::printf("%-28s %7.1f M particles/s wall, %7.1f M particles/s CPU (positions + velocity)\n", label,
                double(n) / bestWall / 1e6, double(n) / bestCpu / 1e6);
  }
}

}  // namespace
}  // namespace flipscope
