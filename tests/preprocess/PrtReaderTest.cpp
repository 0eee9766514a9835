// The Krakatoa PRT reader (preprocess/particles/PrtParticles.cpp): Thinkbox's real test files,
// every channel type and arity through the test writer (PrtTestWriter.h) in many zlib pieces and
// chunks, PRT 1.0 and 1.1 headers, an unknown count, mismatched counts, bad layouts, damage.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>

#include "DamageTestSupport.h"
#include "ParticleTestSupport.h"
#include "PrtTestWriter.h"
#include "preprocess/particles/BinaryColumns.h"
#include "preprocess/particles/ParticleFormatRegistry.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;
using testing::expectFileError;
using testing::PrtChannelSpec;
using testing::PrtType;
using testing::TempDir;

const fs::path kPrtFolder = fs::path(FLIPSCOPE_DATA_DIR) / "formats" / "krakatoa-prt";

TEST(PrtReader, RealFiles) {
  ASSERT_TRUE(fs::is_directory(kPrtFolder)) << kPrtFolder;
  // prt_fractal_for_krscene.prt: PRT 1.1 with metadata, 312 particles of Position, Color,
  // Velocity (float32[3]) and Density (float32).
  ReadOptions options;
  options.allAttributes = true;
  auto source = openParticleFile(kPrtFolder / "prt_fractal_for_krscene.prt", options);
  EXPECT_EQ(source->format(), "Krakatoa PRT 1.1 (header version 2)");
  EXPECT_EQ(source->countHint(), 312u);
  EXPECT_TRUE(source->hasVelocity());
  const std::vector<AttributeDesc> expected = {
      {"Color", ValueType::Float32, 3}, {"Velocity", ValueType::Float32, 3}, {"Density", ValueType::Float32, 1}};
  EXPECT_EQ(source->attributes(), expected);
  ParticleChunk all, chunk;
  std::vector<float> density;
  while (source->read(chunk, 100)) {
    all.positions.insert(all.positions.end(), chunk.positions.begin(), chunk.positions.end());
    ASSERT_EQ(chunk.attributes.size(), 3u);
    density.insert(density.end(), chunk.attributes[2].values.begin(), chunk.attributes[2].values.end());
  }
  ASSERT_EQ(all.size(), 312u);
  EXPECT_EQ(all.positions[0], glm::vec3(0.294915289f, -0.287722528f, -0.532819271f));
  EXPECT_EQ(all.positions[1], glm::vec3(-0.0616526902f, -0.870030344f, 0.36038065f));
  EXPECT_EQ(all.positions[311], glm::vec3(0.788036287f, 0.48390168f, -0.886384249f));
  EXPECT_EQ(density[311], 1.f);
  // negative_eight.prt: a metadata chunk of length -8 (Thinkbox's regression test for an
  // endless loop): refused.
  expectFileError([&] { testing::readFile(kPrtFolder / "negative_eight.prt"); },
                  {"negative_eight.prt", "chunk 'Metb' at byte 56", "length -8"});
}

/// A value every type stores exactly, for particle p, channel i, component c.
double exactValue(PrtType type, std::size_t p, std::size_t i, int c) {
  const double k = double((p * 7 + i * 13 + std::size_t(c) * 5) % 97);
  switch (type) {
    case PrtType::Int8:
      return k - 48;
    case PrtType::UInt8:
      return k + 150;
    case PrtType::Int16:
      return (k - 48) * 600;
    case PrtType::UInt16:
      return k * 650;
    case PrtType::Int32:
      return (k - 48) * 40000000;
    case PrtType::UInt32:
      return k * 40000000;
    case PrtType::Int64:
      return (k - 48) * 1099511627776.0;  // k * 2^40: exact in float
    case PrtType::UInt64:
      return k * 1099511627776.0 * 1024;
    case PrtType::Float16:
      return (k - 48) * 0.5;
    case PrtType::Float32:
      return (k - 48) * 0.375 + double(p);
    case PrtType::Float64:
      return (k - 48) * 0.0625 - double(p) * 2;
  }
  return 0;
}

constexpr PrtType kAllTypes[] = {PrtType::Int8,    PrtType::UInt8,   PrtType::Int16,  PrtType::UInt16,
                                 PrtType::Int32,   PrtType::UInt32,  PrtType::Int64,  PrtType::UInt64,
                                 PrtType::Float16, PrtType::Float32, PrtType::Float64};

TEST(PrtReader, EveryTypeAndArityRoundTrips) {
  TempDir dir("prt-types");
  std::vector<PrtChannelSpec> channels;
  for (PrtType position : {PrtType::Float16, PrtType::Float32, PrtType::Float64}) {
    channels = {{"Position", position, 3}, {"Velocity", PrtType::Float32, 3}};
    int n = 0;
    for (PrtType type : kAllTypes)
      for (int arity : {1, 2, 3, 4, 7}) channels.push_back({"c" + std::to_string(n++), type, arity});
    const std::size_t count = 701;
    auto value = [&](std::size_t p, std::size_t i, int c) { return exactValue(channels[i].type, p, i, c); };
    for (int version : {1, 2})
      for (bool reverse : {false, true}) {
        testing::PrtWriteOptions options;
        options.version = version;
        options.reverseOffsets = reverse;
        options.piece = 500;  // many sync-flushed pieces, records split across them
        testing::writeBytes(dir / "all.prt", testing::makePrt(channels, count, value, options));
        for (std::size_t chunkSize : {std::size_t(7), std::size_t(333), count}) {
          SCOPED_TRACE("position " + std::to_string(int(position)) + " version " + std::to_string(version) +
                       (reverse ? " reversed" : "") + " chunks of " + std::to_string(chunkSize));
          ReadOptions read;
          read.allAttributes = true;
          auto source = openParticleFile(dir / "all.prt", read);
          ASSERT_EQ(source->attributes().size(), channels.size() - 1);
          EXPECT_EQ(source->attributes()[0], (AttributeDesc{"Velocity", ValueType::Float32, 3}));
          EXPECT_EQ(source->attributes()[1 + 8 * 5], (AttributeDesc{"c40", ValueType::Float16, 1}));
          ASSERT_TRUE(source->hasVelocity());
          std::size_t p = 0;
          ParticleChunk chunk;
          while (source->read(chunk, chunkSize)) {
            ASSERT_LE(chunk.size(), chunkSize);
            ASSERT_EQ(chunk.attributes.size(), channels.size() - 1);
            for (std::size_t k = 0; k < chunk.size(); ++k, ++p) {
              for (int c = 0; c < 3; ++c) {
                ASSERT_EQ(chunk.positions[k][c], float(value(p, 0, c))) << p;
                ASSERT_EQ(chunk.velocities[k][c], float(value(p, 1, c))) << p;
              }
              for (std::size_t i = 2; i < channels.size(); ++i)
                for (int c = 0; c < channels[i].arity; ++c)
                  ASSERT_EQ(chunk.attributes[i - 1].values[k * std::size_t(channels[i].arity) + std::size_t(c)],
                            float(value(p, i, c)))
                      << "particle " << p << " channel " << channels[i].name;
            }
          }
          EXPECT_EQ(p, count);
        }
      }
  }
}

TEST(PrtReader, UnknownCountReadsTheWholeStream) {
  TempDir dir("prt-unknown");
  testing::PrtWriteOptions options;
  options.unknownCount = true;
  const std::vector<PrtChannelSpec> channels = {{"Position", PrtType::Float32, 3}};
  auto value = [](std::size_t p, std::size_t, int c) { return double(p) + c * 0.25; };
  testing::writeBytes(dir / "unknown.prt", testing::makePrt(channels, 2500, value, options));
  auto source = openParticleFile(dir / "unknown.prt");
  EXPECT_FALSE(source->countHint().has_value());
  EXPECT_FALSE(source->hasVelocity());
  for (int pass = 0; pass < 2; ++pass) {
    const ParticleChunk all = testing::readAll(*source, 1000);
    ASSERT_EQ(all.size(), 2500u);
    EXPECT_EQ(all.positions[2499], glm::vec3(2499.f, 2499.25f, 2499.5f));
    source->rewind();
  }
}

TEST(PrtReader, RefusesInconsistentFiles) {
  TempDir dir("prt-refuse");
  auto value = [](std::size_t p, std::size_t, int) { return double(p); };
  const std::vector<PrtChannelSpec> channels = {{"Position", PrtType::Float32, 3}, {"id", PrtType::Int32, 1}};
  std::string bytes = testing::makePrt(channels, 10, value, {.version = 1});
  // The header declares more, or fewer, particles than the stream holds.
  std::string more = bytes, fewer = bytes;
  more[48] = 11;
  fewer[48] = 9;
  testing::writeBytes(dir / "more.prt", more);
  testing::writeBytes(dir / "fewer.prt", fewer);
  expectFileError([&] { testing::readFile(dir / "more.prt"); }, {"more.prt", "after 10 of the 11 particles"});
  expectFileError([&] { testing::readFile(dir / "fewer.prt"); }, {"fewer.prt", "more than the 9 particles"});
  testing::writeBytes(dir / "tail.prt", bytes + "junk");
  expectFileError([&] { testing::readFile(dir / "tail.prt"); }, {"tail.prt", "4 bytes of trailing garbage"});
  // No Position, or a Position that is not 3 floats; overlapping channels; an unknown type.
  testing::writeBytes(dir / "nopos.prt", testing::makePrt({{"P", PrtType::Float32, 3}}, 2, value));
  expectFileError([&] { testing::readFile(dir / "nopos.prt"); }, {"nopos.prt", "no Position channel", "P float32[3]"});
  testing::writeBytes(dir / "intpos.prt", testing::makePrt({{"Position", PrtType::Int32, 3}}, 2, value));
  expectFileError([&] { testing::readFile(dir / "intpos.prt"); }, {"intpos.prt", "Position channel is int32[3]"});
  std::string overlap = bytes;
  const std::size_t idOffsetAt = 56 + 12 + 44 + 40;  // the second channel's offset field
  overlap[idOffsetAt] = 8;
  testing::writeBytes(dir / "overlap.prt", overlap);
  expectFileError([&] { testing::readFile(dir / "overlap.prt"); }, {"overlap.prt", "channel 'id'", "overlaps"});
  std::string type = bytes;
  type[56 + 12 + 32] = 11;
  testing::writeBytes(dir / "type.prt", type);
  expectFileError([&] { testing::readFile(dir / "type.prt"); }, {"type.prt", "unknown data type 11"});
  std::string version = bytes;
  version[44] = 3;
  testing::writeBytes(dir / "version.prt", version);
  expectFileError([&] { testing::readFile(dir / "version.prt"); }, {"version.prt", "header version 3"});
  // Damaged zlib data.
  std::string damaged = bytes;
  damaged[damaged.size() - 6] ^= 0x55;
  testing::writeBytes(dir / "damaged.prt", damaged);
  expectFileError([&] { testing::readFile(dir / "damaged.prt"); }, {"damaged.prt", "PRT: "});
}

TEST(PrtReader, TruncatedAtEveryLengthIsRefused) {
  const std::vector<PrtChannelSpec> channels = {{"Position", PrtType::Float16, 3}, {"Velocity", PrtType::Float64, 3}};
  auto value = [](std::size_t p, std::size_t i, int c) { return double(p + i) * 0.5 + c; };
  testing::expectEveryTruncationRefused("small.prt", testing::makePrt(channels, 40, value, {.piece = 64}));
  testing::expectEveryTruncationRefused("fractal.prt", testing::readBytes(kPrtFolder / "prt_fractal_for_krscene.prt"));
}

TEST(PrtReader, SingleByteCorruptionsAreReadOrRefused) {
  const std::vector<PrtChannelSpec> channels = {{"Position", PrtType::Float32, 3}, {"Density", PrtType::UInt8, 1}};
  auto value = [](std::size_t p, std::size_t, int c) { return double(p * 3 + std::size_t(c)); };
  const std::string bytes = testing::makePrt(channels, 30, value);
  // More refusals than bytes changed: most of the four changes of a header byte are refused.
  EXPECT_GT(testing::expectCorruptionsHandled("small.prt", bytes), bytes.size() / testing::damageSweepStride());
}

TEST(HalfFloat, EveryClassOfValue) {
  using detail::halfToFloat;
  EXPECT_EQ(halfToFloat(0x0000), 0.f);
  EXPECT_TRUE(std::signbit(halfToFloat(0x8000)));
  EXPECT_EQ(halfToFloat(0x3c00), 1.f);
  EXPECT_EQ(halfToFloat(0xc000), -2.f);
  EXPECT_EQ(halfToFloat(0x7bff), 65504.f);               // largest finite
  EXPECT_EQ(halfToFloat(0x0400), std::ldexp(1.f, -14));  // smallest normal
  EXPECT_EQ(halfToFloat(0x0001), std::ldexp(1.f, -24));  // smallest subnormal
  EXPECT_EQ(halfToFloat(0x03ff), std::ldexp(1023.f, -24));
  EXPECT_EQ(halfToFloat(0x3555), 0.333251953125f);
  EXPECT_EQ(halfToFloat(0x7c00), std::numeric_limits<float>::infinity());
  EXPECT_EQ(halfToFloat(0xfc00), -std::numeric_limits<float>::infinity());
  EXPECT_TRUE(std::isnan(halfToFloat(0x7e00)));
  for (std::uint32_t bits = 0; bits < 0x7c00; ++bits)  // every finite half survives float and back
    ASSERT_EQ(testing::floatToHalf(halfToFloat(std::uint16_t(bits))), bits) << bits;
}

}  // namespace
}  // namespace flipscope
