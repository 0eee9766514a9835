// Particle readers: chunking, rewind, concatenation, NaN pass-through, every PLY scalar type
// against an independent PLY encoder, and the error messages for malformed files.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "GzipTestWriter.h"
#include "ParticleTestSupport.h"
#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleFormatRegistry.h"

namespace flipscope {
namespace {

using testing::expectFileError;
using testing::randomParticles;
using testing::readAll;
using testing::readBytes;
using testing::readFile;
using testing::sameBits;
using testing::TempDir;
using testing::writeBytes;
using testing::writeFile;

bool sameParticles(const ParticleChunk& a, const ParticleChunk& b) {
  if (a.size() != b.size() || a.velocities.size() != b.velocities.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!sameBits(a.positions[i], b.positions[i]) ||
        (!a.velocities.empty() && !sameBits(a.velocities[i], b.velocities[i])))
      return false;
  return true;
}

// ---- An independent PLY encoder (the oracle for the reader) ----

struct PlyColumn {
  std::string type;  // PLY type name
  std::string name;
};

std::size_t typeBytes(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "double" || type == "float64") return 8;
  return 4;
}

void appendBinary(std::string& out, const std::string& type, double value, bool bigEndian) {
  char bytes[8];
  std::size_t n = typeBytes(type);
  if (type == "float" || type == "float32") {
    float f = float(value);
    std::memcpy(bytes, &f, 4);
  } else if (type == "double" || type == "float64") {
    std::memcpy(bytes, &value, 8);
  } else if (type[0] == 'u') {
    auto u = static_cast<std::uint64_t>(value);
    std::memcpy(bytes, &u, n);  // little-endian host: low bytes first
  } else {
    auto s = static_cast<std::int64_t>(value);
    std::memcpy(bytes, &s, n);
  }
  if (bigEndian) std::reverse(bytes, bytes + n);
  out.append(bytes, n);
}

std::string encodePly(const std::string& format, const std::vector<PlyColumn>& columns,
                      const std::vector<std::vector<double>>& rows, const std::string& trailingElements = "") {
  std::string out = "ply\nformat " + format + " 1.0\ncomment made by test_readers\nelement vertex " +
                    std::to_string(rows.size()) + "\n";
  for (const auto& c : columns) out += "property " + c.type + " " + c.name + "\n";
  out += trailingElements + "end_header\n";
  for (const auto& row : rows) {
    for (std::size_t i = 0; i < columns.size(); ++i) {
      if (format == "ascii") {
        char text[64];
        std::snprintf(text, sizeof text, "%.17g", row[i]);
        out += text + std::string(i + 1 < columns.size() ? " " : "\n");
      } else {
        appendBinary(out, columns[i].type, row[i], format == "binary_big_endian");
      }
    }
  }
  return out;
}

TEST(PlyReader, EveryScalarTypeAndEncodingAgainstEncoder) {
  const std::vector<std::string> types = {"char", "uchar", "short", "ushort", "int",   "uint",   "float",   "double",
                                          "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};
  const std::vector<std::string> fields = {"x", "y", "z", "vx", "vy", "vz"};
  std::mt19937 rng(99);
  TempDir dir("ply-types");
  for (int trial = 0; trial < 60; ++trial) {
    // Random layout: the six fields in random order with random types, plus skipped columns.
    std::vector<PlyColumn> columns;
    bool velocity = trial % 2 == 0;
    for (std::size_t f = 0; f < (velocity ? 6u : 3u); ++f) columns.push_back({types[rng() % types.size()], fields[f]});
    for (int extra = rng() % 4; extra > 0; --extra)
      columns.push_back({types[rng() % types.size()], "attr" + std::to_string(extra)});
    columns.push_back({"uchar", "red"});
    std::shuffle(columns.begin(), columns.end(), rng);
    std::vector<std::vector<double>> rows(rng() % 40 + 1);
    for (auto& row : rows)
      for (const auto& c : columns) {
        double v = double(rng() % 128);  // fits every type, int8 and unsigned included
        if (c.type.find("float") != std::string::npos || c.type == "double")
          v = (double(rng()) / rng.max() - 0.5) * 1e3;
        row.push_back(c.type == "float" || c.type == "float32" ? double(float(v)) : v);
      }
    const char* formats[] = {"ascii", "binary_little_endian", "binary_big_endian"};
    std::string format = formats[trial % 3];
    auto path = dir / ("t" + std::to_string(trial) + ".ply");
    writeBytes(path, encodePly(format, columns, rows,
                               trial % 5 == 0 ? "element face 3\nproperty list uchar int vertex_indices\n" : ""));
    auto source = openParticleFile(path);
    ASSERT_EQ(source->hasVelocity(), velocity);
    auto read = readAll(*source, 7);
    ASSERT_EQ(read.size(), rows.size());
    for (std::size_t r = 0; r < rows.size(); ++r)
      for (std::size_t c = 0; c < columns.size(); ++c)
        for (std::size_t f = 0; f < fields.size(); ++f)
          if (columns[c].name == fields[f]) {
            float got = f < 3 ? read.positions[r][int(f)] : read.velocities[r][int(f - 3)];
            ASSERT_EQ(got, float(rows[r][c])) << format << " " << columns[c].type << " " << fields[f] << " row " << r;
          }
    // Random access to every other particle and the last one: binary files only.
    std::vector<std::uint64_t> some;
    for (std::uint64_t r = 0; r < rows.size(); r += 2) some.push_back(r);
    if (some.back() + 1 != rows.size()) some.push_back(rows.size() - 1);
    std::vector<glm::vec3> picked;
    ASSERT_EQ(source->readPositionsAt(some, picked), format != "ascii") << format;
    if (format == "ascii") continue;
    ASSERT_EQ(picked.size(), some.size());
    for (std::size_t i = 0; i < some.size(); ++i)
      ASSERT_EQ(picked[i], read.positions[some[i]]) << format << " particle " << some[i];
  }
}

TEST(PlyReader, NaNPassesThrough) {
  TempDir dir("ply-nan");
  std::vector<std::vector<double>> rows = {{1, 2, 3}, {NAN, 5, INFINITY}, {7, -NAN, 9}};
  for (std::string format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    writeBytes(dir / "n.ply", encodePly(format, {{"float", "x"}, {"double", "y"}, {"float", "z"}}, rows));
    auto read = readFile(dir / "n.ply");
    ASSERT_EQ(read.size(), 3u);
    EXPECT_EQ(read.positions[0], glm::vec3(1, 2, 3)) << format;
    EXPECT_TRUE(std::isnan(read.positions[1].x)) << format;
    EXPECT_TRUE(std::isinf(read.positions[1].z)) << format;
    EXPECT_TRUE(std::isnan(read.positions[2].y)) << format;
  }
}

TEST(RawReader, NaNPassesThrough) {
  TempDir dir("raw-nan");
  auto particles = randomParticles(50, false, 4);
  particles.positions[3].x = NAN;
  particles.positions[17].z = -INFINITY;
  writeFile(dir / "n.raw", particles, WriteOptions{});
  EXPECT_TRUE(sameParticles(readFile(dir / "n.raw", 8), particles));
}

// A chunk read into again holds what the reader gives and nothing of before: a column a wrapper
// added (convert's TypedSource appends the particles' types) or velocities; positions that grow
// over the last read's are still the file's.
TEST(RawReader, AChunkReadIntoAgainHoldsOnlyItsPositions) {
  TempDir dir("raw-again");
  auto particles = randomParticles(50, false, 4);
  writeFile(dir / "a.raw", particles, WriteOptions{});
  auto source = openParticleFile(dir / "a.raw");
  ParticleChunk chunk;
  std::size_t at = 0;
  for (std::size_t size : {8, 8, 20, 30}) {
    chunk.attributes.push_back({"types", 1, std::vector<float>(chunk.size(), 0.0f)});
    chunk.velocities.assign(chunk.size(), glm::vec3(1));
    ASSERT_TRUE(source->read(chunk, size));
    const std::size_t expected = std::min<std::size_t>(size, 50 - at);
    ASSERT_EQ(chunk.size(), expected);
    EXPECT_TRUE(chunk.attributes.empty());
    EXPECT_TRUE(chunk.velocities.empty());
    for (std::size_t i = 0; i < expected; ++i) ASSERT_EQ(chunk.positions[i], particles.positions[at + i]) << at + i;
    at += expected;
  }
  EXPECT_FALSE(source->read(chunk, 8));
}

// ---- Malformed files ----

TEST(RawReader, SizeNotMultipleOf12) {
  TempDir dir("raw-bad");
  writeBytes(dir / "r.bin", std::string(25, 'x'));
  expectFileError([&] { openParticleFile(dir / "r.bin"); }, {"r.bin", "25 bytes", "not a multiple of 12"});
}

std::string plyHeader(const std::string& body) { return "ply\n" + body + "end_header\n"; }

TEST(PlyReader, MalformedHeaders) {
  TempDir dir("ply-bad");
  auto path = dir / "bad.ply";
  struct Case {
    std::string bytes;
    std::vector<std::string> message;
  };
  const std::string xyz = "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n";
  std::vector<Case> cases = {
      {"plx\nformat ascii 1.0\n", {"bad magic"}},
      {"", {"bad magic"}},
      {plyHeader("format binary_middle_endian 1.0\n" + xyz), {"line 2", "unknown format 'binary_middle_endian'"}},
      {plyHeader("format ascii 2.0\n" + xyz), {"unknown format version '2.0'"}},
      {plyHeader("format ascii 1.0\nelement vertex 1\nproperty float x\nproperty float z\n"), {"no property 'y'"}},
      {plyHeader("format ascii 1.0\nelement vertex 1\nproperty half x\n"),
       {"line 4", "unknown property type 'half' for 'x'"}},
      {plyHeader("format ascii 1.0\n" + xyz + "property list uchar int n\n"),
       {"list property 'n' in the vertex element"}},
      {plyHeader("format ascii 1.0\nelement vertex many\n"), {"malformed element count 'many'"}},
      {plyHeader("format ascii 1.0\nelement face 2\nproperty list uchar int i\n" + xyz),
       {"element 'face' before the vertex"}},
      {plyHeader("format ascii 1.0\nelement face 0\n"), {"no vertex element"}},
      {plyHeader(xyz), {"before a format line"}},
      {"ply\nformat ascii 1.0\n" + xyz, {"ends before end_header"}},
      {plyHeader("format ascii 1.0\nbogus\n" + xyz), {"unknown keyword 'bogus'"}},
  };
  for (const auto& c : cases) {
    writeBytes(path, c.bytes);
    auto message = c.message;
    message.push_back("bad.ply");
    expectFileError([&] { readFile(path); }, message);
  }
}

TEST(PlyReader, TruncatedBinaryDataAtEveryLength) {
  TempDir dir("ply-truncated");
  std::vector<PlyColumn> columns = {{"double", "x"}, {"uchar", "red"}, {"float", "y"}, {"float", "z"}};
  std::vector<std::vector<double>> rows(20, {1.5, 200, -2.5, 3.25});
  for (std::string format : {"binary_little_endian", "binary_big_endian"}) {
    std::string full = encodePly(format, columns, rows);
    const std::size_t stride = 17, dataStart = full.size() - rows.size() * stride;
    for (std::size_t cut = dataStart; cut < full.size(); cut += 5) {
      writeBytes(dir / "t.ply", full.substr(0, cut));
      std::size_t whole = (cut - dataStart) / stride;
      expectFileError([&] { readFile(dir / "t.ply"); },
                      {"t.ply", "file ends at particle " + std::to_string(whole) + " of 20",
                       "byte offset " + std::to_string(dataStart + whole * stride)});
    }
  }
}

TEST(PlyReader, AsciiErrorsNameTheLine) {
  TempDir dir("ply-ascii-bad");
  std::string header =
      plyHeader("format ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n");
  writeBytes(dir / "a.ply", header + "1 2 3\n4 abc 6\n7 8 9\n");
  expectFileError([&] { readFile(dir / "a.ply"); }, {"a.ply", "line 9", "malformed number 'abc' for property 'y'"});
  writeBytes(dir / "a.ply", header + "1 2 3\n4 5e 6\n7 8 9\n");
  expectFileError([&] { readFile(dir / "a.ply"); }, {"line 9", "malformed number '5e'"});
  writeBytes(dir / "a.ply", header + "1 2 3\n4 5\n");
  expectFileError([&] { readFile(dir / "a.ply"); }, {"line 9", "expected 3 values for a vertex, found 2"});
  writeBytes(dir / "a.ply", header + "1 2 3\n4 5 6\n");
  expectFileError([&] { readFile(dir / "a.ply"); }, {"file ends at particle 2 of 3", "line 10"});
}

// ---- Chunking, rewind, concatenation, dispatch ----

std::vector<std::filesystem::path> writeEveryFormat(const TempDir& dir, const ParticleChunk& particles) {
  std::vector<std::filesystem::path> paths;
  WriteOptions options;
  options.velocity = !particles.velocities.empty();
  for (const char* name : {"c.bin", "c.ply", "c.vdb"}) {
    paths.push_back(dir / name);
    writeFile(paths.back(), particles, options);
  }
  return paths;
}

TEST(ParticleSource, RandomAccessGivesTheParticlesOfAReadAndLeavesTheReadWhereItWas) {
  TempDir dir("random-access");
  const std::vector<std::uint64_t> some{0, 1, 17, 600, 899};
  std::size_t seeking = 0;
  for (const auto& path : writeEveryFormat(dir, randomParticles(900, true, 33))) {
    auto source = openParticleFile(path);
    const ParticleChunk reference = readAll(*source, 1 << 20);
    source->rewind();
    ParticleChunk chunk;
    ASSERT_TRUE(source->read(chunk, 100));
    std::vector<glm::vec3> picked, range;
    if (source->readPositionsAt(some, picked)) {
      ++seeking;
      ASSERT_EQ(picked.size(), some.size()) << path;
      for (std::size_t i = 0; i < some.size(); ++i)
        EXPECT_TRUE(sameBits(picked[i], reference.positions[some[i]])) << path;
      // ... and by range: particles 650 to 899, the last ones.
      ASSERT_TRUE(source->readPositionRange(0, 0, range)) << path;
      EXPECT_TRUE(range.empty());
      ASSERT_TRUE(source->readPositionRange(650, 250, range)) << path;
      ASSERT_EQ(range.size(), 250u);
      for (std::size_t i = 0; i < range.size(); ++i)
        EXPECT_TRUE(sameBits(range[i], reference.positions[650 + i])) << path;
    } else {
      EXPECT_FALSE(source->readPositionRange(0, 10, range)) << path;
    }
    ASSERT_TRUE(source->read(chunk, 100));
    EXPECT_TRUE(sameBits(chunk.positions[0], reference.positions[100])) << path << ": the read moved";
    // Compressed, the same particles are no cheaper to reach than by reading: no random access.
    if (path.extension() != ".ply") continue;
    writeBytes(dir / "packed.ply.gz", testing::gzip(readBytes(path)));
    EXPECT_FALSE(openParticleFile(dir / "packed.ply.gz")->readPositionsAt(some, picked));
    EXPECT_FALSE(openParticleFile(dir / "packed.ply.gz")->readPositionRange(0, 10, range));
  }
  EXPECT_EQ(seeking, 2u) << "raw and binary PLY seek to a particle";
}

TEST(InputFile, ManyScatteredReadsOnTwoThreadsGiveEveryRangeAndAShortOneNamesTheFile) {
  TempDir dir("scattered");
  std::string bytes(1 << 16, '\0');
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = char(i % 251);
  writeBytes(dir / "bytes.bin", bytes);
  InputFile file(dir / "bytes.bin");
  std::vector<std::uint64_t> offsets;  // more than one thread's share, and up to the last byte
  for (std::uint64_t at = 0; at + 7 <= bytes.size(); at += 21) offsets.push_back(at);
  offsets.push_back(bytes.size() - 7);
  ASSERT_GT(offsets.size(), 2048u);
  std::vector<std::byte> got(offsets.size() * 7);
  ASSERT_TRUE(file.readScattered(offsets, 7, got.data()));
  for (std::size_t i = 0; i < offsets.size(); ++i)
    ASSERT_EQ(std::memcmp(got.data() + i * 7, bytes.data() + offsets[i], 7), 0) << "range " << i;
  offsets.back() = bytes.size() - 3;  // ends past the file, on the second thread's share
  expectFileError([&] { file.readScattered(offsets, 7, got.data()); }, {"bytes.bin", "file ends before byte 65540"});
}

/// Bytes in memory that say half their ranges are cached: readIfCached gives the ranges at even
/// multiples of `stride` and scribbles over the others before turning them away, which willRead
/// and readAt must then announce and read.
class HalfCachedBytes final : public ByteSource {
 public:
  HalfCachedBytes(std::string bytes, std::uint64_t stride) : mBytes(std::move(bytes)), mStride(stride) {}
  std::uint64_t size() const override { return mBytes.size(); }
  std::size_t readAt(std::uint64_t offset, void* data, std::size_t bytes) override {
    ++reads;
    const std::size_t n = offset >= mBytes.size() ? 0 : std::min<std::size_t>(bytes, mBytes.size() - offset);
    std::memcpy(data, mBytes.data() + offset, n);
    return n;
  }
  bool randomAccess() const override { return true; }
  void willRead(std::span<const std::uint64_t> offsets, std::size_t) override {
    announced += offsets.size();
    for (const std::uint64_t offset : offsets)
      if ((offset / mStride) % 2 == 0) ++announcedCached;
  }
  bool readIfCached(std::uint64_t offset, void* data, std::size_t bytes) override {
    if ((offset / mStride) % 2 == 0) return readAt(offset, data, bytes) == bytes;
    std::memset(data, 0xaa, bytes);
    return false;
  }
  std::atomic<std::size_t> reads{0}, announced{0}, announcedCached{0};

 private:
  std::string mBytes;
  std::uint64_t mStride;
};

// Ranges the source has cached are read once; the others (scribbled over by the failed try) are
// announced and read: on two threads, every range holds its bytes.
TEST(InputFile, ScatteredRangesTheSourceHasNotCachedAreAnnouncedAndReadAgain) {
  std::string bytes(std::size_t(1) << 16, '\0');
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = char((i * 7) % 253);
  auto source = std::make_unique<HalfCachedBytes>(bytes, 16);
  HalfCachedBytes& half = *source;
  InputFile file("half-cached.bin", std::move(source));
  std::vector<std::uint64_t> offsets;
  for (std::uint64_t at = 0; at + 16 <= bytes.size(); at += 16) offsets.push_back(at);
  ASSERT_GT(offsets.size(), 2048u);  // both threads' shares
  std::vector<std::byte> got(offsets.size() * 9);
  ASSERT_TRUE(file.readScattered(offsets, 9, got.data()));
  for (std::size_t i = 0; i < offsets.size(); ++i)
    ASSERT_EQ(std::memcmp(got.data() + i * 9, bytes.data() + offsets[i], 9), 0) << "range " << i;
  EXPECT_EQ(half.announced.load(), offsets.size() / 2);
  EXPECT_EQ(half.announcedCached.load(), 0u);
  EXPECT_EQ(half.reads.load(), offsets.size());  // each range read once: from the cache, or after
}

// Scattered ranges come from the page cache in one read each where cached, and through an
// announcement and a read where not: either way, from a file dropped from the cache, then
// cached, every range holds its bytes, those across a page boundary too.
TEST(InputFile, ScatteredRangesOfAColdFileAndThenOfACachedOneGiveTheirBytes) {
  TempDir dir("scattered-cold");
  std::string bytes(std::size_t(4) << 20, '\0');
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = char((i * 131) % 251);
  writeBytes(dir / "bytes.bin", bytes);
  std::vector<std::uint64_t> offsets;
  for (std::uint64_t page = 1; page * 4096 + 16 < bytes.size(); page += 3) offsets.push_back(page * 4096 - 5);
  ASSERT_GT(offsets.size(), 300u);
  const bool cold = testing::dropFromPageCache(dir / "bytes.bin");
  for (const char* state : {"cold", "cached"}) {
    InputFile file(dir / "bytes.bin");
    std::vector<std::byte> got(offsets.size() * 11);
    ASSERT_TRUE(file.readScattered(offsets, 11, got.data())) << state;
    for (std::size_t i = 0; i < offsets.size(); ++i)
      ASSERT_EQ(std::memcmp(got.data() + i * 11, bytes.data() + offsets[i], 11), 0) << state << ", range " << i;
  }
  if (!cold) std::printf("note: the file could not be dropped from the page cache here (tmpfs?)\n");
}

// The buffer's first fill is short (64 KiB, a header's), the next ones 1 MiB: lines, and small
// reads across the end of each kind of fill, give every byte.
TEST(InputFile, LinesAndSmallReadsAcrossTheShortFirstFillAndTheFullOnesGiveEveryByte) {
  TempDir dir("fills");
  std::string text;
  for (int i = 0; text.size() < (std::size_t(5) << 19); ++i)  // 2.5 MiB of lines of 1 to 300 bytes
    text += std::string(std::size_t(1 + (i * 7919) % 300), char('a' + i % 26)) + (i % 3 ? "\n" : "\r\n");
  writeBytes(dir / "lines.txt", text);
  InputFile file(dir / "lines.txt");
  std::string expected, line;
  std::size_t lines = 0;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = text.find('\n', at);
    expected = text.substr(at, end - at);
    if (!expected.empty() && expected.back() == '\r') expected.pop_back();
    ASSERT_TRUE(file.readLine(line, 1000)) << "line " << lines;
    ASSERT_EQ(line, expected) << "line " << lines;
    at = end + 1;
    ++lines;
  }
  EXPECT_FALSE(file.readLine(line, 1000));
  // Small reads in order on a file opened afresh: inside the first fill, across its end into a
  // full one, across that one's end, and the file's last bytes.
  InputFile fresh(dir / "lines.txt");
  std::uint64_t at = 0;
  for (const std::size_t n : {std::size_t(65530), std::size_t(13), std::size_t((1 << 20) - 20), std::size_t(13)}) {
    std::string got(n, '\0');
    ASSERT_EQ(fresh.read(got.data(), n), n) << "at " << at;
    ASSERT_EQ(got, text.substr(at, n)) << "at " << at;
    at += n;
  }
  fresh.seek(text.size() - 9);
  std::string tail(13, '\0');
  ASSERT_EQ(fresh.read(tail.data(), tail.size()), 9u);
  EXPECT_EQ(tail.substr(0, 9), text.substr(text.size() - 9));
}

TEST(ParticleSource, ChunkSizeDoesNotChangeTheParticles) {
  TempDir dir("chunks");
  for (const auto& path : writeEveryFormat(dir, randomParticles(2500, true, 31))) {
    auto reference = readFile(path, 1 << 20);
    ASSERT_EQ(reference.size(), 2500u) << path;
    for (std::size_t maxParticles : {1u, 7u, 1000u})
      EXPECT_TRUE(sameParticles(readFile(path, maxParticles), reference)) << path << " " << maxParticles;
  }
}

TEST(ParticleSource, RewindRestarts) {
  TempDir dir("rewind");
  for (const auto& path : writeEveryFormat(dir, randomParticles(900, true, 32))) {
    auto source = openParticleFile(path);
    auto reference = readAll(*source, 1 << 20);
    source->rewind();
    ParticleChunk chunk;
    ASSERT_TRUE(source->read(chunk, 100));
    ASSERT_TRUE(source->read(chunk, 100));
    source->rewind();
    EXPECT_TRUE(sameParticles(readAll(*source, 64), reference)) << path;
  }
}

TEST(ParticleSource, ConcatenatedReadsPartsInOrder) {
  TempDir dir("concat");
  auto a = randomParticles(300, true, 41), b = randomParticles(200, true, 42);
  WriteOptions withVelocity;
  withVelocity.velocity = true;
  writeFile(dir / "a.ply", a, withVelocity);
  writeFile(dir / "b.ply", b, withVelocity);
  writeFile(dir / "b.bin", b, WriteOptions{});
  ParticleChunk both = a;
  both.positions.insert(both.positions.end(), b.positions.begin(), b.positions.end());
  both.velocities.insert(both.velocities.end(), b.velocities.begin(), b.velocities.end());

  std::vector<std::unique_ptr<ParticleSource>> parts;
  parts.push_back(openParticleFile(dir / "a.ply"));
  parts.push_back(openParticleFile(dir / "b.ply"));
  auto source = concatSources(std::move(parts));
  EXPECT_TRUE(source->hasVelocity());
  EXPECT_EQ(source->countHint(), 500u);
  EXPECT_NE(source->name().find("a.ply"), std::string::npos);
  EXPECT_NE(source->name().find("b.ply"), std::string::npos);
  EXPECT_TRUE(sameParticles(readAll(*source, 77), both));
  source->rewind();
  EXPECT_TRUE(sameParticles(readAll(*source, 1000), both));

  parts.clear();
  parts.push_back(openParticleFile(dir / "a.ply"));
  parts.push_back(openParticleFile(dir / "b.bin"));
  auto mixed = concatSources(std::move(parts));
  EXPECT_FALSE(mixed->hasVelocity());
  both.velocities.clear();
  EXPECT_TRUE(sameParticles(readAll(*mixed, 128), both));
}

TEST(ParticleSource, DispatchByExtension) {
  TempDir dir("dispatch");
  auto particles = randomParticles(20, false, 51);
  writeFile(dir / "UPPER.PLY", particles, WriteOptions{});
  EXPECT_TRUE(sameParticles(readFile(dir / "UPPER.PLY"), particles));
  writeBytes(dir / "p.xyz", "1 2 3\n");
  expectFileError([&] { openParticleFile(dir / "p.xyz"); },
                  {"p.xyz", "unknown particle file format", ".vdb", ".ply", ".bin", ".raw"});
  expectFileError([&] { openParticleFile(dir / "missing.ply"); }, {"missing.ply", "no such file"});
}

// The list that unknown-format errors and `convert --help` give: every format's endings, each
// once (modern and classic Houdini share .bgeo, .geo, .bgeo.gz and .geo.gz; RealFlow and raw
// floats share .bin).
TEST(ParticleFormatRegistry, SupportedExtensionsNameEveryEndingOnce) {
  const std::string list = supportedExtensions();
  std::vector<std::string> items;
  for (std::size_t at = 0; at <= list.size();) {
    const std::size_t comma = std::min(list.find(", ", at), list.size());
    items.push_back(list.substr(at, comma - at));
    at = comma + 2;
  }
  for (const auto& format : particleFormats())
    for (auto extension : format.extensions)
      EXPECT_EQ(std::count(items.begin(), items.end(), std::string(extension)), 1) << extension << " in " << list;
  for (const auto& item : items) EXPECT_EQ(particleExtensionLength("a" + item), item.size()) << item;
}

TEST(ParticleSource, VelocityOptionOff) {
  TempDir dir("novel");
  ReadOptions options;
  options.velocity = false;
  for (const auto& path : writeEveryFormat(dir, randomParticles(50, true, 52))) {
    auto source = openParticleFile(path, options);
    EXPECT_FALSE(source->hasVelocity()) << path;
    EXPECT_EQ(readAll(*source, 10).size(), 50u);
  }
}

// ---- OpenVDB files that are not what they claim ----

TEST(VdbReader, TruncatedAndCorruptedFilesThrowFileError) {
  TempDir dir("vdb-bad");
  WriteOptions options;
  options.velocity = true;
  writeFile(dir / "good.vdb", randomParticles(3000, true, 61), options);
  std::string full = testing::readBytes(dir / "good.vdb");
  std::vector<std::size_t> cuts = {
      0, 4, 8, 16, 64, 200, full.size() / 4, full.size() / 2, full.size() * 3 / 4, full.size() - 100};
  for (std::size_t cut : cuts) {
    writeBytes(dir / "cut.vdb", full.substr(0, cut));
    expectFileError([&] { readFile(dir / "cut.vdb"); }, {"cut.vdb"});
  }
  std::mt19937 rng(62);
  std::string garbage(5000, '\0');
  for (char& c : garbage) c = char(rng());
  writeBytes(dir / "garbage.vdb", garbage);
  expectFileError([&] { readFile(dir / "garbage.vdb"); }, {"garbage.vdb"});
  // A valid header followed by garbage.
  writeBytes(dir / "tail.vdb", full.substr(0, 300) + garbage);
  expectFileError([&] { readFile(dir / "tail.vdb"); }, {"tail.vdb"});
}

TEST(VdbReader, UnknownGridNameListsTheGrids) {
  TempDir dir("vdb-grids");
  writeFile(dir / "g.vdb", randomParticles(10, false, 63), WriteOptions{});
  ReadOptions options;
  options.grids = {"nope"};
  expectFileError([&] { openParticleFile(dir / "g.vdb", options); }, {"g.vdb", "no grid named 'nope'", "'particles'"});
}

}  // namespace
}  // namespace flipscope
