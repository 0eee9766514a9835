// Binary values of any ValueType, of either byte order, converted to float in one tight loop
// per type: what the readers of formats that store whole arrays (VTK) decode with.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "preprocess/particles/ParticleSource.h"

namespace flipscope::detail {

/// Bytes of one value of `type`.
constexpr std::size_t valueTypeBytes(ValueType type) {
  switch (type) {
    case ValueType::Int8:
    case ValueType::UInt8:
      return 1;
    case ValueType::Int16:
    case ValueType::UInt16:
    case ValueType::Float16:
      return 2;
    case ValueType::Int32:
    case ValueType::UInt32:
    case ValueType::Float32:
      return 4;
    case ValueType::Int64:
    case ValueType::UInt64:
    case ValueType::Float64:
      return 8;
  }
  return 0;
}

namespace value_decode {

template <std::size_t Bytes>
using Bits = std::conditional_t<
    Bytes == 1, std::uint8_t,
    std::conditional_t<Bytes == 2, std::uint16_t, std::conditional_t<Bytes == 4, std::uint32_t, std::uint64_t>>>;

template <class B>
inline B swapped(B bits) {
  if constexpr (sizeof(B) == 2) return __builtin_bswap16(bits);
  if constexpr (sizeof(B) == 4) return __builtin_bswap32(bits);
  if constexpr (sizeof(B) == 8) return __builtin_bswap64(bits);
  return bits;
}

inline float halfToFloat(std::uint16_t h) {
  const std::uint32_t sign = std::uint32_t(h & 0x8000) << 16;
  const std::uint32_t exponent = (h >> 10) & 0x1f, mantissa = h & 0x3ff;
  if (exponent == 0) {  // zero or subnormal: mantissa * 2^-24
    float value = float(mantissa) * 0x1p-24f;
    return sign ? -value : value;
  }
  std::uint32_t bits =
      exponent == 31 ? sign | 0x7f800000u | (mantissa << 13) : sign | ((exponent + 112) << 23) | (mantissa << 13);
  return std::bit_cast<float>(bits);
}

template <class T, bool Swap>
void decode(const std::byte* src, std::size_t count, float* dst) {
  using B = Bits<sizeof(T)>;
  for (std::size_t i = 0; i < count; ++i) {
    B bits;
    std::memcpy(&bits, src + i * sizeof(T), sizeof(T));
    if constexpr (Swap) bits = swapped(bits);
    dst[i] = static_cast<float>(std::bit_cast<T>(bits));
  }
}

template <bool Swap>
void decodeHalf(const std::byte* src, std::size_t count, float* dst) {
  for (std::size_t i = 0; i < count; ++i) {
    std::uint16_t bits;
    std::memcpy(&bits, src + i * 2, 2);
    if constexpr (Swap) bits = swapped(bits);
    dst[i] = halfToFloat(bits);
  }
}

template <bool Swap>
void decodeAll(ValueType type, const std::byte* src, std::size_t count, float* dst) {
  switch (type) {
    case ValueType::Int8:
      return decode<std::int8_t, Swap>(src, count, dst);
    case ValueType::UInt8:
      return decode<std::uint8_t, Swap>(src, count, dst);
    case ValueType::Int16:
      return decode<std::int16_t, Swap>(src, count, dst);
    case ValueType::UInt16:
      return decode<std::uint16_t, Swap>(src, count, dst);
    case ValueType::Int32:
      return decode<std::int32_t, Swap>(src, count, dst);
    case ValueType::UInt32:
      return decode<std::uint32_t, Swap>(src, count, dst);
    case ValueType::Int64:
      return decode<std::int64_t, Swap>(src, count, dst);
    case ValueType::UInt64:
      return decode<std::uint64_t, Swap>(src, count, dst);
    case ValueType::Float16:
      return decodeHalf<Swap>(src, count, dst);
    case ValueType::Float32:
      return decode<float, Swap>(src, count, dst);
    case ValueType::Float64:
      return decode<double, Swap>(src, count, dst);
  }
}

}  // namespace value_decode

/// Converts `count` values of `type` at `src` (big-endian when `bigEndian`) to float at `dst`.
inline void decodeValues(ValueType type, bool bigEndian, const std::byte* src, std::size_t count, float* dst) {
  if (bigEndian == (std::endian::native == std::endian::big))
    value_decode::decodeAll<false>(type, src, count, dst);
  else
    value_decode::decodeAll<true>(type, src, count, dst);
}

/// Float32 values read as stored (big-endian when `bigEndian`) made native, in place.
inline void swapFloatsToNative(float* values, std::size_t count, bool bigEndian) {
  if (bigEndian == (std::endian::native == std::endian::big)) return;
  std::size_t i = 0;
#if defined(__SSE2__)
  for (; i + 4 <= count; i += 4) {  // SSE2 has no byte shuffle: swap the bytes of each half, then the halves
    __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(values + i));
    v = _mm_or_si128(_mm_slli_epi16(v, 8), _mm_srli_epi16(v, 8));
    v = _mm_shufflehi_epi16(_mm_shufflelo_epi16(v, 0xb1), 0xb1);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(values + i), v);
  }
#endif
  for (; i < count; ++i) {
    std::uint32_t bits;
    std::memcpy(&bits, values + i, 4);
    bits = __builtin_bswap32(bits);
    std::memcpy(values + i, &bits, 4);
  }
}

/// An unsigned integer of `bytes` (4 or 8) bytes at `src`, in the given byte order.
inline std::uint64_t decodeUnsigned(const std::byte* src, std::size_t bytes, bool bigEndian) {
  const bool swap = bigEndian != (std::endian::native == std::endian::big);
  if (bytes == 4) {
    std::uint32_t v;
    std::memcpy(&v, src, 4);
    return swap ? __builtin_bswap32(v) : v;
  }
  std::uint64_t v;
  std::memcpy(&v, src, 8);
  return swap ? __builtin_bswap64(v) : v;
}

}  // namespace flipscope::detail
