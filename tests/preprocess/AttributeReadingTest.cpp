// Per-particle attributes of the existing readers: what PLY and OpenVDB point files list
// (attributes()) and the columns they read (ReadOptions::attributes, allAttributes), with exact
// values: PLY against the values the test wrote in every encoding, OpenVDB against OpenVDB's own
// AttributeHandle for every type and codec it writes (uncompressed and blosc), the Blender
// Mantaflow sample included. Raw files hold none.
#include <gtest/gtest.h>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/points/PointGroup.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <map>

#include "ParticleTestSupport.h"
#include "VdbOracle.h"
#include "VdbTestFiles.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;
using testing::expectFileError;
using testing::TempDir;
using testing::writeBytes;

/// Every particle of `source` in chunks of `chunk`: positions and each column, checked for shape.
struct ReadBack {
  std::vector<glm::vec3> positions;
  std::map<std::string, std::vector<float>> columns;
};

ReadBack readColumns(ParticleSource& source, std::size_t chunkSize) {
  ReadBack all;
  ParticleChunk chunk;
  while (source.read(chunk, chunkSize)) {
    EXPECT_LE(chunk.size(), chunkSize);
    all.positions.insert(all.positions.end(), chunk.positions.begin(), chunk.positions.end());
    for (const auto& column : chunk.attributes) {
      EXPECT_EQ(column.values.size(), chunk.size() * std::size_t(column.arity)) << column.name;
      auto& values = all.columns[column.name];
      values.insert(values.end(), column.values.begin(), column.values.end());
    }
  }
  return all;
}

// ---- PLY ----------------------------------------------------------------------------------

struct PlyProperty {
  std::string type, name;
};

void appendValue(std::string& out, const std::string& type, double value, bool bigEndian) {
  char bytes[8];
  std::size_t n = 4;
  if (type == "float") {
    const float f = float(value);
    std::memcpy(bytes, &f, 4);
  } else if (type == "double") {
    n = 8;
    std::memcpy(bytes, &value, 8);
  } else {
    n = type == "uchar" || type == "char" ? 1 : type == "short" || type == "ushort" ? 2 : 4;
    const auto v = static_cast<std::int64_t>(value);
    std::memcpy(bytes, &v, n);  // little-endian host
  }
  if (bigEndian) std::reverse(bytes, bytes + n);
  out.append(bytes, n);
}

std::string plyFile(const std::string& format, const std::vector<PlyProperty>& properties,
                    const std::vector<std::vector<double>>& rows) {
  std::string out = "ply\nformat " + format + " 1.0\nelement vertex " + std::to_string(rows.size()) + "\n";
  for (const auto& p : properties) out += "property " + p.type + " " + p.name + "\n";
  out += "end_header\n";
  for (const auto& row : rows)
    for (std::size_t i = 0; i < properties.size(); ++i) {
      if (format == "ascii") {
        char text[64];
        std::snprintf(text, sizeof text, "%.17g", row[i]);
        out += text + std::string(i + 1 < properties.size() ? " " : "\n");
      } else {
        appendValue(out, properties[i].type, row[i], format == "binary_big_endian");
      }
    }
  return out;
}

const std::vector<PlyProperty> kPlyProperties{
    {"float", "x"},      {"float", "y"}, {"float", "z"},     {"float", "vx"},       {"float", "vy"}, {"float", "vz"},
    {"float", "pscale"}, {"int", "id"},  {"uchar", "flags"}, {"double", "density"}, {"short", "age"}};

std::vector<std::vector<double>> plyRows(std::size_t count) {
  std::vector<std::vector<double>> rows;
  for (std::size_t i = 0; i < count; ++i) {
    const double k = double(i);
    rows.push_back({k * 0.5, -k, 2.0, 1.0, -2.0, 0.25 * k, 0.125 + k / 64.0, double(100000 + i), double(i % 256),
                    1000.0 + k / 1024.0, -double(i % 300)});
  }
  return rows;
}

TEST(PlyAttributes, EveryPropertyButXyzIsAScalarAttribute) {
  TempDir dir("ply-attrs");
  const auto path = dir.path() / "a.ply";
  writeBytes(path, plyFile("ascii", kPlyProperties, plyRows(3)));
  auto source = openParticleFile(path);
  const std::vector<AttributeDesc> expected{{"vx", ValueType::Float32, 1},      {"vy", ValueType::Float32, 1},
                                            {"vz", ValueType::Float32, 1},      {"pscale", ValueType::Float32, 1},
                                            {"id", ValueType::Int32, 1},        {"flags", ValueType::UInt8, 1},
                                            {"density", ValueType::Float64, 1}, {"age", ValueType::Int16, 1}};
  EXPECT_EQ(source->attributes(), expected);
  EXPECT_TRUE(source->hasVelocity());
  // Nothing asked for: no columns.
  ParticleChunk chunk;
  ASSERT_TRUE(source->read(chunk, 10));
  EXPECT_TRUE(chunk.attributes.empty());
}

TEST(PlyAttributes, ColumnsHoldTheValuesWrittenInEveryEncoding) {
  TempDir dir("ply-columns");
  const auto rows = plyRows(1000);
  for (const std::string format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    SCOPED_TRACE(format);
    const auto path = dir.path() / (format + ".ply");
    writeBytes(path, plyFile(format, kPlyProperties, rows));
    ReadOptions options;
    options.attributes = {"id", "pscale", "flags", "density", "age", "vz"};
    auto source = openParticleFile(path, options);
    const ReadBack got = readColumns(*source, 77);
    ASSERT_EQ(got.positions.size(), rows.size());
    ASSERT_EQ(got.columns.size(), 6u);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      ASSERT_EQ(got.columns.at("id")[i], float(rows[i][7])) << i;
      ASSERT_EQ(got.columns.at("pscale")[i], float(rows[i][6])) << i;
      ASSERT_EQ(got.columns.at("flags")[i], float(rows[i][8])) << i;
      ASSERT_EQ(got.columns.at("density")[i], float(rows[i][9])) << i;
      ASSERT_EQ(got.columns.at("age")[i], float(rows[i][10])) << i;
      ASSERT_EQ(got.columns.at("vz")[i], float(rows[i][5])) << i;
    }
    // The order asked for, and rewinding reads them again.
    ParticleChunk chunk;
    source->rewind();
    ASSERT_TRUE(source->read(chunk, 5));
    ASSERT_EQ(chunk.attributes.size(), 6u);
    EXPECT_EQ(chunk.attributes[0].name, "id");
    EXPECT_EQ(chunk.attributes[5].name, "vz");
    EXPECT_EQ(chunk.attributes[1].values[4], float(rows[4][6]));
    // allAttributes: every listed attribute, in the listed order.
    ReadOptions all;
    all.allAttributes = true;
    auto every = openParticleFile(path, all);
    ParticleChunk first;
    ASSERT_TRUE(every->read(first, 2));
    ASSERT_EQ(first.attributes.size(), 8u);
    for (std::size_t a = 0; a < 8; ++a) {
      EXPECT_EQ(first.attributes[a].name, kPlyProperties[a + 3].name);
      EXPECT_EQ(first.attributes[a].values[1], float(rows[1][a + 3])) << first.attributes[a].name;
    }
  }
}

// Binary records are read about a megabyte at a time (readRecordBatches: 24386 records of 43
// bytes, the fewest that make 1 MiB): a chunk of 60000 spans three slices, the last one short.
// Every value lands at its own particle, and a file cut inside the third slice says where it ends.
TEST(PlyAttributes, AChunkOfSeveralReadSlicesKeepsEveryRecordInPlace) {
  TempDir dir("ply-slices");
  const auto rows = plyRows(60000);
  const std::string bytes = plyFile("binary_little_endian", kPlyProperties, rows);
  const auto path = dir.path() / "slices.ply";
  writeBytes(path, bytes);
  ReadOptions options;
  options.velocity = true;
  options.attributes = {"density", "age"};
  auto source = openParticleFile(path, options);
  ParticleChunk chunk;
  ASSERT_TRUE(source->read(chunk, rows.size()));
  ASSERT_EQ(chunk.size(), rows.size());
  ASSERT_EQ(chunk.velocities.size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    ASSERT_EQ(chunk.positions[i], glm::vec3(float(rows[i][0]), float(rows[i][1]), float(rows[i][2]))) << i;
    ASSERT_EQ(chunk.velocities[i], glm::vec3(float(rows[i][3]), float(rows[i][4]), float(rows[i][5]))) << i;
    ASSERT_EQ(chunk.attributes[0].values[i], float(rows[i][9])) << i;
    ASSERT_EQ(chunk.attributes[1].values[i], float(rows[i][10])) << i;
  }
  EXPECT_FALSE(source->read(chunk, rows.size()));
  const std::size_t header = bytes.size() - rows.size() * 43;
  const std::size_t whole = 55000;  // in the third slice (records 48772 on)
  writeBytes(path, bytes.substr(0, header + whole * 43 + 20));
  expectFileError([&] { openParticleFile(path, options)->read(chunk, rows.size()); },
                  {"slices.ply", "file ends at particle " + std::to_string(whole) + " of 60000"});
}

TEST(PlyAttributes, AMissingAttributeNamesTheFileAndWhatItHolds) {
  TempDir dir("ply-missing");
  const auto path = dir.path() / "few.ply";
  writeBytes(path, plyFile("ascii", {{"float", "x"}, {"float", "y"}, {"float", "z"}, {"float", "pscale"}}, plyRows(0)));
  ReadOptions options;
  options.attributes = {"temperature"};
  expectFileError([&] { openParticleFile(path, options); },
                  {"few.ply", "has no attribute 'temperature'", "it holds: pscale"});
  const auto bare = dir.path() / "bare.ply";
  writeBytes(bare, plyFile("ascii", {{"float", "x"}, {"float", "y"}, {"float", "z"}}, plyRows(0)));
  expectFileError([&] { openParticleFile(bare, options); }, {"bare.ply", "positions only"});
}

TEST(RawAttributes, NoneListedAndARequestIsRefused) {
  TempDir dir("raw-attrs");
  const auto path = dir.path() / "p.bin";
  writeBytes(path, std::string(24, '\0'));
  EXPECT_TRUE(openParticleFile(path)->attributes().empty());
  ReadOptions options;
  options.attributes = {"v"};
  expectFileError([&] { openParticleFile(path, options); }, {"p.bin", "has no attribute 'v'", "positions only"});
}

// ---- OpenVDB points -----------------------------------------------------------------------

/// OpenVDB's values of attribute `name` of the grid `grid`, leaf by leaf, voxel by voxel, point
/// by point (the reader's order), each value's components as floats.
std::vector<float> oracleColumn(const fs::path& path, const std::string& gridName, const std::string& name) {
  testing::initializeOpenVdbOracle();
  openvdb::io::File file(path.string());
  file.open(false);
  auto grid = openvdb::gridPtrCast<openvdb::points::PointDataGrid>(file.readGrid(gridName));
  file.close();
  std::vector<float> out;
  if (!grid) return out;
  for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) {
    const auto& array = leaf->constAttributeArray(name);
    const std::string type = array.valueType();
    auto emit = [&]<class T>(T) {
      openvdb::points::AttributeHandle<T> handle(array);
      for (openvdb::Index i = 0; i < leaf->pointCount(); ++i) {
        const T value = handle.get(i);
        if constexpr (std::is_arithmetic_v<T>) {
          out.push_back(float(value));
        } else {
          for (int c = 0; c < int(sizeof(T) / sizeof(value[0])); ++c) out.push_back(float(value[c]));
        }
      }
    };
    if (type == "float")
      emit(float{});
    else if (type == "double")
      emit(double{});
    else if (type == "int32")
      emit(std::int32_t{});
    else if (type == "int16")
      emit(std::int16_t{});
    else if (type == "int8")
      emit(std::int8_t{});
    else if (type == "uint8")
      emit(std::uint8_t{});
    else if (type == "int64")
      emit(std::int64_t{});
    else if (type == "bool")
      emit(bool{});
    else if (type == "vec3s")
      emit(openvdb::Vec3f{});
    else if (type == "vec3d")
      emit(openvdb::Vec3d{});
    else if (type == "vec3i")
      emit(openvdb::Vec3i{});
    else
      ADD_FAILURE() << "oracle: no handle for " << type;
  }
  return out;
}

/// Every attribute flipscope lists and decodes equals OpenVDB's values, bit for bit; returns
/// how many attributes were compared.
std::size_t expectColumnsMatchOpenVdb(const fs::path& path, const std::string& grid) {
  ReadOptions options;
  options.grids = {grid};
  auto listing = openParticleFile(path, options);
  std::size_t compared = 0;
  for (const AttributeDesc& attribute : listing->attributes()) {
    SCOPED_TRACE(path.filename().string() + ": " + attribute.name);
    ReadOptions one = options;
    one.attributes = {attribute.name};
    std::unique_ptr<ParticleSource> source;
    try {
      source = openParticleFile(path, one);
    } catch (const FileError& e) {
      EXPECT_NE(std::string(e.what()).find("cannot decode"), std::string::npos) << e.what();
      continue;
    }
    const ReadBack got = readColumns(*source, 1000);
    const std::vector<float> expected = oracleColumn(path, grid, attribute.name);
    const std::vector<float>& values = got.columns.at(attribute.name);
    EXPECT_EQ(values.size(), got.positions.size() * std::size_t(attribute.arity));
    EXPECT_EQ(values.size(), expected.size());
    if (values.size() != expected.size()) continue;
    std::size_t different = 0;
    for (std::size_t i = 0; i < values.size(); ++i)
      if (std::memcmp(&values[i], &expected[i], 4) != 0 && different++ < 3)
        ADD_FAILURE() << "value " << i << ": " << values[i] << " vs " << expected[i];
    EXPECT_EQ(different, 0u);
    ++compared;
  }
  return compared;
}

/// A grid with an attribute of every kind the reader decodes, and a group.
openvdb::GridPtrVec attributeGrid(std::size_t count, bool uniformTag) {
  namespace pts = openvdb::points;
  using openvdb::Vec3f;
  testing::initializeOpenVdbOracle();
  using UInt8Array = pts::TypedAttributeArray<std::uint8_t, pts::NullCodec>;
  if (!UInt8Array::isRegistered()) UInt8Array::registerType();
  const auto points = testing::vdbfiles::randomPoints(count, 2.0f, false, 11);
  auto transform = openvdb::math::Transform::createLinearTransform(0.1);
  auto grid = testing::vdbfiles::makeGrid<pts::NullCodec, pts::NullCodec>(points, transform, "particles", "v");
  pts::PointAttributeVector<Vec3f> positions(points.positions);
  auto index = openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(positions, *transform);
  auto add = [&]<class T, class Codec>(const std::string& name, auto make) {
    pts::appendAttribute<T, Codec>(grid->tree(), name);
    std::vector<T> values;
    for (std::size_t i = 0; i < count; ++i) values.push_back(make(i));
    pts::PointAttributeVector<T> wrapped(values);
    pts::populateAttribute(grid->tree(), index->tree(), name, wrapped);
  };
  add.template operator()<float, pts::NullCodec>("pscale", [](std::size_t i) { return 0.01f * float(i) + 0.5f; });
  add.template operator()<float, pts::TruncateCodec>("life", [](std::size_t i) { return 1.0f / float(i + 3); });
  add.template operator()<std::int32_t, pts::NullCodec>("id", [](std::size_t i) { return std::int32_t(7 * i) - 50; });
  add.template operator()<std::int32_t, pts::TruncateCodec>("U", [](std::size_t i) { return std::int32_t(i % 3000); });
  add.template operator()<std::int8_t, pts::NullCodec>("tag",
                                                       [](std::size_t i) { return std::int8_t(int(i % 200) - 100); });
  add.template operator()<std::uint8_t, pts::NullCodec>("flags", [](std::size_t i) { return std::uint8_t(i * 13); });
  add.template operator()<double, pts::NullCodec>("mass", [](std::size_t i) { return 1.0 + double(i) / 3.0; });
  add.template operator()<Vec3f, pts::TruncateCodec>(
      "Cd", [](std::size_t i) { return Vec3f(float(i % 7) / 7.f, 0.25f, 1.f / float(i + 1)); });
  if (uniformTag) pts::appendAttribute<float>(grid->tree(), "uniform", 2.5f);
  pts::appendGroup(grid->tree(), "splash");
  return {grid};
}

TEST(VdbAttributes, ListsEveryAttributeButPWithItsType) {
  TempDir dir("vdb-list");
  const auto path = dir.path() / "attrs.vdb";
  testing::vdbfiles::writeFile(path, attributeGrid(500, true), openvdb::io::COMPRESS_BLOSC);
  auto source = openParticleFile(path);
  std::map<std::string, AttributeDesc> byName;
  for (const auto& a : source->attributes()) byName[a.name] = a;
  EXPECT_EQ(byName.count("P"), 0u);
  EXPECT_EQ(byName.at("v"), (AttributeDesc{"v", ValueType::Float32, 3}));
  EXPECT_EQ(byName.at("pscale"), (AttributeDesc{"pscale", ValueType::Float32, 1}));
  EXPECT_EQ(byName.at("life"), (AttributeDesc{"life", ValueType::Float32, 1}));
  EXPECT_EQ(byName.at("id"), (AttributeDesc{"id", ValueType::Int32, 1}));
  EXPECT_EQ(byName.at("U"), (AttributeDesc{"U", ValueType::Int32, 1}));
  EXPECT_EQ(byName.at("tag"), (AttributeDesc{"tag", ValueType::Int8, 1}));
  EXPECT_EQ(byName.at("flags"), (AttributeDesc{"flags", ValueType::UInt8, 1}));
  EXPECT_EQ(byName.at("mass"), (AttributeDesc{"mass", ValueType::Float64, 1}));
  EXPECT_EQ(byName.at("Cd"), (AttributeDesc{"Cd", ValueType::Float32, 3}));
  EXPECT_EQ(byName.at("uniform"), (AttributeDesc{"uniform", ValueType::Float32, 1}));
  // The group's membership array is listed (uint8) but refused when asked for.
  std::string group;
  for (const auto& [name, a] : byName)
    if (name.rfind("__group", 0) == 0) group = name;
  ASSERT_FALSE(group.empty());
  EXPECT_EQ(byName.at(group).type, ValueType::UInt8);
  ReadOptions options;
  options.attributes = {group};
  expectFileError([&] { openParticleFile(path, options); },
                  {"attrs.vdb", "'" + group + "'", "codec 'grp'", "cannot decode"});
  options.attributes = {"temperature"};
  expectFileError([&] { openParticleFile(path, options); },
                  {"attrs.vdb", "has no attribute 'temperature'", "pscale", "Cd"});
}

TEST(VdbAttributes, ColumnsEqualOpenVdbUncompressedAndBlosc) {
  TempDir dir("vdb-columns");
  for (const auto& [name, compression] : std::vector<std::pair<std::string, std::uint32_t>>{
           {"none.vdb", openvdb::io::COMPRESS_NONE},
           {"blosc.vdb", openvdb::io::COMPRESS_BLOSC},
           {"blosc_mask.vdb", openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK}}) {
    const auto path = dir.path() / name;
    testing::vdbfiles::writeFile(path, attributeGrid(3000, true), compression);
    // v, pscale, life, id, U, tag, flags, mass, Cd, uniform; the group is refused.
    EXPECT_EQ(expectColumnsMatchOpenVdb(path, "particles"), 10u) << name;
  }
  // Many pages (an attribute over several 1 MiB pages), and several columns at once in the
  // order asked for.
  const auto big = dir.path() / "big.vdb";
  testing::vdbfiles::writeFile(big, attributeGrid(200000, false), openvdb::io::COMPRESS_BLOSC);
  ReadOptions options;
  options.attributes = {"mass", "id", "v"};
  auto source = openParticleFile(big, options);
  const ReadBack got = readColumns(*source, 4096);
  ASSERT_EQ(got.positions.size(), 200000u);
  for (const auto& name : options.attributes) {
    const auto expected = oracleColumn(big, "particles", name);
    ASSERT_EQ(got.columns.at(name).size(), expected.size()) << name;
    EXPECT_TRUE(std::equal(expected.begin(), expected.end(), got.columns.at(name).begin())) << name;
  }
}

TEST(VdbAttributes, MantaflowAttributesEqualOpenVdb) {
  std::size_t files = 0, compared = 0;
  for (const char* folder : {"data", "particles"}) {
    const fs::path dir = fs::path(FLIPSCOPE_DATA_DIR) / "mantaflow-dam64" / folder;
    if (!fs::is_directory(dir)) continue;
    std::vector<fs::path> paths;
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.path().extension() == ".vdb") paths.push_back(entry.path());
    std::sort(paths.begin(), paths.end());
    if (paths.size() > 3) paths = {paths[0], paths[1], paths.back()};
    const std::string grid = std::string(folder) == "data" ? "particles" : "particles_secondary";
    for (const auto& path : paths) {
      ReadOptions options;
      options.grids = {grid};
      auto source = openParticleFile(path, options);
      if (source->countHint() == 0) continue;
      std::vector<std::string> names;
      for (const auto& a : source->attributes()) {
        names.push_back(a.name);
        if (std::getenv("FLIPSCOPE_ORACLE_VERBOSE"))
          std::printf("%s: %s %s x%d\n", path.filename().c_str(), a.name.c_str(),
                      std::string(valueTypeName(a.type)).c_str(), a.arity);
      }
      // Mantaflow's velocity and, for secondary particles, the life time (float trnc).
      if (std::string(folder) == "particles") {
        EXPECT_NE(std::find(names.begin(), names.end(), "particles_life_secondary"), names.end()) << path;
      }
      compared += expectColumnsMatchOpenVdb(path, grid);
      ++files;
    }
  }
  EXPECT_GE(files, 4u);
  EXPECT_GE(compared, 8u);
}

}  // namespace
}  // namespace flipscope
