// Column decoding for the binary record formats (see the header).
#include "preprocess/particles/BinaryColumns.h"

#include <bit>
#include <cstring>
#include <type_traits>

#include "core/Error.h"

namespace flipscope::detail {
namespace {

template <class T>
using BitsOf = std::conditional_t<sizeof(T) == 1, std::uint8_t,
                                  std::conditional_t<sizeof(T) == 2, std::uint16_t,
                                                     std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>>;

template <class Bits>
Bits byteSwap(Bits bits) {
  if constexpr (sizeof(Bits) == 2) return __builtin_bswap16(bits);
  if constexpr (sizeof(Bits) == 4) return __builtin_bswap32(bits);
  if constexpr (sizeof(Bits) == 8) return __builtin_bswap64(bits);
  return bits;
}

struct Half {};  // tag: binary16 stored as uint16

template <class T, bool Swap>
inline float load(const std::byte* p) {
  if constexpr (std::is_same_v<T, Half>) {
    std::uint16_t bits;
    std::memcpy(&bits, p, 2);
    if constexpr (Swap) bits = byteSwap(bits);
    return halfToFloat(bits);
  } else {
    BitsOf<T> bits;
    std::memcpy(&bits, p, sizeof bits);
    if constexpr (Swap) bits = byteSwap(bits);
    return static_cast<float>(std::bit_cast<T>(bits));
  }
}

template <class T, bool Swap>
void decodeTyped(const std::byte* first, std::size_t stride, int arity, std::size_t count, float* out) {
  constexpr std::size_t bytes = std::is_same_v<T, Half> ? 2 : sizeof(T);
  if (arity == 3) {  // positions, velocities, colours: the common case, unrolled
    for (std::size_t i = 0; i < count; ++i, first += stride, out += 3) {
      out[0] = load<T, Swap>(first);
      out[1] = load<T, Swap>(first + bytes);
      out[2] = load<T, Swap>(first + 2 * bytes);
    }
    return;
  }
  for (std::size_t i = 0; i < count; ++i, first += stride)
    for (int c = 0; c < arity; ++c) *out++ = load<T, Swap>(first + std::size_t(c) * bytes);
}

template <bool Swap>
void decodeOrdered(ValueType type, const std::byte* first, std::size_t stride, int arity, std::size_t count,
                   float* out) {
  switch (type) {
    case ValueType::Int8:
      return decodeTyped<std::int8_t, Swap>(first, stride, arity, count, out);
    case ValueType::UInt8:
      return decodeTyped<std::uint8_t, Swap>(first, stride, arity, count, out);
    case ValueType::Int16:
      return decodeTyped<std::int16_t, Swap>(first, stride, arity, count, out);
    case ValueType::UInt16:
      return decodeTyped<std::uint16_t, Swap>(first, stride, arity, count, out);
    case ValueType::Int32:
      return decodeTyped<std::int32_t, Swap>(first, stride, arity, count, out);
    case ValueType::UInt32:
      return decodeTyped<std::uint32_t, Swap>(first, stride, arity, count, out);
    case ValueType::Int64:
      return decodeTyped<std::int64_t, Swap>(first, stride, arity, count, out);
    case ValueType::UInt64:
      return decodeTyped<std::uint64_t, Swap>(first, stride, arity, count, out);
    case ValueType::Float16:
      return decodeTyped<Half, Swap>(first, stride, arity, count, out);
    case ValueType::Float32:
      return decodeTyped<float, Swap>(first, stride, arity, count, out);
    case ValueType::Float64:
      return decodeTyped<double, Swap>(first, stride, arity, count, out);
  }
  FLIPSCOPE_CHECK(false, "unknown value type " << int(type));
}

}  // namespace

float halfToFloat(std::uint16_t bits) {
  const std::uint32_t sign = std::uint32_t(bits & 0x8000u) << 16;
  const std::uint32_t exponent = (bits >> 10) & 0x1fu;
  std::uint32_t mantissa = bits & 0x3ffu;
  std::uint32_t result;
  if (exponent == 0x1f) {
    result = sign | 0x7f800000u | (mantissa << 13);  // infinity, or NaN with its payload
  } else if (exponent != 0) {
    result = sign | ((exponent + 112) << 23) | (mantissa << 13);  // rebias 15 -> 127
  } else if (mantissa == 0) {
    result = sign;  // signed zero
  } else {
    // Subnormal: value = mantissa * 2^-24; normalise it.
    int shift = 0;
    while (!(mantissa & 0x400u)) {
      mantissa <<= 1;
      ++shift;
    }
    result = sign | (std::uint32_t(113 - shift) << 23) | ((mantissa & 0x3ffu) << 13);
  }
  return std::bit_cast<float>(result);
}

void decodeColumn(ValueType type, ByteOrder order, const std::byte* first, std::size_t stride, int arity,
                  std::size_t count, float* out) {
  FLIPSCOPE_CHECK(arity > 0, "arity=" << arity);
  const bool swap = (order == ByteOrder::Big) == (std::endian::native == std::endian::little);
  if (swap)
    decodeOrdered<true>(type, first, stride, arity, count, out);
  else
    decodeOrdered<false>(type, first, stride, arity, count, out);
}

void prepareColumns(ParticleChunk& chunk, const std::vector<AttributeColumn>& wanted, std::size_t count) {
  bool same = chunk.attributes.size() == wanted.size();
  for (std::size_t i = 0; same && i < wanted.size(); ++i)
    same = chunk.attributes[i].name == wanted[i].name && chunk.attributes[i].arity == wanted[i].arity;
  if (!same) chunk.attributes = wanted;
  for (auto& column : chunk.attributes) column.values.resize(count * std::size_t(column.arity));
}

}  // namespace flipscope::detail
