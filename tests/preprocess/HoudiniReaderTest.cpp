// Houdini's modern geometry: binary JSON .bgeo, ASCII JSON .geo and the scf1 container (.sc).
// Every real file is read with its declared point count and attributes, or refused saying what
// it holds; each .bgeo reads exactly like its .geo twin; a .bgeo.sc reads like the bytes it
// decodes to; synthetic files (BgeoTestWriter.h) cover many pages, chunks and every storage;
// damaged files are refused with a FileError.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <random>

#include "BgeoTestWriter.h"
#include "DamageTestSupport.h"
#include "ParticleTestSupport.h"
#include "core/Elapsed.h"
#include "preprocess/particles/ParticleFormatRegistry.h"
#include "preprocess/particles/ParticleFormats.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;
using testing::expectFileError;
using testing::TempDir;
namespace bgeo = testing::bgeo;

const fs::path kModern = fs::path(FLIPSCOPE_DATA_DIR) / "formats" / "houdini-modern";
const fs::path kCompressed = fs::path(FLIPSCOPE_DATA_DIR) / "formats" / "houdini-bgeo-sc";

/// Everything a source gives: positions, velocities and every attribute column, concatenated.
struct Particles {
  std::vector<glm::vec3> positions, velocities;
  std::map<std::string, std::vector<float>> columns;
};

Particles readEverything(ParticleSource& source, std::size_t chunkSize) {
  Particles all;
  ParticleChunk chunk;
  while (source.read(chunk, chunkSize)) {
    EXPECT_LE(chunk.size(), chunkSize);
    EXPECT_EQ(chunk.velocities.size(), source.hasVelocity() ? chunk.size() : 0u);
    all.positions.insert(all.positions.end(), chunk.positions.begin(), chunk.positions.end());
    all.velocities.insert(all.velocities.end(), chunk.velocities.begin(), chunk.velocities.end());
    for (const auto& column : chunk.attributes) {
      EXPECT_EQ(column.values.size(), chunk.size() * std::size_t(column.arity)) << column.name;
      auto& values = all.columns[column.name];
      values.insert(values.end(), column.values.begin(), column.values.end());
    }
  }
  return all;
}

Particles readPath(const fs::path& path, std::size_t chunkSize = 1000) {
  ReadOptions options;
  options.allAttributes = true;
  auto source = openParticleFile(path, options);
  return readEverything(*source, chunkSize);
}

Particles readBytes(const std::string& name, const std::string& bytes, std::size_t chunkSize = 1000) {
  ReadOptions options;
  options.allAttributes = true;
  auto source = openParticleBytes(name, std::as_bytes(std::span(bytes.data(), bytes.size())), options);
  return readEverything(*source, chunkSize);
}

bool sameFloats(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}
bool sameVectors(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0);
}
void expectSame(const Particles& a, const Particles& b, const std::string& what) {
  EXPECT_TRUE(sameVectors(a.positions, b.positions)) << what << ": positions differ";
  EXPECT_TRUE(sameVectors(a.velocities, b.velocities)) << what << ": velocities differ";
  EXPECT_EQ(a.columns.size(), b.columns.size()) << what;
  for (const auto& [name, values] : a.columns) {
    auto other = b.columns.find(name);
    ASSERT_NE(other, b.columns.end()) << what << ": no column " << name;
    EXPECT_TRUE(sameFloats(values, other->second)) << what << ": column " << name << " differs";
  }
}

std::string stemOf(const fs::path& path) {
  std::string name = path.filename().string();
  for (const char* suffix : {".bgeo.sc", ".bgeo", ".geo"})
    if (name.size() > std::strlen(suffix) && name.ends_with(suffix)) return name.substr(0, name.size() - std::strlen(suffix));
  return name;
}

std::vector<fs::path> filesIn(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (entry.is_regular_file()) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::string fileBytes(const fs::path& path) { return testing::readBytes(path); }

// ---- The real files ----

struct Expected {
  const char* stem;
  std::uint64_t points;    ///< 0: refused
  const char* attributes;  ///< besides P, in file order; or what the refusal says
};

// Point counts and attributes as each file's header declares them (read with Python's json
// from the .geo twins); refusals for files whose points are only the anchors of volumes,
// packed or quadric primitives, for empty files, and for badgrid (a tuple short of a value).
const Expected kExpected[] = {
    {"H16_fragment_crash", 202, "rest v"},
    {"cube_even_odd", 8, ""},
    {"cube_multi_groups", 32, ""},
    {"cube_multi_groups_14", 32, ""},
    {"cube_multi_groups_15", 32, ""},
    {"cube_primgroup", 8, ""},
    {"cube_primgroup_14", 8, ""},
    {"cube_primgroup_15", 8, ""},
    {"cubes_connectivity", 24, ""},
    {"grid", 4, "uv"},
    {"grid_14", 4, "uv"},
    {"grid_15", 4, ""},
    {"grid_tetra", 8, ""},
    {"grid_tetra_14", 8, ""},
    {"grid_tetra_15", 8, ""},
    {"points_noprim", 10, "N"},
    {"points_noprim_14", 10, "N"},
    {"points_noprim_15", 10, "N"},
    {"points_partsys", 10, "N"},
    {"points_partsys_15", 10, "N"},
    {"psoup_cubes", 84, "N"},
    {"psoup_simple", 8, ""},
    {"simple_partanim.0017", 10, "age dead force has_pprevious id life N pprevious rest sourceptnum uv v"},
    {"simple_partanim_14.0017", 10, "age dead force has_pprevious id life N pprevious rest sourceptnum uv v"},
    {"simple_partanim_15.0017", 10, "age dead force has_pprevious id life N pprevious rest sourceptnum uv v"},
    {"sphere_grid", 5, ""},
    {"sphere_grid_14", 5, ""},
    {"sphere_grid_15", 5, ""},
    {"calculate_occlusion_demoscene.1", 2766, "Cd"},
    {"curve_sweep_demoscene.1", 453, "pscale up"},
    {"delete_small_parts_demoscene.1", 464, "pscale"},
    {"labs_lightning.1", 888, "Cd cost curveu origpt"},
    {"labs_sine_wave.1", 400, ""},
    {"labs_sphere_generator.1", 3137, ""},
    {"labs_spiral.1", 188, ""},
    {"labs_star.1", 10, ""},
    {"labs_wfc.1", 400, "Cd transform"},
    {"empty", 0, "holds no points (an empty geometry)"},
    {"empty_14", 0, "holds no points (an empty geometry)"},
    {"empty_15", 0, "holds no points (an empty geometry)"},
    {"badgrid", 0, "point attribute 'P': tuple 3 holds 3 numbers, the ones before it 4"},
    {"atmos_vol_lo.0054", 0, "holds no point cloud: only 1 volume (Volume), whose positions are its 1 point"},
    {"atmos_vol_lo_14.0054", 0, "holds no point cloud: only 1 volume (Volume)"},
    {"atmos_vol_lo_15.0054", 0, "holds no point cloud: only 1 volume (Volume)"},
    {"multivolume", 0, "holds no point cloud: only 7 volumes (Volume), whose positions are its 7 points"},
    {"multivolume_15", 0, "holds no point cloud: only 7 volumes (Volume)"},
    {"pyro_crash_lo", 0, "holds no point cloud: only 7 volumes (Volume)"},
    {"splash_interior", 0, "holds no point cloud: only 1 volume (Volume)"},
    {"splash_interior_14", 0, "holds no point cloud: only 1 volume (Volume)"},
    {"splash_interior_15", 0, "holds no point cloud: only 1 volume (Volume)"},
    {"vol", 0, "holds no point cloud: only 1 volume (Volume)"},
    {"vol_14", 0, "holds no point cloud: only 1 volume (Volume)"},
    {"vol_15", 0, "holds no point cloud: only 1 volume (Volume)"},
    {"vol2_noshared", 0, "holds no point cloud: only 2 volumes (Volume)"},
    {"vol2_shared", 0, "holds no point cloud: only 2 volumes (Volume)"},
    {"vol5_noshared", 0, "holds no point cloud: only 5 volumes (Volume)"},
    {"vol5_shared", 0, "holds no point cloud: only 5 volumes (Volume)"},
    {"sphere", 0, "holds no point cloud: only 1 quadric primitive (Sphere)"},
    {"sphere_14", 0, "holds no point cloud: only 1 quadric primitive (Sphere)"},
    {"sphere_15", 0, "holds no point cloud: only 1 quadric primitive (Sphere)"},
    {"pack1", 0, "holds no point cloud: only 1 packed primitive (PackedGeometry), whose positions are its 1 point"},
    {"pack1_xform", 0, "holds no point cloud: only 1 packed primitive (PackedGeometry)"},
    {"pack4_simple", 0, "holds no point cloud: only 4 packed primitives (PackedGeometry)"},
    {"pack4_unshared", 0, "holds no point cloud: only 4 packed primitives (PackedGeometry)"},
    {"pack4_xform", 0, "holds no point cloud: only 4 packed primitives (PackedGeometry)"},
    {"pack_fragments2", 0, "holds no point cloud: only 2 packed primitives (PackedFragment)"},
    {"pack_fragments6", 0, "holds no point cloud: only 6 packed primitives (PackedFragment)"},
    {"pack_fragments6_anim.0020", 0, "holds no point cloud: only 6 packed primitives (PackedFragment)"},
    {"pack_level2", 0, "holds no point cloud: only 1 packed primitive (PackedGeometry)"},
    {"packed_15", 0, "holds no point cloud: only 3 packed primitives (PackedGeometry)"},
    {"packed_disk", 0, "holds no point cloud: only 1 packed primitive (PackedDisk)"},
    {"packed_disk_frames", 0, "holds no point cloud: only 4 packed primitives (PackedDisk)"},
    {"packed_points_simple_15_5", 0, "holds no point cloud: only 2 packed primitives (PackedGeometry)"},
    {"destruction_cleanup_demoscene.1", 0,
     "holds no point cloud: only 77 packed primitives (PackedFragment, PackedGeometry), whose positions are its 77 points"},
};

const Expected* expectedFor(const fs::path& path) {
  for (const auto& e : kExpected)
    if (stemOf(path) == e.stem) return &e;
  return nullptr;
}

TEST(HoudiniReader, EveryRealFileIsReadOrRefusedClearly) {
  std::size_t files = 0, read = 0;
  for (const fs::path& dir : {kModern, kCompressed})
    for (const fs::path& path : filesIn(dir)) {
      SCOPED_TRACE(path.string());
      const Expected* expected = expectedFor(path);
      ASSERT_NE(expected, nullptr) << "add " << path.filename() << " to kExpected";
      ++files;
      if (expected->points == 0) {
        expectFileError([&] { openParticleFile(path); }, {path.filename().string(), expected->attributes});
        continue;
      }
      ++read;
      ReadOptions options;
      options.allAttributes = true;
      auto source = openParticleFile(path, options);
      EXPECT_EQ(source->countHint(), expected->points);
      std::string names;
      for (const auto& attribute : source->attributes()) names += (names.empty() ? "" : " ") + attribute.name;
      EXPECT_EQ(names, expected->attributes);
      EXPECT_EQ(source->hasVelocity(), names.find(" v") != std::string::npos || names.starts_with("v"));
      EXPECT_NE(source->format().find(path.extension() == ".geo" ? "ASCII JSON" : "binary JSON"), std::string::npos)
          << source->format();
      const Particles all = readEverything(*source, 7);
      EXPECT_EQ(all.positions.size(), expected->points);
      for (const auto& attribute : source->attributes())
        EXPECT_EQ(all.columns.at(attribute.name).size(), expected->points * std::size_t(attribute.arity)) << attribute.name;
      source->rewind();
      expectSame(readEverything(*source, 1 << 20), all, "after rewind()");
    }
  EXPECT_GE(files, 6u) << "the real files are missing from " << kModern;
  EXPECT_GE(read, 3u);
}

TEST(HoudiniReader, ExactValuesOfPointClouds) {
  // (Each Houdini version wrote slightly different values: these are the 13.0 files'.)
  for (const char* name : {"points_noprim.bgeo", "points_noprim.geo", "points_partsys.geo"}) {
    if (!fs::exists(kModern / name)) continue;
    SCOPED_TRACE(name);
    const Particles p = readPath(kModern / name);
    ASSERT_EQ(p.positions.size(), 10u);
    EXPECT_EQ(p.positions.front(), glm::vec3(float(-1.0709567069999999), float(0.245002537965999995),
                                             float(0.0458687506615999968)));
    EXPECT_EQ(p.positions.back(), glm::vec3(float(0.235484302044000005), float(-0.103837713599000001),
                                            float(-0.471310973166999991)));
    const std::vector<float>& normals = p.columns.at("N");
    EXPECT_EQ(normals[0], float(-0.601949989796000007));
    EXPECT_EQ(normals[29], float(-0.758393168448999955));
  }
  for (const char* name : {"simple_partanim.0017.bgeo", "simple_partanim.0017.geo"}) {
    if (!fs::exists(kModern / name)) continue;
    SCOPED_TRACE(name);
    const Particles p = readPath(kModern / name, 3);
    ASSERT_EQ(p.positions.size(), 10u);
    EXPECT_EQ(p.positions.front(),
              glm::vec3(float(7.52561378478999998), float(1.34114897251000009), float(4.46619892120000017)));
    EXPECT_EQ(p.positions.back(),
              glm::vec3(float(5.95316314696999971), float(1.21525859832999994), float(1.44889509678000006)));
    ASSERT_EQ(p.velocities.size(), 10u);
    EXPECT_EQ(p.velocities.front(),
              glm::vec3(float(5.41995143890000008), float(-1.11781489849000004), float(5.41995143890000008)));
    EXPECT_EQ(p.velocities.back(),
              glm::vec3(float(5.26712512970000013), float(-1.27064132690000009), float(5.26712512970000013)));
    EXPECT_EQ(p.columns.at("v"), std::vector<float>(&p.velocities[0].x, &p.velocities[0].x + 30));
    const auto& id = p.columns.at("id");
    for (int i = 0; i < 10; ++i) EXPECT_EQ(id[std::size_t(i)], float(i));
    EXPECT_EQ(p.columns.at("life"), std::vector<float>(10, 100.f));  // a constant page in the .bgeo
    EXPECT_EQ(p.columns.at("age").front(), float(0.674656987190000001));
    EXPECT_EQ(p.columns.at("age").back(), float(0.67033106088600003));
  }
  for (const char* name : {"labs_wfc.1.bgeo.sc", "labs_star.1.bgeo.sc"}) {
    if (!fs::exists(kCompressed / name)) continue;
    SCOPED_TRACE(name);
    const Particles p = readPath(kCompressed / name);
    if (std::string(name) == "labs_star.1.bgeo.sc") {
      ASSERT_EQ(p.positions.size(), 10u);
      EXPECT_EQ(p.positions.front(), glm::vec3(0, 2, 0));
      EXPECT_EQ(p.positions.back(), glm::vec3(float(0.5877848863601685), float(0.8090172410011292), 0));
    } else {
      ASSERT_EQ(p.positions.size(), 400u);
      EXPECT_EQ(p.positions.front(), glm::vec3(-9.5f, 0, -9.5f));
      EXPECT_EQ(p.positions.back(), glm::vec3(9.5f, 0, 9.5f));
      EXPECT_EQ(p.columns.at("Cd").size(), 1200u);
      EXPECT_EQ(p.columns.at("transform")[2], 1.f);
      EXPECT_EQ(p.columns.at("transform")[0], float(-4.371138828673793e-08));
    }
  }
}

TEST(HoudiniReader, EachBgeoReadsLikeItsGeoTwin) {
  std::size_t pairs = 0;
  for (const fs::path& binary : filesIn(kModern)) {
    if (binary.extension() != ".bgeo") continue;
    fs::path ascii = binary;
    ascii.replace_extension(".geo");
    if (!fs::exists(ascii)) continue;
    SCOPED_TRACE(binary.filename().string());
    ++pairs;
    std::string binaryError, asciiError;
    Particles fromBinary, fromAscii;
    try {
      fromBinary = readPath(binary, 3);
    } catch (const FileError& e) {
      binaryError = std::string(e.what()).substr(binary.string().size());
    }
    try {
      fromAscii = readPath(ascii, 4);
    } catch (const FileError& e) {
      asciiError = std::string(e.what()).substr(ascii.string().size());
    }
    EXPECT_EQ(binaryError, asciiError);
    expectSame(fromBinary, fromAscii, ".bgeo against .geo");
  }
  EXPECT_GE(pairs, 1u);
}

std::string decodeWhole(const fs::path& path) {
  std::unique_ptr<ByteSource> decoded = detail::decodeScf(InputFile(path));
  std::string bytes(std::size_t(decoded->size()), '\0');
  EXPECT_EQ(decoded->readAt(0, bytes.data(), bytes.size()), bytes.size());
  return bytes;
}

TEST(HoudiniReader, ScContainerReadsLikeTheBgeoItHolds) {
  std::size_t files = 0;
  for (const fs::path& path : filesIn(kCompressed)) {
    SCOPED_TRACE(path.filename().string());
    ++files;
    const std::string bytes = decodeWhole(path);
    ASSERT_GE(bytes.size(), 5u);
    EXPECT_EQ(bytes.substr(0, 5), std::string("\x7fNSJb", 5));
    InputFile file(path);
    EXPECT_EQ(recogniseInput(std::move(file)).containers, std::vector<std::string>{"scf1"});
    const Expected* expected = expectedFor(path);
    ASSERT_NE(expected, nullptr);
    if (expected->points == 0) {
      expectFileError([&] { readBytes("decoded.bgeo", bytes); }, {expected->attributes});
      continue;
    }
    expectSame(readPath(path, 100), readBytes("decoded.bgeo", bytes, 333), ".bgeo.sc against its decoded bytes");
    // Random access: reads anywhere match the whole.
    std::unique_ptr<ByteSource> source = detail::decodeScf(InputFile(path));
    std::mt19937 rng(1);
    for (int i = 0; i < 50; ++i) {
      const std::size_t at = rng() % bytes.size(), n = rng() % 5000;
      std::string part(n, '\0');
      const std::size_t got = source->readAt(at, part.data(), n);
      EXPECT_EQ(got, std::min(n, bytes.size() - at));
      EXPECT_EQ(part.substr(0, got), bytes.substr(at, got));
    }
  }
  EXPECT_GE(files, 1u);
}

// ---- Synthetic files ----

double smooth(std::uint64_t p, int c) { return std::sin(0.001 * double(p) + c) * 50.0 + 0.25 * c; }

/// A geometry of `points` points with P (hpoint: packing 3,1 and w constant), v, and attributes
/// of every storage and layout, some with constant pages.
bgeo::Geometry richGeometry(std::uint64_t points, std::uint64_t pageSize, bool uniform) {
  bgeo::Geometry g;
  g.points = points;
  auto add = [&](std::string name, std::string storage, int arity, auto value, bgeo::Layout layout) {
    bgeo::Attribute a;
    a.name = std::move(name);
    a.storage = std::move(storage);
    a.arity = arity;
    a.value = value;
    a.layout = layout;
    a.pageSize = pageSize;
    a.uniform = uniform;
    g.attributes.push_back(std::move(a));
    return &g.attributes.back();
  };
  add("P", "fpreal32", 4, [](std::uint64_t p, int c) { return c == 3 ? 1.0 : smooth(p, c); }, bgeo::Layout::Paged)
      ->packing = {3, 1};
  add("v", "fpreal64", 3, [](std::uint64_t p, int c) { return std::cos(0.01 * double(p) * (c + 1)); }, bgeo::Layout::Paged);
  add("name", "int32", 1, nullptr, bgeo::Layout::Paged)->isString = true;
  // Constant over the first pages, then varying: constant pages and plain ones in one attribute.
  add("pscale", "fpreal32", 1, [=](std::uint64_t p, int) { return p < 2 * pageSize ? 0.5 : 0.5 + double(p % 7); },
      bgeo::Layout::Paged);
  add("id", "int64", 1, [](std::uint64_t p, int) { return double(p); }, bgeo::Layout::Paged);
  add("Cd", "fpreal16", 3, [](std::uint64_t p, int c) { return double((p + std::uint64_t(c)) % 64) / 64.0; },
      bgeo::Layout::Tuples);
  add("age", "int16", 1, [](std::uint64_t p, int) { return double(int(p % 60000) - 30000); }, bgeo::Layout::Arrays);
  add("flags", "uint8", 2, [](std::uint64_t p, int c) { return double((p * 7 + std::uint64_t(c)) % 256); },
      bgeo::Layout::Arrays);
  add("small", "int8", 1, [](std::uint64_t p, int) { return double(int(p % 256) - 128); }, bgeo::Layout::Tuples);
  add("count", "uint16", 1, [](std::uint64_t p, int) { return double(p % 65536); }, bgeo::Layout::Paged);
  add("mass", "int32", 1, [](std::uint64_t, int) { return 7.0; }, bgeo::Layout::Paged);  // every page constant
  return g;
}

/// What the reader must give for attribute `a` of `g`: its values cast to the storage, as float.
float expectedValue(const bgeo::Attribute& a, std::uint64_t p, int c) {
  const double v = a.value(p, c);
  if (a.storage == "fpreal32" || a.storage == "fpreal16") return float(v);
  if (a.storage == "fpreal64") return float(v);
  return float(std::int64_t(v));
}

void checkAgainst(const bgeo::Geometry& g, const Particles& p) {
  ASSERT_EQ(p.positions.size(), g.points);
  const bgeo::Attribute& P = g.attributes[0];
  const bgeo::Attribute& v = g.attributes[1];
  ASSERT_EQ(p.velocities.size(), g.points);
  for (std::uint64_t i = 0; i < g.points; ++i) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(p.positions[i][c], expectedValue(P, i, c)) << "point " << i;
      ASSERT_EQ(p.velocities[i][c], expectedValue(v, i, c)) << "point " << i;
    }
  }
  EXPECT_EQ(p.columns.count("name"), 0u) << "string attributes are not read";
  for (const auto& a : g.attributes) {
    if (a.name == "P" || a.isString) continue;
    const std::vector<float>& values = p.columns.at(a.name);
    ASSERT_EQ(values.size(), g.points * std::size_t(a.arity)) << a.name;
    for (std::uint64_t i = 0; i < g.points; ++i)
      for (int c = 0; c < a.arity; ++c)
        ASSERT_EQ(values[i * std::size_t(a.arity) + std::size_t(c)], expectedValue(a, i, c))
            << a.name << " point " << i << " component " << c;
  }
}

TEST(HoudiniReader, SyntheticRoundTripsInEveryEncodingAndLayout) {
  struct Case {
    std::uint64_t points, pageSize;
    bool uniform;
  };
  for (const Case& k : {Case{20000, 1000, true}, Case{5000, 1024, false}, Case{1, 1024, true}, Case{3001, 7, true}})
    for (auto encoding : {bgeo::Encoding::Binary, bgeo::Encoding::Ascii}) {
      const bgeo::Geometry g = richGeometry(k.points, k.pageSize, k.uniform);
      const std::string bytes = bgeo::geometryBytes(g, encoding);
      const std::string name = encoding == bgeo::Encoding::Binary ? "synthetic.bgeo" : "synthetic.geo";
      SCOPED_TRACE(name + " points " + std::to_string(k.points) + " pagesize " + std::to_string(k.pageSize) +
                   (k.uniform ? " uniform" : " tokens"));
      ReadOptions options;
      options.allAttributes = true;
      auto source = openParticleBytes(name, std::as_bytes(std::span(bytes.data(), bytes.size())), options);
      EXPECT_EQ(source->countHint(), k.points);
      std::vector<AttributeDesc> expected;
      for (const auto& a : g.attributes)
        if (a.name != "P" && !a.isString)
          expected.push_back({a.name,
                              a.storage == "fpreal32"   ? ValueType::Float32
                              : a.storage == "fpreal64" ? ValueType::Float64
                              : a.storage == "fpreal16" ? ValueType::Float16
                              : a.storage == "int8"     ? ValueType::Int8
                              : a.storage == "int16"    ? ValueType::Int16
                              : a.storage == "int32"    ? ValueType::Int32
                              : a.storage == "int64"    ? ValueType::Int64
                              : a.storage == "uint8"    ? ValueType::UInt8
                                                        : ValueType::UInt16,
                              a.arity});
      EXPECT_EQ(source->attributes(), expected);
      checkAgainst(g, readEverything(*source, 777));
      source->rewind();
      checkAgainst(g, readEverything(*source, 100000));
      // In the scf1 container, in chunks smaller than the file.
      const std::string packed = bgeo::scfContainer(bytes, 4096 + 17);
      checkAgainst(g, readBytes(name + ".sc", packed, 1234));
    }
}

TEST(HoudiniReader, OnlyTheAttributesAskedForAreRead) {
  const bgeo::Geometry g = richGeometry(3000, 256, true);
  const std::string bytes = bgeo::geometryBytes(g, bgeo::Encoding::Binary);
  ReadOptions options;
  options.velocity = false;
  options.attributes = {"id", "Cd"};
  auto source = openParticleBytes("x.bgeo", std::as_bytes(std::span(bytes.data(), bytes.size())), options);
  EXPECT_FALSE(source->hasVelocity());
  ParticleChunk chunk;
  ASSERT_TRUE(source->read(chunk, 500));
  ASSERT_EQ(chunk.attributes.size(), 2u);
  EXPECT_EQ(chunk.attributes[0].name, "id");
  EXPECT_EQ(chunk.attributes[1].name, "Cd");
  EXPECT_EQ(chunk.attributes[1].values.size(), 1500u);
  EXPECT_EQ(chunk.attributes[0].values[499], 499.f);
  options.attributes = {"nope"};
  expectFileError([&] { openParticleBytes("x.bgeo", std::as_bytes(std::span(bytes.data(), bytes.size())), options); },
                  {"has no attribute 'nope'", "v, pscale, id"});
}

TEST(HoudiniReader, ScfChunksReadInAnyOrder) {
  std::string bytes(300000, '\0');
  std::mt19937 rng(5);
  for (auto& b : bytes) b = char(rng() % 16);
  const std::string packed = bgeo::scfContainer(bytes, 65536);
  InputFile file("x.bgeo.sc", std::as_bytes(std::span(packed.data(), packed.size())));
  ASSERT_TRUE(detail::isScf(file));
  std::unique_ptr<ByteSource> source = detail::decodeScf(std::move(file));
  ASSERT_EQ(source->size(), bytes.size());
  for (int i = 0; i < 300; ++i) {
    const std::size_t at = rng() % (bytes.size() + 10), n = rng() % 200000;
    std::string part(n, '\0');
    const std::size_t got = source->readAt(at, part.data(), n);
    ASSERT_EQ(got, at >= bytes.size() ? 0 : std::min(n, bytes.size() - at));
    ASSERT_EQ(part.substr(0, got), bytes.substr(std::min(at, bytes.size()), got)) << "at " << at;
  }
}

// ---- Recognition and messages ----

std::span<const std::byte> spanOf(const std::string& text) { return std::as_bytes(std::span(text.data(), text.size())); }

TEST(HoudiniReader, RecognisedByContent) {
  EXPECT_TRUE(detail::isHoudiniJson(spanOf(std::string("\x7fNSJb[", 6))));
  EXPECT_TRUE(detail::isHoudiniJson(spanOf("[\"fileversion\",\"18.5\"")));
  EXPECT_TRUE(detail::isHoudiniJson(spanOf("\n\t [\n  \"fileversion\" ,")));
  EXPECT_FALSE(detail::isHoudiniJson(spanOf("[1, 2, 3]")));
  EXPECT_FALSE(detail::isHoudiniJson(spanOf("{\"fileversion\": 1}")));
  EXPECT_FALSE(detail::isHoudiniJson(spanOf("[\"pointcount\",10]")));
  EXPECT_FALSE(detail::isHoudiniJson(spanOf("PGEOMETRY V5")));
  const ParticleFormat* format = findParticleFormat("bgeo");
  ASSERT_NE(format, nullptr);
  for (const char* extension : {".bgeo", ".geo", ".bgeo.sc", ".geo.sc", ".bgeo.gz", ".geo.gz"})
    EXPECT_NE(std::find(format->extensions.begin(), format->extensions.end(), extension), format->extensions.end());
  // Content wins over the name; an ASCII file in the container too.
  bgeo::Geometry g = richGeometry(10, 4, true);
  const std::string ascii = bgeo::geometryBytes(g, bgeo::Encoding::Ascii);
  checkAgainst(g, readBytes("misnamed.bin", ascii));
  checkAgainst(g, readBytes("ascii.geo.sc", bgeo::scfContainer(ascii, 100)));
}

/// The bytes of a small valid binary file with P only, for the message tests.
std::string smallBinary(std::uint64_t points = 5) {
  bgeo::Geometry g;
  g.points = points;
  bgeo::Attribute a;
  a.name = "P";
  a.value = smooth;
  g.attributes.push_back(a);
  return bgeo::geometryBytes(g, bgeo::Encoding::Binary);
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(HoudiniReader, MessagesSayWhatIsWrong) {
  auto refuse = [](const std::string& name, const std::string& bytes, const std::vector<std::string>& parts) {
    expectFileError([&] { readBytes(name, bytes); }, parts);
  };
  const std::string binary = smallBinary();
  refuse("cut.bgeo", binary.substr(0, binary.size() - 3), {"cut.bgeo", "truncated", "file size"});
  refuse("swapped.bgeo", std::string("\x7f" "bJSN", 5) + binary.substr(5), {"byte-swapped"});
  refuse("badlength.bgeo", replaced(binary, std::string("\x2b\x00\x0b", 3), std::string("\x2b\x00\xf3", 3)), {"bad length byte 0xf3"});
  refuse("token.bgeo", binary.substr(0, 5) + "\x99" + binary.substr(6), {"binary JSON at byte 5", "unknown token 0x99"});
  refuse("trailing.bgeo", binary + "x", {"unexpected bytes after the end of the geometry"});

  bgeo::Geometry g;
  g.points = 3;
  bgeo::Attribute a;
  a.name = "P";
  a.value = smooth;
  a.uniform = false;
  g.tokenStrings = false;
  g.attributes.push_back(a);
  const std::string ascii = bgeo::geometryBytes(g, bgeo::Encoding::Ascii);
  refuse("count.geo", replaced(ascii, "\"pointcount\",3", "\"pointcount\",4"),
         {"point attribute 'P'", "rawpagedata holds 9 numbers, expected 12 (4 points, pagesize 1024)"});
  refuse("nocount.geo", replaced(ascii, "\"pointcount\",3,", ""), {"the geometry has no \"pointcount\""});
  refuse("noP.geo", replaced(ascii, "\"name\",\"P\"", "\"name\",\"Q\""), {"has no numeric point attribute 'P'"});
  refuse("word.geo", replaced(ascii, "\"rawpagedata\",[", "\"rawpagedata\",[x,"), {"malformed number 'x'"});
  refuse("cut.geo", ascii.substr(0, ascii.size() - 3), {"truncated"});
  refuse("storage.geo", replaced(ascii, "\"storage\",\"fpreal32\",\"pagesize\"", "\"storage\",\"fpreal7\",\"pagesize\""),
         {"point attribute 'P': unknown storage 'fpreal7'"});
  refuse("packing.geo", replaced(ascii, "\"pagesize\"", "\"packing\",[2],\"pagesize\""),
         {"packing adds up to 2 components, its size is 3"});
  refuse("points.geo", replaced(ascii, "\"pointcount\",3", "\"pointcount\",0"),
         {"rawpagedata holds 9 numbers, expected 0"});

  // What a file without particles holds.
  bgeo::Geometry shapes = g;
  shapes.points = 0;
  shapes.attributes[0].value = nullptr;
  shapes.primitives = {"Poly"};
  refuse("nopoints.geo", bgeo::geometryBytes(shapes, bgeo::Encoding::Ascii), {"holds no points, only 1 primitive (Poly)"});
  shapes = g;
  shapes.primitives = {"Volume", "PackedGeometry"};
  refuse("anchors.bgeo", bgeo::geometryBytes(shapes, bgeo::Encoding::Binary),
         {"holds no point cloud: only 2 primitives (Volume, PackedGeometry), whose positions are its 3 points"});
  shapes.primitives = {"Volume", "Poly"};  // the points of a polygon: read
  EXPECT_EQ(readBytes("mixed.bgeo", bgeo::geometryBytes(shapes, bgeo::Encoding::Binary)).positions.size(), 3u);

  const std::string packed = bgeo::scfContainer(binary);
  refuse("cut.bgeo.sc", packed.substr(0, packed.size() - 1), {"scf1 container without its footer"});
  std::string badIndex = packed;
  badIndex[badIndex.size() - 13] ^= 1;  // the decoded size in the index
  refuse("index.bgeo.sc", badIndex, {"scf1 index", "decoded size"});
  std::string badChunk = packed;
  badChunk[12 + 15] = char(0x7f);  // the chunk's compressed size
  refuse("chunk.bgeo.sc", badChunk, {"scf1 chunk 0 at byte 12", "compressed size", "does not fit"});
}

// ---- Damage ----

/// The real files the damage tests start from, else synthetic ones (CI without ../shared).
std::vector<std::pair<std::string, std::string>> smallFiles() {
  std::vector<std::pair<std::string, std::string>> files;
  for (const fs::path& path : {kModern / "points_noprim_15.bgeo", kModern / "points_noprim_15.geo",
                               kCompressed / "labs_star.1.bgeo.sc"})
    if (fs::exists(path)) files.emplace_back(path.filename().string(), fileBytes(path));
  const bgeo::Geometry g = richGeometry(40, 16, true);
  files.emplace_back("synthetic.bgeo", bgeo::geometryBytes(g, bgeo::Encoding::Binary));
  files.emplace_back("synthetic.bgeo.sc", bgeo::scfContainer(bgeo::geometryBytes(g, bgeo::Encoding::Binary), 600));
  return files;
}

/// Reads everything twice (rewind between); FileError passes through, nothing else may.
void readTwice(const std::string& name, const std::string& bytes) {
  ReadOptions options;
  options.allAttributes = true;
  auto source = openParticleBytes(name, spanOf(bytes), options);
  ParticleChunk chunk;
  while (source->read(chunk, 3)) {
  }
  source->rewind();
  while (source->read(chunk, 1000)) {
  }
}

TEST(HoudiniReader, RefusesEveryTruncatedLength) {
  for (const auto& [name, bytes] : smallFiles()) {
    SCOPED_TRACE(name);
    readTwice(name, bytes);
    // ASCII: cutting the white space after the last ']' leaves a whole file.
    std::size_t complete = bytes.size();
    if (name.ends_with(".geo"))
      while (complete > 0 && std::isspace(static_cast<unsigned char>(bytes[complete - 1]))) --complete;
    for (std::size_t length = 0; length < complete; length += testing::damageSweepStride()) {
      try {
        readTwice(name, bytes.substr(0, length));
        ADD_FAILURE() << "a file cut to " << length << " of " << bytes.size() << " bytes was read";
      } catch (const FileError&) {
      }
    }
  }
}

TEST(HoudiniReader, SurvivesEverySingleByteCorruption) {
  std::size_t refused = 0, accepted = 0;
  for (const auto& [name, bytes] : smallFiles()) {
    SCOPED_TRACE(name);
    for (std::size_t at = 0; at < bytes.size(); at += testing::damageSweepStride())
      for (int change : {0x00, 0xff, 0x01, 0x80}) {
        std::string damaged = bytes;
        damaged[at] = change == 0x00 || change == 0xff ? char(change) : char(damaged[at] ^ change);
        if (damaged == bytes) continue;
        try {
          readTwice(name, damaged);
          ++accepted;
        } catch (const FileError&) {
          ++refused;
        }
      }
  }
  std::printf("single-byte corruptions: %zu refused, %zu read (a changed value)\n", refused, accepted);
  EXPECT_GT(refused, 0u);
}

// ---- Throughput (run by hand: --gtest_also_run_disabled_tests --gtest_filter='*Throughput*') ----

TEST(HoudiniReader, DISABLED_Throughput) {
  TempDir tmp("bgeo-throughput");
  const std::uint64_t points = 5'000'000;
  bgeo::Geometry g;
  g.points = points;
  for (const char* name : {"P", "v"}) {
    bgeo::Attribute a;
    a.name = name;
    a.value = [](std::uint64_t p, int c) { return double(float(std::sin(double(p) * 1e-3 + c))); };
    g.attributes.push_back(a);
  }
  {
    std::ofstream out(tmp / "big.bgeo", std::ios::binary);
    bgeo::writeGeometry(out, g, bgeo::Encoding::Binary);
  }
  ParticleChunk raw;
  for (std::uint64_t p = 0; p < points; ++p)
    raw.positions.emplace_back(float(g.attributes[0].value(p, 0)), float(g.attributes[0].value(p, 1)),
                               float(g.attributes[0].value(p, 2)));
  testing::writeFile(tmp / "big.bin", raw, WriteOptions{}, 1 << 20);
  {
    std::string bytes = testing::readBytes(tmp / "big.bgeo");
    testing::writeBytes(tmp / "big.bgeo.sc", bgeo::scfContainer(bytes));
    std::ofstream out(tmp / "big.geo", std::ios::binary);
    bgeo::writeGeometry(out, g, bgeo::Encoding::Ascii);
  }
  auto time = [&](const fs::path& path, bool velocity) {
    double best = 1e30;
    for (int run = 0; run < 3; ++run) {
      ReadOptions options;
      options.velocity = velocity;
      const auto start = std::chrono::steady_clock::now();
      auto source = openParticleFile(path, options);
      ParticleChunk chunk;
      std::uint64_t total = 0;
      while (source->read(chunk, 1 << 20)) total += chunk.size();
      EXPECT_EQ(total, points);
      best = std::min(best, secondsSince(start));
    }
    const double megabytes = double(fs::file_size(path)) / 1e6;
    std::printf("%-12s %s: %.3f s, %.1f M points/s, %.0f MB/s of file\n", path.filename().c_str(),
                velocity ? "P+v" : "P  ", best, double(points) / best / 1e6, megabytes / best);
    return best;
  };
  const double rawTime = time(tmp / "big.bin", false);
  const double bgeoTime = time(tmp / "big.bgeo", true);
  time(tmp / "big.bgeo", false);
  time(tmp / "big.bgeo.sc", true);
  time(tmp / "big.geo", true);
  std::printf("bgeo P+v (24 bytes a point) against raw xyz (12 bytes a point): %.2fx the time\n", bgeoTime / rawTime);
}

}  // namespace
}  // namespace flipscope
