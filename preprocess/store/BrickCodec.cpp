// Brick payload codec. A payload is one zstd frame of:
//   varint occupied                      number of occupied cells
//   varint gap[occupied]                 cells[0], then cells[i] - cells[i-1] - 1
//   varint countMinus1[occupied]         particles per cell, minus one
//   u8     kind[occupied]                only if the store has particle kinds (ParticleKind)
//   u16    attribute[particles]          only if the store has an attribute, as AttributeCoding
//                                        says (below)
// Separate streams compress far better than interleaved ones: at 8 particles per cell most
// gaps and counts are tiny and repeat. Particles are quantized to their cell (Reichl et al.
// 2014 §3, §4.3), so cells and counts are all that is left of the positions. A byte per kind
// rather than 2 bits a cell: plain to check (a value >= 4 is refused) and about as small after
// zstd. On the 30 frames of the Mantaflow sample (320,612 cells, a quarter not liquid) the kinds
// add 1.23 bits a cell (49.3 KB to 204.2 KB at level 1); 2 bits packed four to a byte, 1.04.
//
// Attribute values (one a particle, by cell, ascending within a cell; Reichl et al. 2014 §3.2
// keep one a cell, we keep every particle's for the renderer's reduction) are most of a payload
// where a store has them. AttributeCoding::Values (versions 3 to 6) stores them as they are,
// u16 little endian. AttributeCoding::CellDeltas (version 7) stores a code a value, the high
// bytes of every code first and then the low bytes (byte planes: zstd's entropy coder sees the
// high bytes, mostly zero, apart from the noisy low ones): a cell's first value as the zigzag
// of its difference from the previous cell's first value (0 before the first cell), each
// further value as its difference from the one before it in the cell (ascending: small and
// not negative). All arithmetic is modulo 2^16, so any values round-trip, ascending or not.
// Measured on the 20 M particle synth PLY with its speed (`bench render --peer embree`'s),
// zstd level 1: 40.0 MB of values took 34.7 MB as they are, 16.6 MB coded at 8 particles a
// cell (--cell-size 0.00446289), 33.4 MB and 19.7 MB at one cell per particle spacing.
#include <zstd.h>

#include <algorithm>
#include <memory>

#include "core/Bytes.h"
#include "core/UninitializedVector.h"
#include "preprocess/store/BrickStore.h"

namespace flipscope {
namespace {

struct CompressorDeleter {
  void operator()(ZSTD_CCtx* context) const { ZSTD_freeCCtx(context); }
};
struct DecompressorDeleter {
  void operator()(ZSTD_DCtx* context) const { ZSTD_freeDCtx(context); }
};

/// One zstd context per thread, reused by every brick the thread codes and freed when the
/// thread ends (LeakSanitizer saw raw thread_local pointers outlive their threads).
ZSTD_CCtx* threadCompressor() {
  thread_local std::unique_ptr<ZSTD_CCtx, CompressorDeleter> context(ZSTD_createCCtx());
  return context.get();
}
ZSTD_DCtx* threadDecompressor() {
  thread_local std::unique_ptr<ZSTD_DCtx, DecompressorDeleter> context(ZSTD_createDCtx());
  return context.get();
}

/// A thread's scratch buffer kept from brick to brick: a fresh one per brick cost a first touch
/// of its pages each time. Let go when this brick made it larger than `keep` bytes.
template <class Buffer>
struct ReleaseLarge {
  Buffer& buffer;
  std::size_t keep;
  ~ReleaseLarge() {
    if (buffer.capacity() > keep) Buffer().swap(buffer);
  }
};

/// Scratch kept by an encoding thread, per buffer: the raw streams of a 64^3 brick at 8
/// particles a cell with an attribute (about 5 MB).
constexpr std::size_t kKeptEncodeBytes = 8 << 20;

}  // namespace

std::uint64_t DecodedBrick::particleCount() const {
  std::uint64_t n = 0;
  for (auto c : counts) n += c;
  return n;
}

namespace {

std::uint16_t zigzag(std::uint16_t difference) {
  return std::uint16_t((difference << 1) ^ (difference & 0x8000u ? 0xffffu : 0u));
}
std::uint16_t unzigzag(std::uint16_t code) { return std::uint16_t((code >> 1) ^ (code & 1u ? 0xffffu : 0u)); }

/// AttributeCoding::CellDeltas of `values` (grouped by `counts`) into `out`: 2 bytes a value.
void codeCellDeltas(std::span<const std::uint16_t> values, std::span<const std::uint32_t> counts, std::byte* out) {
  const std::size_t n = values.size();
  std::size_t i = 0;
  std::uint16_t previousFirst = 0;
  for (const std::uint32_t count : counts) {
    for (std::uint32_t k = 0; k < count; ++k, ++i) {
      const std::uint16_t code =
          k == 0 ? zigzag(std::uint16_t(values[i] - previousFirst)) : std::uint16_t(values[i] - values[i - 1]);
      out[i] = std::byte(code >> 8);
      out[n + i] = std::byte(code & 0xffu);
    }
    previousFirst = values[i - count];
  }
}

/// The inverse of codeCellDeltas: `values` (sized) from the 2 * values.size() bytes at `in`.
/// `counts` sums to values.size() (decodeBrick checked it).
void decodeCellDeltas(const std::byte* in, std::span<const std::uint32_t> counts, std::span<std::uint16_t> values) {
  const std::size_t n = values.size();
  std::size_t i = 0;
  std::uint16_t previousFirst = 0;
  for (const std::uint32_t count : counts) {
    for (std::uint32_t k = 0; k < count; ++k, ++i) {
      const auto code = std::uint16_t((std::uint32_t(in[i]) << 8) | std::uint32_t(in[n + i]));
      values[i] = k == 0 ? std::uint16_t(previousFirst + unzigzag(code)) : std::uint16_t(values[i - 1] + code);
    }
    previousFirst = values[i - count];
  }
}

}  // namespace

void encodeBrickInto(const DecodedBrick& brick, int zstdLevel, UninitializedVector<std::byte>& payload,
                     AttributeCoding coding) {
  FLIPSCOPE_CHECK(brick.cells.size() == brick.counts.size(), brick.cells.size() << " vs " << brick.counts.size());
  FLIPSCOPE_CHECK(brick.kinds.empty() || brick.kinds.size() == brick.cells.size(),
                  brick.kinds.size() << " kinds for " << brick.cells.size() << " cells");
  // The raw streams in the thread's buffer: a fresh one per brick was a tenth of a 20 M
  // particle convert (page faults).
  thread_local ByteWriter raw;
  const ReleaseLarge<std::vector<std::byte>> releaseRaw{raw.bytes(), kKeptEncodeBytes};
  raw.bytes().clear();
  raw.bytes().reserve(brick.cells.size() * 2 + brick.kinds.size() + brick.attributes.size() * 2 + 8);
  raw.putVarint(brick.cells.size());
  std::uint32_t previous = 0;
  for (std::size_t i = 0; i < brick.cells.size(); ++i) {
    FLIPSCOPE_CHECK(i == 0 || brick.cells[i] > previous, "cells not ascending");
    raw.putVarint(i == 0 ? brick.cells[i] : brick.cells[i] - previous - 1);
    previous = brick.cells[i];
  }
  for (auto c : brick.counts) {
    FLIPSCOPE_CHECK(c >= 1, "empty cell in brick");
    raw.putVarint(c - 1);
  }
  for (ParticleKind kind : brick.kinds) {
    FLIPSCOPE_CHECK(std::uint32_t(kind) < kParticleKindCount, int(kind));
    raw.put(std::uint8_t(kind));
  }
  if (coding == AttributeCoding::Values || brick.attributes.empty()) {
    raw.putArray(std::span<const std::uint16_t>(brick.attributes));
  } else {
    FLIPSCOPE_CHECK(brick.attributes.size() == brick.particleCount(),
                    brick.attributes.size() << " attribute values for " << brick.particleCount() << " particles");
    std::vector<std::byte>& bytes = raw.bytes();
    const std::size_t at = bytes.size();
    bytes.resize(at + 2 * brick.attributes.size());
    codeCellDeltas(brick.attributes, brick.counts, bytes.data() + at);
  }

  payload.resize(ZSTD_compressBound(raw.size()));  // uninitialized: no memset of the bound
  ZSTD_CCtx* context = threadCompressor();
  const std::size_t n =
      ZSTD_compressCCtx(context, payload.data(), payload.size(), raw.view().data(), raw.size(), zstdLevel);
  FLIPSCOPE_CHECK(!ZSTD_isError(n), ZSTD_getErrorName(n));
  payload.resize(n);
}

std::vector<std::byte> encodeBrick(const DecodedBrick& brick, int zstdLevel, AttributeCoding coding) {
  UninitializedVector<std::byte> payload;
  encodeBrickInto(brick, zstdLevel, payload, coding);
  return {payload.begin(), payload.end()};
}

namespace {

/// Payloads that claim more than this (and more than 64 times their size) are decompressed as a
/// stream into a buffer that grows with what the frame really holds, so that a payload that
/// declares more than it holds cannot make us allocate what it declares.
constexpr std::uint64_t kOneShotBytes = 4 << 20;

template <class Fail>
std::vector<std::byte> decompressStreamed(std::span<const std::byte> payload, std::uint64_t declared,
                                          const Fail& fail) {
  ZSTD_DCtx* context = threadDecompressor();
  ZSTD_DCtx_reset(context, ZSTD_reset_session_only);
  std::vector<std::byte> raw;
  std::size_t produced = 0;
  ZSTD_inBuffer input{payload.data(), payload.size(), 0};
  for (std::size_t hint = 1; hint != 0;) {
    if (produced == raw.size() && raw.size() < declared)
      raw.resize(
          std::size_t(std::min<std::uint64_t>(declared, std::max<std::uint64_t>(2 * raw.size(), kOneShotBytes))));
    std::byte spare;  // room for zstd to finish the frame, and to show content beyond the declared size
    const bool full = produced == raw.size();
    ZSTD_outBuffer out{full ? &spare : raw.data() + produced, full ? 1 : raw.size() - produced, 0};
    const std::size_t consumed = input.pos;
    hint = ZSTD_decompressStream(context, &out, &input);
    if (ZSTD_isError(hint)) throw fail(std::string("zstd: ") + ZSTD_getErrorName(hint));
    if (full && out.pos) throw fail("payload holds more than the " + std::to_string(declared) + " bytes it declares");
    if (!full) produced += out.pos;
    if (hint != 0 && out.pos == 0 && input.pos == consumed) throw fail("payload ends inside its zstd frame");
  }
  if (produced != declared) throw fail("payload decompressed to fewer bytes than declared");
  if (input.pos != input.size) throw fail("bytes after the payload's zstd frame");
  return raw;
}

/// The first raw.size() bytes of the payload's zstd frame into `raw`, the rest of it left
/// compressed (zstd stops when the output is full).
template <class Fail>
void decompressPrefix(std::span<const std::byte> payload, std::vector<std::byte>& raw, const Fail& fail) {
  ZSTD_DCtx* context = threadDecompressor();
  ZSTD_DCtx_reset(context, ZSTD_reset_session_only);
  ZSTD_inBuffer input{payload.data(), payload.size(), 0};
  ZSTD_outBuffer out{raw.data(), raw.size(), 0};
  while (out.pos < out.size) {
    const std::size_t consumed = input.pos, produced = out.pos;
    const std::size_t hint = ZSTD_decompressStream(context, &out, &input);
    if (ZSTD_isError(hint)) throw fail(std::string("zstd: ") + ZSTD_getErrorName(hint));
    if (hint == 0 && out.pos < out.size) throw fail("payload decompressed to fewer bytes than declared");
    if (out.pos == produced && input.pos == consumed) throw fail("payload ends inside its zstd frame");
  }
  ZSTD_DCtx_reset(context, ZSTD_reset_session_only);  // the frame left unfinished
}

}  // namespace

DecodedBrick decodeBrick(std::span<const std::byte> payload, const std::filesystem::path& file,
                         std::uint32_t brickIndex, const BrickRecord& expected, std::uint32_t cellsPerBrick,
                         bool hasAttribute, bool hasKinds, AttributeCoding coding, bool readAttributes) {
  const std::string where = "brick " + std::to_string(brickIndex);
  auto fail = [&](const std::string& reason) -> FileError { return FileError(file, where + ": " + reason); };

  if (expected.cells > cellsPerBrick || expected.particles < expected.cells)
    throw fail("record claims " + std::to_string(expected.cells) + " cells and " + std::to_string(expected.particles) +
               " particles in a brick of " + std::to_string(cellsPerBrick) + " cells");
  // Largest valid raw size: a 5-byte varint per gap and count, plus the kinds and attributes.
  const std::uint64_t bound = 10 + (hasKinds ? 11ull : 10ull) * expected.cells +
                              (hasAttribute ? 2ull * expected.particles : 0);
  const unsigned long long declared = ZSTD_getFrameContentSize(payload.data(), payload.size());
  if (declared == ZSTD_CONTENTSIZE_ERROR || declared == ZSTD_CONTENTSIZE_UNKNOWN)
    throw fail("payload is not a zstd frame of known size");
  if (declared > bound) throw fail("payload declares " + std::to_string(declared) + " bytes, more than possible");
  const std::uint64_t attributeBytes = hasAttribute ? 2 * std::uint64_t(expected.particles) : 0;
  if (declared < attributeBytes)
    throw fail("payload declares " + std::to_string(declared) + " bytes, fewer than its " +
               std::to_string(expected.particles) + " attribute values take");
  const bool skipAttributes = hasAttribute && !readAttributes;
  ZSTD_DCtx* context = threadDecompressor();
  // The thread's buffer, kept from brick to brick: a fresh one per brick cost a first touch of
  // its pages each time (most of the page faults of a large first image).
  // One larger than a one-shot read is let go after this brick.
  thread_local std::vector<std::byte> raw;
  const ReleaseLarge<std::vector<std::byte>> release{raw, kOneShotBytes};
  if (skipAttributes) {
    // The streams before the attributes: they are last, two bytes a particle.
    raw.resize(std::size_t(declared - attributeBytes));
    decompressPrefix(payload, raw, fail);
  } else if (declared <= std::max<std::uint64_t>(kOneShotBytes, 64 * std::uint64_t(payload.size()))) {
    raw.resize(declared);
    const std::size_t n = ZSTD_decompressDCtx(context, raw.data(), raw.size(), payload.data(), payload.size());
    if (ZSTD_isError(n)) throw fail(std::string("zstd: ") + ZSTD_getErrorName(n));
    if (n != declared) throw fail("payload decompressed to fewer bytes than declared");
  } else {
    raw = decompressStreamed(payload, declared, fail);
  }

  ByteReader in(raw, file.string() + ", " + where + " (decompressed)");
  DecodedBrick brick;
  const std::uint64_t occupied = in.getVarint("occupied cells");
  if (occupied != expected.cells)
    throw fail("holds " + std::to_string(occupied) + " cells, table says " + std::to_string(expected.cells));
  brick.cells.resize(occupied);
  brick.counts.resize(occupied);
  std::uint64_t cell = ~std::uint64_t(0);  // the first gap counts from -1
  std::uint32_t* cells = brick.cells.data();
  in.forEachVarint(occupied, "cell gap", [&](std::uint64_t gap) {
    if (gap >= cellsPerBrick) throw fail("cell gap " + std::to_string(gap) + " is larger than the brick");
    cell += 1 + gap;  // no wrap-around past -1: both terms are below cellsPerBrick
    if (cell >= cellsPerBrick) throw fail("cell index " + std::to_string(cell) + " outside the brick");
    *cells++ = std::uint32_t(cell);
  });
  std::uint64_t particles = 0;
  std::uint32_t* counts = brick.counts.data();
  in.forEachVarint(occupied, "cell count", [&](std::uint64_t countMinus1) {
    if (countMinus1 >= expected.particles) throw fail("cell count larger than the brick's particle count");
    *counts++ = std::uint32_t(countMinus1 + 1);
    particles += countMinus1 + 1;
  });
  if (particles != expected.particles)
    throw fail("holds " + std::to_string(particles) + " particles, table says " + std::to_string(expected.particles));
  if (hasKinds) {
    brick.kinds.resize(occupied);
    for (std::uint64_t i = 0; i < occupied; ++i) {
      const auto kind = in.get<std::uint8_t>("cell kind");
      if (kind >= kParticleKindCount)
        throw fail("cell " + std::to_string(brick.cells[i]) + " has particle kind " + std::to_string(kind) +
                   ", not one of the " + std::to_string(kParticleKindCount));
      brick.kinds[i] = ParticleKind(kind);
    }
  }
  if (hasAttribute && !skipAttributes) {
    brick.attributes.resize(particles);
    if (coding == AttributeCoding::Values)
      in.getArray(std::span<std::uint16_t>(brick.attributes), "attributes");
    else
      decodeCellDeltas(in.getBytes(2 * particles, "attributes").data(), brick.counts, brick.attributes);
  }
  in.expectEnd("end of brick payload");
  return brick;
}

}  // namespace flipscope
