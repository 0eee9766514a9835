// Fixed-size binary records (PRT, RealFlow .bin, classic bgeo, binary PLY, Maya PDB): read a
// batch at a time (readRecordBatches), and decoded a column at a time: one value type, byte
// order, offset and stride for a whole column, decoded to float in a tight loop. The switch on
// the type runs once a column, never once a value. Private to flipscope::particles.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleSource.h"
#include "preprocess/particles/ValueDecode.h"  // valueTypeBytes

namespace flipscope::detail {

enum class ByteOrder : std::uint8_t { Little, Big };

/// IEEE 754 binary16 to float, exactly (subnormals, infinities and NaN included).
float halfToFloat(std::uint16_t bits);

/// Decodes `count` records: from each, `arity` components of `type` starting at `first` (the
/// column in the first record), records `stride` bytes apart, into `out` (count * arity floats,
/// record after record). Integers convert to the nearest float, doubles round to float.
void decodeColumn(ValueType type, ByteOrder order, const std::byte* first, std::size_t stride, int arity,
                  std::size_t count, float* out);

/// decodeColumn() with arity 3 into vectors.
inline void decodeVec3Column(ValueType type, ByteOrder order, const std::byte* first, std::size_t stride,
                             std::size_t count, glm::vec3* out) {
  static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
  decodeColumn(type, order, first, stride, 3, count, reinterpret_cast<float*>(out));
}

/// Bytes of records a reader reads and decodes at once: in the cache, and few reads.
inline constexpr std::size_t kRecordBatchBytes = InputFile::kLargeReadBytes;

/// Reads `count` records of `stride` (> 0) bytes from where `file` stands, the fewest that make
/// kRecordBatchBytes (at least one) at a time into `buffer`, and calls decode(records, n, first)
/// for each batch of n records, the first of them record `first` of the `count`. A batch of that
/// size is a large read of `file` (InputFile::kLargeReadBytes): what the file's buffer does not
/// hold of it is read from its source straight into `buffer`. Leaves `file` just after the last
/// record. Where the file ends inside record i (of the `count`), throws what truncated(i)
/// returns, the records before i's batch decoded.
template <class Decode, class Truncated>
void readRecordBatches(InputFile& file, std::size_t stride, std::size_t count, std::vector<std::byte>& buffer,
                       const Decode& decode, const Truncated& truncated) {
  const std::size_t batch = 1 + (kRecordBatchBytes - 1) / stride;  // rounded up, without overflow
  for (std::size_t first = 0; first < count; first += batch) {
    const std::size_t n = std::min(batch, count - first);
    buffer.resize(n * stride);
    const std::size_t got = file.read(buffer.data(), buffer.size());
    if (got != buffer.size()) throw truncated(first + got / stride);
    decode(buffer.data(), n, first);
  }
}

/// Gives `chunk` the columns of `wanted` (names and arities; a chunk may come from another
/// source) with room for `count` particles each.
void prepareColumns(ParticleChunk& chunk, const std::vector<AttributeColumn>& wanted, std::size_t count);

}  // namespace flipscope::detail
