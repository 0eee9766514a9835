// A small Krakatoa PRT writer for the reader tests: any channels of any type and arity, PRT 1.0
// or 1.1 headers (with metadata chunks), channel offsets in any order, the zlib stream written
// in many flushed pieces. Values are given as doubles and stored in the channel's type (the
// caller picks values every type holds exactly).
#pragma once

#include <zlib.h>

#include <bit>
#include <cstdint>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace flipscope::testing {

/// PRT data types, as the file numbers them.
enum class PrtType : std::int32_t {
  Int16 = 0,
  Int32,
  Int64,
  Float16,
  Float32,
  Float64,
  UInt16,
  UInt32,
  UInt64,
  Int8,
  UInt8
};

inline std::size_t prtTypeBytes(PrtType type) {
  switch (type) {
    case PrtType::Int8:
    case PrtType::UInt8:
      return 1;
    case PrtType::Int16:
    case PrtType::UInt16:
    case PrtType::Float16:
      return 2;
    case PrtType::Int32:
    case PrtType::UInt32:
    case PrtType::Float32:
      return 4;
    default:
      return 8;
  }
}

/// float to IEEE binary16, rounding to nearest even (finite values in range; enough for tests).
inline std::uint16_t floatToHalf(float value) {
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(value);
  const std::uint32_t sign = (bits >> 16) & 0x8000u;
  const int exponent = int((bits >> 23) & 0xff) - 127 + 15;
  std::uint32_t mantissa = bits & 0x7fffffu;
  if ((bits & 0x7fffffffu) == 0) return std::uint16_t(sign);
  if (exponent >= 31) return std::uint16_t(sign | 0x7c00u);
  if (exponent <= 0) {  // subnormal half
    mantissa |= 0x800000u;
    const int shift = 14 - exponent;
    std::uint32_t half = mantissa >> shift;
    const std::uint32_t rest = mantissa & ((1u << shift) - 1), halfway = 1u << (shift - 1);
    if (rest > halfway || (rest == halfway && (half & 1))) ++half;
    return std::uint16_t(sign | half);
  }
  std::uint32_t half = (std::uint32_t(exponent) << 10) | (mantissa >> 13);
  const std::uint32_t rest = mantissa & 0x1fffu;
  if (rest > 0x1000u || (rest == 0x1000u && (half & 1))) ++half;
  return std::uint16_t(sign | half);
}

struct PrtChannelSpec {
  std::string name;
  PrtType type = PrtType::Float32;
  int arity = 1;
};

/// Stores `value` in `type` at `out` (little-endian).
inline void putPrtValue(PrtType type, double value, unsigned char* out) {
  auto put = [&](auto v) { std::memcpy(out, &v, sizeof v); };
  switch (type) {
    case PrtType::Int8:
      put(std::int8_t(value));
      break;
    case PrtType::UInt8:
      put(std::uint8_t(value));
      break;
    case PrtType::Int16:
      put(std::int16_t(value));
      break;
    case PrtType::UInt16:
      put(std::uint16_t(value));
      break;
    case PrtType::Int32:
      put(std::int32_t(value));
      break;
    case PrtType::UInt32:
      put(std::uint32_t(value));
      break;
    case PrtType::Int64:
      put(std::int64_t(value));
      break;
    case PrtType::UInt64:
      put(std::uint64_t(value));
      break;
    case PrtType::Float16:
      put(floatToHalf(float(value)));
      break;
    case PrtType::Float32:
      put(float(value));
      break;
    case PrtType::Float64:
      put(value);
      break;
  }
}

struct PrtWriteOptions {
  int version = 2;              ///< 1: PRT 1.0, 2: PRT 1.1 with metadata chunks
  bool reverseOffsets = false;  ///< lay the channels out in the record in reverse order
  bool unknownCount = false;    ///< write the particle count as -1
  std::size_t piece = 4096;     ///< bytes of records deflated between flushes
  int level = 6;
};

/// A PRT file of `count` particles; `value(particle, channel, component)` gives each value.
inline std::string makePrt(const std::vector<PrtChannelSpec>& channels, std::size_t count,
                           const std::function<double(std::size_t, std::size_t, int)>& value,
                           PrtWriteOptions options = {}) {
  std::string out;
  auto put = [&](const auto& v) { out.append(reinterpret_cast<const char*>(&v), sizeof v); };
  out.append("\xc0PRT\r\n\x1a\n", 8);
  const std::size_t headerLengthAt = out.size();
  put(std::int32_t(56));
  char signature[32] = "Extensible Particle Format";
  out.append(signature, 32);
  put(std::int32_t(options.version));
  put(std::int64_t(options.unknownCount ? -1 : std::int64_t(count)));
  if (options.version == 2) {
    auto chunk = [&](const char* tag, const std::string& body) {
      out.append(tag, 4);
      put(std::int32_t(body.size()));
      out += body;
    };
    std::string meta = std::string("\0LengthUnitInMeters\0", 20);
    const std::int32_t type = 5;
    meta.append(reinterpret_cast<const char*>(&type), 4);
    const double unit = 0.01;
    meta.append(reinterpret_cast<const char*>(&unit), 8);
    chunk("Meta", meta);
    chunk("Stop", "");
    const auto headerLength = std::int32_t(out.size());
    std::memcpy(out.data() + headerLengthAt, &headerLength, 4);
  }
  put(std::int32_t(4));
  put(std::int32_t(channels.size()));
  put(std::int32_t(44));
  std::vector<std::size_t> offsets(channels.size());
  std::size_t stride = 0;
  for (std::size_t k = 0; k < channels.size(); ++k) {
    const std::size_t i = options.reverseOffsets ? channels.size() - 1 - k : k;
    offsets[i] = stride;
    stride += prtTypeBytes(channels[i].type) * std::size_t(channels[i].arity);
  }
  for (std::size_t i = 0; i < channels.size(); ++i) {
    char name[32] = {};
    std::memcpy(name, channels[i].name.data(), std::min<std::size_t>(31, channels[i].name.size()));
    out.append(name, 32);
    put(std::int32_t(channels[i].type));
    put(std::int32_t(channels[i].arity));
    put(std::int32_t(offsets[i]));
  }
  std::vector<unsigned char> records(count * stride);
  for (std::size_t p = 0; p < count; ++p)
    for (std::size_t i = 0; i < channels.size(); ++i)
      for (int c = 0; c < channels[i].arity; ++c)
        putPrtValue(channels[i].type, value(p, i, c),
                    records.data() + p * stride + offsets[i] + std::size_t(c) * prtTypeBytes(channels[i].type));
  z_stream z{};
  if (deflateInit(&z, options.level) != Z_OK) throw std::runtime_error("deflateInit");
  std::vector<unsigned char> buffer(64 * 1024);
  std::size_t at = 0;
  for (;;) {
    const std::size_t n = std::min(options.piece, records.size() - at);
    z.next_in = records.data() + at;
    z.avail_in = uInt(n);
    at += n;
    const int flush = at == records.size() ? Z_FINISH : Z_SYNC_FLUSH;
    int status;
    do {
      z.next_out = buffer.data();
      z.avail_out = uInt(buffer.size());
      status = deflate(&z, flush);
      out.append(reinterpret_cast<const char*>(buffer.data()), buffer.size() - z.avail_out);
    } while (z.avail_out == 0 || (flush == Z_FINISH && status != Z_STREAM_END));
    if (flush == Z_FINISH) break;
  }
  deflateEnd(&z);
  return out;
}

}  // namespace flipscope::testing
