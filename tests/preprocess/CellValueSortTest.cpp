// sortCellValues (preprocess/CellValueSort.h): a cell's attribute values, ascending, whatever
// their count, order and ties.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "preprocess/CellValueSort.h"

namespace flipscope {
namespace {

TEST(CellValueSort, ACellsValuesAreSortedWhateverTheirCountAndTies) {
  // Every count up to past the largest network (16), with ties and both ends of the range.
  std::mt19937 rng(5);
  for (std::uint32_t count = 0; count <= 40; ++count) {
    for (int trial = 0; trial < 50; ++trial) {
      std::vector<std::uint16_t> values(count);
      for (auto& v : values)
        v = trial % 3 == 0 ? std::uint16_t(rng() % 3 ? 65535 : 0)
                           : std::uint16_t(trial % 3 == 1 ? rng() : rng() % 7 * 9000);
      std::vector<std::uint16_t> expected = values;
      std::sort(expected.begin(), expected.end());
      detail::sortCellValues(values.data(), count);
      ASSERT_EQ(values, expected) << count << " values, trial " << trial;
    }
  }
}

TEST(CellValueSort, EverySequenceOfTwoValuesUpToSixteenIsSorted) {
  // A comparison network that sorts every sequence of 0s and 1s sorts every sequence (the 0-1
  // principle): on builds that sort by a network (CellValueSort.cpp), the counts 8 and 16 prove
  // each network over all of its inputs, and the others check the padding.
  // Two values near the top too, where the padding (0xffff) ties with the larger.
  for (const std::uint16_t low : {std::uint16_t(0), std::uint16_t(65534)}) {
    for (std::uint32_t count = 2; count <= 16; ++count) {
      for (std::uint32_t bits = 0; bits < (1u << count); ++bits) {
        std::vector<std::uint16_t> values(count);
        for (std::uint32_t i = 0; i < count; ++i) values[i] = std::uint16_t(low + ((bits >> i) & 1));
        std::vector<std::uint16_t> expected = values;
        std::sort(expected.begin(), expected.end());
        detail::sortCellValues(values.data(), count);
        ASSERT_EQ(values, expected) << count << " values, bits " << bits << ", from " << low;
      }
    }
  }
}

TEST(CellValueSort, NeitherReadsNorWritesPastTheCount) {
  // The cell's values lie inside a brick's buffer, between other cells' values: 0xffff before
  // and 0 after them, which a sort of a whole register's lanes read from the buffer would move.
  for (std::uint32_t count = 0; count <= 17; ++count) {
    std::vector<std::uint16_t> buffer(count + 32, 0);
    std::fill(buffer.begin(), buffer.begin() + 16, std::uint16_t(0xffff));
    for (std::uint32_t i = 0; i < count; ++i) buffer[16 + i] = std::uint16_t(1000 - i);
    detail::sortCellValues(buffer.data() + 16, count);
    for (std::uint32_t i = 0; i < 16; ++i) ASSERT_EQ(buffer[i], 0xffff) << count;
    for (std::uint32_t i = 16 + count; i < buffer.size(); ++i) ASSERT_EQ(buffer[i], 0) << count;
    for (std::uint32_t i = 0; i < count; ++i) ASSERT_EQ(buffer[16 + i], std::uint16_t(1000 - (count - 1) + i)) << count;
  }
}

}  // namespace
}  // namespace flipscope
