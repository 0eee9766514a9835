// The gzip container (preprocess/particles/GzipContainer.cpp): gzipped files of any format read
// like the plain ones, concatenated members, random access forwards and backwards, nesting, and
// damaged or truncated gzip refused with the offset.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "ClassicBgeoTestWriter.h"
#include "DamageTestSupport.h"
#include "GzipTestWriter.h"
#include "ParticleTestSupport.h"
#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleFormatRegistry.h"
#include "preprocess/particles/ParticleFormats.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;
using testing::expectFileError;
using testing::TempDir;

std::string plyBytes(const TempDir& dir, PlyEncoding encoding, std::size_t count) {
  WriteOptions options;
  options.velocity = true;
  options.plyEncoding = encoding;
  testing::writeFile(dir / "plain.ply", testing::randomParticles(count, true, 11), options);
  return testing::readBytes(dir / "plain.ply");
}

TEST(GzipContainer, GzippedPlyReadsLikeThePlainFile) {
  TempDir dir("gzip-ply");
  for (PlyEncoding encoding : {PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian}) {
    const std::string plain = plyBytes(dir, encoding, 5000);
    const ParticleChunk expected = testing::readFile(dir / "plain.ply");
    for (int members : {1, 3}) {
      for (const char* name : {"a.ply.gz", "a.gz", "a"}) {
        SCOPED_TRACE(std::string(name) + ", " + std::to_string(members) + " members");
        testing::writeBytes(dir / name, testing::gzip(plain, members));
        const RecognisedInput input = recogniseInput(InputFile(dir / name));
        EXPECT_EQ(input.format->name, "ply");
        EXPECT_EQ(input.containers, std::vector<std::string>{"gzip"});
        EXPECT_EQ(input.file.size(), plain.size());
        auto source = openParticleFile(dir / name);
        for (int pass = 0; pass < 2; ++pass) {  // the second pass inflates again from the start
          const ParticleChunk read = testing::readAll(*source, 777);
          ASSERT_EQ(read.size(), expected.size());
          EXPECT_EQ(read.positions, expected.positions);
          EXPECT_EQ(read.velocities, expected.velocities);
          source->rewind();
        }
      }
    }
  }
}

TEST(GzipContainer, RandomAccessForwardsAndBackwards) {
  std::mt19937 rng(5);
  std::string plain(1 << 20, '\0');
  for (std::size_t i = 0; i < plain.size(); ++i) plain[i] = char(rng() % 7 == 0 ? rng() : i / 1000);
  const std::string packed = testing::gzip(plain, 2);
  auto source = detail::decodeGzip(InputFile("x.gz", std::as_bytes(std::span(packed.data(), packed.size()))));
  ASSERT_EQ(source->size(), plain.size());
  std::string buffer;
  for (int i = 0; i < 40; ++i) {
    const std::uint64_t offset = rng() % (plain.size() + 100);
    const std::size_t bytes = rng() % 100000;
    buffer.resize(bytes);
    const std::size_t got = source->readAt(offset, buffer.data(), bytes);
    const std::size_t expected = offset >= plain.size() ? 0 : std::min<std::size_t>(bytes, plain.size() - offset);
    ASSERT_EQ(got, expected) << "offset " << offset;
    ASSERT_EQ(buffer.substr(0, got), plain.substr(std::min<std::size_t>(offset, plain.size()), got));
  }
}

TEST(GzipContainer, NestedTwiceAtMost) {
  TempDir dir("gzip-nested");
  const std::string bgeo = testing::makeClassicBgeo(
      20, {}, [](std::size_t p, int c) { return float(p + std::size_t(c)); },
      [](std::size_t, std::size_t, int) { return 0.0; });
  testing::writeBytes(dir / "two.bgeo.gz", testing::gzip(testing::gzip(bgeo)));
  EXPECT_EQ(testing::readFile(dir / "two.bgeo.gz").size(), 20u);
  testing::writeBytes(dir / "three.bgeo.gz", testing::gzip(testing::gzip(testing::gzip(bgeo))));
  expectFileError([&] { testing::readFile(dir / "three.bgeo.gz"); }, {"three.bgeo.gz", "nested compressed containers"});
}

TEST(GzipContainer, DamageIsRefusedWithTheOffset) {
  TempDir dir("gzip-damage");
  const std::string plain = plyBytes(dir, PlyEncoding::BinaryLittleEndian, 40);
  const std::string packed = testing::gzip(plain);
  std::string crc = packed;
  crc[crc.size() - 6] ^= 1;  // the CRC-32 in the member's trailer
  testing::writeBytes(dir / "crc.ply.gz", crc);
  expectFileError([&] { testing::readFile(dir / "crc.ply.gz"); },
                  {"crc.ply.gz", "damaged gzip data near compressed byte", "incorrect data check"});
  std::string data = packed;
  data[20] ^= 0xff;
  testing::writeBytes(dir / "data.ply.gz", data);
  expectFileError([&] { testing::readFile(dir / "data.ply.gz"); }, {"data.ply.gz", "gzip"});
  testing::writeBytes(dir / "cut.ply.gz", packed.substr(0, packed.size() - 3));
  expectFileError([&] { testing::readFile(dir / "cut.ply.gz"); },
                  {"cut.ply.gz", "truncated gzip data: the file ends at byte " + std::to_string(packed.size() - 3)});
  testing::writeBytes(dir / "tail.ply.gz", packed + "garbage");
  expectFileError([&] { testing::readFile(dir / "tail.ply.gz"); },
                  {"tail.ply.gz", "7 bytes of trailing garbage", "ends at byte " + std::to_string(packed.size())});
  testing::expectEveryTruncationRefused("every.ply.gz", packed);
  (void)testing::expectCorruptionsHandled("every.ply.gz", packed);
}

}  // namespace
}  // namespace flipscope
