// Brick store format: codec round trips, header and frame file validation at every truncated
// length and every single-byte corruption.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include <zstd.h>

#include "core/AtomicFile.h"
#include "core/Bytes.h"
#include "core/Error.h"
#include "core/Hash.h"
#include "preprocess/store/BrickStore.h"
#include "preprocess/Convert.h"
#include "TestSupport.h"
#include "VectorSource.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;

DecodedBrick randomBrick(std::mt19937& rng, std::uint32_t cellsPerBrick, bool attribute) {
  DecodedBrick b;
  std::uint32_t cell = rng() % 100;
  while (cell < cellsPerBrick && b.cells.size() < 3000) {
    b.cells.push_back(cell);
    b.counts.push_back(1 + rng() % 12);
    cell += 1 + (rng() % 3 == 0 ? rng() % 2000 : rng() % 3);
  }
  if (attribute) {
    for (auto c : b.counts) {
      std::vector<std::uint16_t> a(c);
      for (auto& v : a) v = std::uint16_t(rng());
      std::sort(a.begin(), a.end());
      b.attributes.insert(b.attributes.end(), a.begin(), a.end());
    }
  }
  return b;
}

TEST(BrickCodec, RoundTripsRandomBricks) {
  std::mt19937 rng(11);
  for (const AttributeCoding coding : {AttributeCoding::Values, AttributeCoding::CellDeltas})
    for (int i = 0; i < 50; ++i) {
      const bool attribute = i % 2;
      DecodedBrick brick = randomBrick(rng, 64 * 64 * 64, attribute);
      // Values need not ascend in a cell for the codings: every tenth brick's are shuffled.
      if (i % 10 == 1) std::shuffle(brick.attributes.begin(), brick.attributes.end(), rng);
      auto payload = encodeBrick(brick, 1, coding);
      BrickRecord r;
      r.cells = std::uint32_t(brick.cells.size());
      r.particles = std::uint32_t(brick.particleCount());
      DecodedBrick back = decodeBrick(payload, "x.fsf", 3, r, 64 * 64 * 64, attribute, false, coding);
      EXPECT_EQ(back.cells, brick.cells);
      EXPECT_EQ(back.counts, brick.counts);
      EXPECT_EQ(back.attributes, brick.attributes);
    }
}

/// The decompressed payload of `brick`.
std::vector<std::byte> rawPayload(const DecodedBrick& brick, AttributeCoding coding) {
  const std::vector<std::byte> payload = encodeBrick(brick, 1, coding);
  std::vector<std::byte> raw(ZSTD_getFrameContentSize(payload.data(), payload.size()));
  EXPECT_EQ(ZSTD_decompress(raw.data(), raw.size(), payload.data(), payload.size()), raw.size());
  return raw;
}

TEST(BrickCodec, AttributeValuesAreLaidOutAsEachCodingSays) {
  // Cells 3 and 4 of 3 and 2 values: the streams before them are 5 bytes (one varint each).
  DecodedBrick brick;
  brick.cells = {3, 4};
  brick.counts = {3, 2};
  brick.attributes = {1000, 1002, 1300, 990, 65535};
  const auto bytes = [](std::initializer_list<int> values) {
    std::vector<std::byte> out;
    for (int v : values) out.push_back(std::byte(v));
    return out;
  };
  const std::vector<std::byte> streams = bytes({2, 3, 0, 2, 1});
  // Versions 3 to 6: u16 little endian.
  std::vector<std::byte> expected = streams;
  for (const std::uint16_t v : brick.attributes)
    for (const std::byte b : bytes({v & 0xff, v >> 8})) expected.push_back(b);
  EXPECT_EQ(rawPayload(brick, AttributeCoding::Values), expected);
  // Version 7: codes 2000 (zigzag of +1000), 2, 298, 19 (zigzag of 990 - 1000 = -10),
  // 64545 (65535 - 990); their high bytes, then their low bytes.
  const std::vector<std::uint16_t> codes = {2000, 2, 298, 19, 64545};
  expected = streams;
  for (const std::uint16_t c : codes) expected.push_back(std::byte(c >> 8));
  for (const std::uint16_t c : codes) expected.push_back(std::byte(c & 0xff));
  EXPECT_EQ(rawPayload(brick, AttributeCoding::CellDeltas), expected);
  EXPECT_EQ(attributeCodingOf(6), AttributeCoding::Values);
  EXPECT_EQ(attributeCodingOf(kStoreVersion), AttributeCoding::CellDeltas);
}

TEST(BrickCodec, CodedValuesOfASmoothFieldTakeLessThanHalfTheBytes) {
  // A speed that varies smoothly over the brick, 8 particles a cell with a little noise: the
  // values differ little from cell to cell and within a cell, but their low bytes vary.
  std::mt19937 rng(3);
  DecodedBrick brick;
  for (std::uint32_t c = 0; c < 64 * 64 * 64; c += 2) {
    brick.cells.push_back(c);
    brick.counts.push_back(8);
    const double x = c % 64, y = (c / 64) % 64, z = c / 4096;
    const double speed = 20000 + 9000 * std::sin(x / 9) + 7000 * std::cos(y / 11) + 300 * z;
    std::vector<std::uint16_t> values(8);
    for (auto& v : values) v = std::uint16_t(speed + double(rng() % 200));
    std::sort(values.begin(), values.end());
    brick.attributes.insert(brick.attributes.end(), values.begin(), values.end());
  }
  const std::size_t plain = encodeBrick(brick, 1, AttributeCoding::Values).size();
  const std::size_t coded = encodeBrick(brick, 1, AttributeCoding::CellDeltas).size();
  EXPECT_LT(2 * coded, plain) << coded << " bytes coded, " << plain << " as they are";
}

TEST(BrickCodec, EncodingIntoAKeptBufferGivesTheSamePayload) {
  // Binning recycles payload buffers from brick to brick: what a larger or smaller brick left in
  // one must not show in the next payload.
  std::mt19937 rng(12);
  UninitializedVector<std::byte> kept;
  bool shrank = false;  // a payload shorter than the one before it in the buffer
  for (int i = 0; i < 20; ++i) {
    const std::size_t before = kept.size();
    const DecodedBrick brick = randomBrick(rng, 64 * 64 * 64, i % 3 != 0);
    encodeBrickInto(brick, 1, kept, kAttributeCoding);
    const std::vector<std::byte> fresh = encodeBrick(brick, 1, kAttributeCoding);
    ASSERT_EQ(std::vector<std::byte>(kept.begin(), kept.end()), fresh) << "brick " << i;
    shrank = shrank || (i > 0 && fresh.size() < before);
  }
  EXPECT_TRUE(shrank);
}

TEST(BrickCodec, DecodingWithoutAttributesLeavesThemOutAndKeepsTheRest) {
  // Dense bricks too, whose streams before the attributes span several zstd blocks (128 KiB):
  // decompression stops inside the frame.
  std::mt19937 rng(17);
  for (const std::uint32_t cells : {200u, 100000u})
    for (const bool kinds : {false, true})
      for (const bool attribute : {false, true}) {
        DecodedBrick brick;
        for (std::uint32_t c = 0; c < cells; ++c) {
          brick.cells.push_back(c * (64 * 64 * 64 / cells) + std::uint32_t(rng() % 2));
          brick.counts.push_back(1 + rng() % 12);
          if (kinds) brick.kinds.push_back(ParticleKind(rng() % kParticleKindCount));
          if (attribute)
            for (std::uint32_t i = 0; i < brick.counts.back(); ++i) brick.attributes.push_back(std::uint16_t(rng()));
        }
        const std::vector<std::byte> payload = encodeBrick(brick, 1, kAttributeCoding);
        BrickRecord r;
        r.cells = std::uint32_t(brick.cells.size());
        r.particles = std::uint32_t(brick.particleCount());
        const DecodedBrick back =
            decodeBrick(payload, "x.fsf", 3, r, 64 * 64 * 64, attribute, kinds, kAttributeCoding, false);
        EXPECT_EQ(back.cells, brick.cells) << cells << " cells";
        EXPECT_EQ(back.counts, brick.counts);
        EXPECT_EQ(back.kinds, brick.kinds);
        EXPECT_TRUE(back.attributes.empty());
        // The streams before the attributes are checked as a whole decode checks them: a count
        // the table does not hold, and a payload cut inside them, are errors.
        BrickRecord more = r;
        ++more.particles;
        EXPECT_THROW(decodeBrick(payload, "x.fsf", 3, more, 64 * 64 * 64, attribute, kinds, kAttributeCoding, false),
                     FileError);
        DecodedBrick streams = brick;  // the payload's bytes before the attributes: about these
        streams.attributes.clear();
        const std::span<const std::byte> cut(payload.data(), encodeBrick(streams, 1, kAttributeCoding).size() / 2);
        EXPECT_THROW(decodeBrick(cut, "x.fsf", 3, r, 64 * 64 * 64, attribute, kinds, kAttributeCoding, false),
                     FileError);
      }
}

TEST(BrickCodec, APayloadTooShortForItsAttributesIsRefusedWithoutThem) {
  // A payload of a store without an attribute read as one with: it declares fewer bytes than
  // its particles' values would take.
  DecodedBrick brick;
  brick.cells = {1, 5, 9};
  brick.counts = {400, 400, 400};
  BrickRecord r;
  r.cells = 3;
  r.particles = 1200;
  try {
    decodeBrick(encodeBrick(brick, 1, kAttributeCoding), "x.fsf", 4, r, 64 * 64 * 64, true, false, kAttributeCoding,
                false);
    ADD_FAILURE() << "decoded";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("fewer than its 1200 attribute values take"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("brick 4"), std::string::npos) << e.what();
  }
}

TEST(BrickCodec, RejectsWrongCountsAndGarbage) {
  std::mt19937 rng(5);
  DecodedBrick brick = randomBrick(rng, 32 * 32 * 32, false);
  auto payload = encodeBrick(brick, 1, kAttributeCoding);
  BrickRecord r;
  r.cells = std::uint32_t(brick.cells.size());
  r.particles = std::uint32_t(brick.particleCount()) + 1;
  try {
    decodeBrick(payload, "f.fsf", 9, r, 32 * 32 * 32, false, false, kAttributeCoding);
    FAIL() << "accepted a wrong particle count";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("f.fsf: brick 9"), std::string::npos) << e.what();
  }
  std::vector<std::byte> garbage(64, std::byte{0x5a});
  EXPECT_THROW(decodeBrick(garbage, "f.fsf", 0, r, 32 * 32 * 32, false, false, kAttributeCoding), FileError);
}

TEST(StoreHeader, RoundTripsAndRejectsEveryCorruption) {
  StoreHeader h;
  h.brickSize = 32;
  h.cellSize = 0.125;
  h.origin = {-1, 2, 3.5};
  h.brickGrid = {4, 5, 6};
  h.attribute = AttributeKind::Speed;
  h.attributeName = "speed";
  h.particleSpacing = 0.0625;
  auto bytes = serializeStoreHeader(h);
  StoreHeader back = parseStoreHeader(bytes, "store.fsh");
  EXPECT_EQ(back.version, kStoreVersion);
  EXPECT_EQ(back.particleSpacing, h.particleSpacing);
  EXPECT_EQ(back.brickSize, h.brickSize);
  EXPECT_EQ(back.cellSize, h.cellSize);
  EXPECT_EQ(back.origin, h.origin);
  EXPECT_EQ(back.brickGrid, h.brickGrid);
  EXPECT_EQ(back.attribute, h.attribute);
  for (std::size_t n = 0; n < bytes.size(); ++n)
    EXPECT_THROW(parseStoreHeader(std::span(bytes).first(n), "store.fsh"), FileError) << "length " << n;
  auto longer = bytes;
  longer.push_back(std::byte{0});
  EXPECT_THROW(parseStoreHeader(longer, "store.fsh"), FileError);
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    auto bad = bytes;
    bad[i] ^= std::byte{0x41};
    EXPECT_THROW(parseStoreHeader(bad, "store.fsh"), FileError) << "byte " << i;
  }
}

TEST(StoreHeader, NamesAnUnknownVersion) {
  StoreHeader h;
  h.cellSize = 1;
  h.brickGrid = {1, 1, 1};
  h.version = kStoreVersion + 1;
  auto bytes = serializeStoreHeader(h);
  try {
    parseStoreHeader(bytes, "s/store.fsh");
    FAIL();
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("unsupported store version " + std::to_string(kStoreVersion + 1)),
              std::string::npos)
        << e.what();
  }
}

TEST(StoreHeader, UnknownSpacingIsZeroAndANegativeOneIsRefused) {
  StoreHeader h;
  h.cellSize = 1;
  h.brickGrid = {1, 1, 1};
  EXPECT_EQ(parseStoreHeader(serializeStoreHeader(h), "store.fsh").particleSpacing, 0.0);
  h.particleSpacing = -0.5;
  EXPECT_THROW(parseStoreHeader(serializeStoreHeader(h), "store.fsh"), FileError);
  h.particleSpacing = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(parseStoreHeader(serializeStoreHeader(h), "store.fsh"), FileError);
}

TEST(BrickStore, VersionOneStoreIsRefusedAskingToConvertAgain) {
  // store.fsh as flipscope wrote it before the particle spacing (version 1, 72 bytes).
  ByteWriter w;
  w.append("FSSTORE1", 8);
  w.put(std::uint32_t(1));   // version
  w.put(std::uint32_t(64));  // brick size
  w.put(0.05);               // cell size
  for (double o : {0.0, 0.0, 0.0}) w.put(o);
  for (std::uint32_t g : {2u, 2u, 2u}) w.put(g);
  w.put(std::uint32_t(0));  // attribute
  w.put(checksum64(w.view()));
  ASSERT_EQ(w.size(), 72u);
  testing::TempDir temp("v1");
  const fs::path dir = temp / "store";
  fs::create_directories(dir);
  {
    std::ofstream out(dir / kStoreHeaderName, std::ios::binary);
    out.write(reinterpret_cast<const char*>(w.view().data()), std::streamsize(w.size()));
  }
  for (int attempt = 0; attempt < 2; ++attempt) {
    try {
      if (attempt == 0) {
        BrickStore::open(dir);
      } else {  // appending to it is refused the same way
        ConvertOptions options;
        options.cellSize = 0.05;
        BrickStore::createOrAppend(dir, makeStoreHeader(Box{{0, 0, 0}, {1, 1, 1}}, options));
      }
      FAIL() << "opened a version 1 store";
    } catch (const FileError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("store.fsh"), std::string::npos) << message;
      EXPECT_NE(message.find("unsupported store version 1"), std::string::npos) << message;
      EXPECT_NE(message.find("convert the particle files again"), std::string::npos) << message;
    }
  }
}

/// Plain write for damaged copies (no fsync: thousands of them per test).
void writeBytes(const fs::path& file, std::span<const std::byte> bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

/// Reads a frame completely: index and every brick.
void readWholeFrame(const fs::path& file, const StoreHeader& header, const BrickStore& store) {
  FrameIndex index = readFrameIndex(file, header);
  for (std::uint32_t i = 0; i < index.bricks.size(); ++i) store.readBrick(index, i);
}

class SmallStore : public ::testing::Test {
 protected:
  void SetUp() override {
    ConvertOptions options;
    options.cellSize = 0.25;
    options.brickSize = 32;
    options.progress = Progress::Mode::Silent;
    auto positions = testing::randomParticles(600, 21, 20.0f);
    std::vector<glm::vec3> velocities(positions.size());
    for (std::size_t i = 0; i < velocities.size(); ++i) velocities[i] = {float(i % 7), 1, 0};
    Box bounds{{0, 0, 0}, {20, 20, 20}};
    BrickStore store = BrickStore::createOrAppend(dir, makeStoreHeader(bounds, options, AttributeKind::Speed));
    testing::VectorSource source(positions, velocities);
    convertFrame(source, store, 4, options);
  }
  testing::TempDir temp{"small-store"};
  fs::path dir = temp.path();
};

TEST_F(SmallStore, EveryTruncatedLengthOfTheFrameFileIsRefused) {
  BrickStore store = BrickStore::open(dir);
  const fs::path file = store.framePath(4);
  const auto bytes = readFile(file);
  ASSERT_GT(bytes.size(), 200u);
  readWholeFrame(file, store.header(), store);  // intact
  const fs::path cut = dir / "frame_000005.fsf";
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    writeBytes(cut, std::span(bytes).first(n));
    EXPECT_THROW(readWholeFrame(cut, store.header(), store), FileError) << "length " << n;
  }
}

TEST_F(SmallStore, EverySingleByteCorruptionOfTheFrameFileIsRefused) {
  BrickStore store = BrickStore::open(dir);
  const auto bytes = readFile(store.framePath(4));
  const fs::path bad = dir / "frame_000006.fsf";
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    auto copy = bytes;
    copy[i] ^= std::byte{0x10};
    writeBytes(bad, copy);
    EXPECT_THROW(readWholeFrame(bad, store.header(), store), FileError) << "byte " << i;
  }
}

TEST_F(SmallStore, DamagedBrickIsNamedInTheError) {
  BrickStore store = BrickStore::open(dir);
  auto index = store.frame(4);
  ASSERT_GT(index->bricks.size(), 2u);
  auto bytes = readFile(store.framePath(4));
  bytes[index->bricks[2].offset + 1] ^= std::byte{1};
  writeFileAtomically(store.framePath(4), bytes);
  BrickStore reopened = BrickStore::open(dir);
  auto frame = reopened.frame(4);
  EXPECT_NO_THROW(reopened.readBrick(*frame, 1));
  try {
    reopened.readBrick(*frame, 2);
    FAIL();
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("frame_000004.fsf: brick 2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("checksum"), std::string::npos) << e.what();
  }
}

TEST_F(SmallStore, AppendKeepsTheHeaderAndRefusesAnotherDomain) {
  BrickStore store = BrickStore::open(dir);
  StoreHeader other = store.header();
  other.cellSize *= 2;
  EXPECT_THROW(BrickStore::createOrAppend(dir, other), FileError);
  BrickStore again = BrickStore::createOrAppend(dir, store.header());
  EXPECT_EQ(again.frames(), std::vector<int>{4});
}

TEST(BrickStore, MissingOrForeignDirectoryIsAClearError) {
  testing::TempDir temp("foreign");
  const fs::path dir = temp.path();
  try {
    BrickStore::open(dir);
    FAIL();
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("store.fsh missing"), std::string::npos) << e.what();
  }
  EXPECT_THROW(BrickStore::open(dir / "missing"), FileError);
}

TEST(BrickStore, AFramelessHeaderIsRemovedOnlyWhileItIsStillFramelessAndOurs) {
  testing::TempDir temp("frameless");
  StoreHeader h;
  h.cellSize = 0.5;
  h.brickGrid = {1, 1, 1};
  bool wrote = false;
  BrickStore store = BrickStore::createOrAppend(temp / "s", h, BrickStore::FramelessStore::Join, &wrote);
  EXPECT_TRUE(wrote);
  const StoreId id = store.header().id;
  // A second writer joins it: nothing written, the same store.
  BrickStore joined = BrickStore::createOrAppend(temp / "s", h, BrickStore::FramelessStore::Join, &wrote);
  EXPECT_FALSE(wrote);
  EXPECT_EQ(joined.header().id, id);
  // Another store's id: left alone. The joined writer lists a frame: left alone.
  EXPECT_FALSE(BrickStore::removeIfFrameless(temp / "s", StoreId{1}));
  joined.addFrame(3);
  EXPECT_FALSE(BrickStore::removeIfFrameless(temp / "s", id));
  EXPECT_EQ(BrickStore::open(temp / "s").frames(), std::vector<int>{3});
  // Still frameless and ours: removed.
  BrickStore::createOrAppend(temp / "t", h, BrickStore::FramelessStore::Join, &wrote);
  EXPECT_TRUE(BrickStore::removeIfFrameless(temp / "t", BrickStore::open(temp / "t").header().id));
  EXPECT_FALSE(BrickStore::exists(temp / "t"));
}

TEST(BrickStore, AddFrameMergesTheFramesOtherWritersListed) {
  testing::TempDir temp("merge");
  StoreHeader h;
  h.cellSize = 0.5;
  h.brickGrid = {1, 1, 1};
  BrickStore a = BrickStore::createOrAppend(temp / "s", h);
  BrickStore b = BrickStore::open(temp / "s");  // opened before a lists anything
  a.addFrame(1);
  b.addFrame(2);
  a.addFrame(3);
  EXPECT_EQ(BrickStore::open(temp / "s").frames(), (std::vector<int>{1, 2, 3}));
  // A store started anew under a writer: its next frame is refused, naming store.fsh.
  fs::remove(temp / "s" / kStoreHeaderName);
  BrickStore::createOrAppend(temp / "s", h);
  try {
    b.addFrame(4);
    FAIL() << "a frame was listed in another store";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("is now the header of another store"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace flipscope
