// readRecordBatches (preprocess/particles/BinaryColumns.h): the batch loop that the RealFlow and
// classic bgeo readers share, on records large enough that a frame takes several batches.
#include <gtest/gtest.h>

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "preprocess/particles/BinaryColumns.h"
#include "preprocess/particles/InputFile.h"

namespace flipscope {
namespace {

using detail::kRecordBatchBytes;
using detail::readRecordBatches;

/// `count` records of `stride` bytes; byte j of record i is (i * 31 + j) mod 251.
std::vector<std::byte> records(std::size_t count, std::size_t stride) {
  std::vector<std::byte> bytes(count * stride);
  for (std::size_t i = 0; i < count; ++i)
    for (std::size_t j = 0; j < stride; ++j) bytes[i * stride + j] = std::byte((i * 31 + j) % 251);
  return bytes;
}

struct Batch {
  std::size_t first, count;
};

TEST(RecordBatches, EveryRecordComesOnceInOrderInBatchesOfTheBatchBytesAndTheFileStandsAfterThem) {
  const std::size_t stride = kRecordBatchBytes / 3 + 5;  // two records a batch
  std::vector<std::byte> bytes = records(7, stride);
  bytes.resize(bytes.size() + 9, std::byte(0xee));  // what follows the records stays unread
  InputFile file("records.bin", bytes);
  std::vector<std::byte> buffer, seen;
  std::vector<Batch> batches;
  readRecordBatches(
      file, stride, 7, buffer,
      [&](const std::byte* data, std::size_t n, std::size_t first) {
        batches.push_back({first, n});
        seen.insert(seen.end(), data, data + n * stride);
      },
      [](std::size_t first) { return std::runtime_error("truncated at " + std::to_string(first)); });
  ASSERT_EQ(batches.size(), 4u);
  for (std::size_t b = 0; b < 4; ++b) {
    EXPECT_EQ(batches[b].first, 2 * b);
    EXPECT_EQ(batches[b].count, b < 3 ? 2u : 1u);
  }
  EXPECT_EQ(seen, std::vector<std::byte>(bytes.begin(), bytes.begin() + std::ptrdiff_t(7 * stride)));
  EXPECT_EQ(file.offset(), 7 * stride);
}

TEST(RecordBatches, NoRecordsReadNothing) {
  const std::vector<std::byte> bytes = records(2, 12);
  InputFile file("records.bin", bytes);
  std::vector<std::byte> buffer;
  readRecordBatches(
      file, 12, 0, buffer, [](const std::byte*, std::size_t, std::size_t) { FAIL() << "a batch of no records"; },
      [](std::size_t first) { return std::runtime_error("truncated at " + std::to_string(first)); });
  EXPECT_EQ(file.offset(), 0u);
}

TEST(RecordBatches, RecordsLargerThanABatchComeOneAtATime) {
  const std::size_t stride = kRecordBatchBytes + 3;
  const std::vector<std::byte> bytes = records(2, stride);
  InputFile file("records.bin", bytes);
  std::vector<std::byte> buffer, seen;
  std::size_t calls = 0;
  readRecordBatches(
      file, stride, 2, buffer,
      [&](const std::byte* data, std::size_t n, std::size_t first) {
        EXPECT_EQ(n, 1u);
        EXPECT_EQ(first, calls++);
        seen.insert(seen.end(), data, data + n * stride);
      },
      [](std::size_t first) { return std::runtime_error("truncated at " + std::to_string(first)); });
  EXPECT_EQ(calls, 2u);
  EXPECT_EQ(seen, bytes);
}

TEST(RecordBatches, AFileThatEndsInsideARecordThrowsWithThatRecordAfterTheBatchesBefore) {
  const std::size_t stride = kRecordBatchBytes / 3 + 5;
  std::vector<std::byte> bytes = records(7, stride);
  bytes.resize(5 * stride + 1);  // ends inside record 5, in the batch of records 4 and 5
  InputFile file("records.bin", bytes);
  std::vector<std::byte> buffer;
  std::vector<std::size_t> decoded;
  try {
    readRecordBatches(
        file, stride, 7, buffer,
        [&](const std::byte*, std::size_t, std::size_t first) { decoded.push_back(first); },
        [](std::size_t first) { return std::runtime_error("truncated at " + std::to_string(first)); });
    FAIL() << "a truncated file was read";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "truncated at 5");
  }
  EXPECT_EQ(decoded, (std::vector<std::size_t>{0, 2}));
}

}  // namespace
}  // namespace flipscope
