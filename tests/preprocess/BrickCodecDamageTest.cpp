// decodeBrick on payloads the fuzzer made (tests/fuzz/regressions/brick_payload): varints that
// wrap a cell index or a count around 2^64 are refused, not decoded into a brick whose cells are
// out of order or whose cells hold no particle; a payload that declares far more bytes than its
// zstd frame holds is refused without allocating what it declares.
#include <gtest/gtest.h>

#include <zstd.h>

#include <cstring>

#include "core/Bytes.h"
#include "core/Error.h"
#include "preprocess/store/BrickStore.h"

namespace flipscope {
namespace {

std::vector<std::byte> compress(const ByteWriter& raw) {
  std::vector<std::byte> out(ZSTD_compressBound(raw.size()));
  out.resize(ZSTD_compress(out.data(), out.size(), raw.view().data(), raw.size(), 1));
  return out;
}

BrickRecord record(std::uint32_t cells, std::uint32_t particles) {
  BrickRecord r;
  r.cells = cells;
  r.particles = particles;
  return r;
}

void expectRefused(const std::vector<std::byte>& payload, const BrickRecord& r, const std::string& part) {
  try {
    decodeBrick(payload, "f.fsf", 3, r, 32 * 32 * 32, false, false, kAttributeCoding);
    ADD_FAILURE() << "accepted; expected a FileError mentioning " << part;
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("brick 3"), std::string::npos) << e.what();
  }
}

TEST(BrickCodecDamage, CellGapWrappingAroundIsRefused) {
  ByteWriter raw;
  raw.putVarint(2);                  // cells
  raw.putVarint(100);                // first cell
  raw.putVarint(~std::uint64_t(0));  // gap: 100 + 1 + gap wraps to 100
  raw.putVarint(0);
  raw.putVarint(0);
  expectRefused(compress(raw), record(2, 2), "cell gap");
}

TEST(BrickCodecDamage, CountWrappingAroundIsRefused) {
  ByteWriter raw;
  raw.putVarint(2);
  raw.putVarint(1);
  raw.putVarint(0);
  raw.putVarint(~std::uint64_t(0));  // count - 1: + 1 wraps to a cell of 0 particles
  raw.putVarint(1);
  expectRefused(compress(raw), record(2, 2), "cell count");
}

TEST(BrickCodecDamage, RecordWithMoreCellsThanTheBrickIsRefused) {
  ByteWriter raw;
  raw.putVarint(1);
  expectRefused(compress(raw), record(32 * 32 * 32 + 1, 40000), "cells");
}

TEST(BrickCodecDamage, DeclaredSizeBeyondTheFrameIsRefusedCheaply) {
  // A real frame of 128 KiB of attributes whose header then claims 1 GiB: decoded as a stream,
  // which stops at the frame's end, having allocated only what the frame holds.
  ByteWriter raw;
  raw.putVarint(1);
  raw.putVarint(0);
  raw.putVarint((1u << 16) - 1);
  std::vector<std::uint16_t> attributes(1 << 16, 7);
  raw.putArray(std::span<const std::uint16_t>(attributes));
  std::vector<std::byte> payload = compress(raw);
  ASSERT_EQ(ZSTD_getFrameContentSize(payload.data(), payload.size()), raw.size());
  // Frame header: magic, descriptor (its top bits 2: a 4-byte content size), window byte unless
  // single segment, then the size.
  const auto descriptor = std::uint8_t(payload[4]);
  ASSERT_EQ(descriptor & 0xc0, 0x80);
  const std::uint32_t huge = 1u << 30;
  std::memcpy(payload.data() + 5 + ((descriptor & 0x20) ? 0 : 1), &huge, 4);
  ASSERT_EQ(ZSTD_getFrameContentSize(payload.data(), payload.size()), huge);
  try {
    decodeBrick(payload, "f.fsf", 0, record(1, 1u << 29), 32 * 32 * 32, true, false, kAttributeCoding);
    ADD_FAILURE() << "accepted";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("f.fsf"), std::string::npos) << e.what();
  }
  // The same frame with its true size decodes (its values as versions 3 to 6 lay them out).
  const std::vector<std::byte> good = compress(raw);
  EXPECT_EQ(
      decodeBrick(good, "f.fsf", 0, record(1, 1u << 16), 32 * 32 * 32, true, false, AttributeCoding::Values).attributes,
      attributes);
}

}  // namespace
}  // namespace flipscope
