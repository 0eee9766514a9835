// readRecordBatches (preprocess/particles/BinaryColumns.h): the batch loop that the RealFlow,
// classic bgeo and binary PLY readers share, on records large enough that a frame takes several
// batches.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
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
  const std::size_t stride = kRecordBatchBytes / 2 + 5;  // two records a batch: the fewest that make one
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
  const std::size_t stride = kRecordBatchBytes / 2 + 5;
  std::vector<std::byte> bytes = records(7, stride);
  bytes.resize(5 * stride + 1);  // ends inside record 5, in the batch of records 4 and 5
  InputFile file("records.bin", bytes);
  std::vector<std::byte> buffer;
  std::vector<std::size_t> decoded;
  try {
    readRecordBatches(
        file, stride, 7, buffer, [&](const std::byte*, std::size_t, std::size_t first) { decoded.push_back(first); },
        [](std::size_t first) { return std::runtime_error("truncated at " + std::to_string(first)); });
    FAIL() << "a truncated file was read";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "truncated at 5");
  }
  EXPECT_EQ(decoded, (std::vector<std::size_t>{0, 2}));
}

/// Bytes in memory that say where each read of them went and how long it was.
class RecordingSource final : public ByteSource {
 public:
  struct Read {
    const void* into;
    std::size_t bytes;
  };
  explicit RecordingSource(std::vector<std::byte> bytes, std::vector<Read>& reads)
      : mBytes(std::move(bytes)), mReads(reads) {}
  std::uint64_t size() const override { return mBytes.size(); }
  std::size_t readAt(std::uint64_t offset, void* data, std::size_t bytes) override {
    const std::size_t n = offset >= mBytes.size() ? 0 : std::min<std::size_t>(bytes, mBytes.size() - offset);
    if (n) std::memcpy(data, mBytes.data() + offset, n);
    mReads.push_back({data, bytes});
    return n;
  }

 private:
  std::vector<std::byte> mBytes;
  std::vector<Read>& mReads;
};

TEST(RecordBatches, EachBatchIsReadStraightIntoTheBatchBufferNotThroughTheFilesBuffer) {
  // A header read through the file's buffer first, as the PLY reader's: the first batch starts
  // inside that buffer, and every batch after it must still not be copied through it.
  const std::size_t header = 100, stride = 24, count = 3 * (kRecordBatchBytes / stride) + 7;
  std::vector<std::byte> bytes = records(1, header);
  const std::vector<std::byte> body = records(count, stride);
  bytes.insert(bytes.end(), body.begin(), body.end());
  std::vector<RecordingSource::Read> reads;
  InputFile file("records.bin", std::make_unique<RecordingSource>(bytes, reads));
  std::vector<std::byte> head(header);
  file.readExact(head.data(), header, "the header");
  const std::size_t headerReads = reads.size();
  std::vector<std::byte> buffer, seen;
  std::vector<const std::byte*> batchData;
  readRecordBatches(
      file, stride, count, buffer,
      [&](const std::byte* data, std::size_t n, std::size_t) {
        batchData.push_back(data);
        seen.insert(seen.end(), data, data + n * stride);
      },
      [](std::size_t first) { return std::runtime_error("truncated at " + std::to_string(first)); });
  EXPECT_EQ(seen, body);
  const std::size_t batch = (kRecordBatchBytes + stride - 1) / stride;
  ASSERT_GT(header + batch * stride, std::size_t(64) << 10) << "the first batch must pass the file's first fill";
  ASSERT_EQ(batchData.size(), (count + batch - 1) / batch);
  // The full batches: one read each, into the batch's own buffer (the first after what the
  // file's buffer held of it); the last, short one may go through the file's buffer.
  ASSERT_GE(reads.size(), headerReads + batchData.size() - 1);
  // Addresses as integers: a read into another allocation (the file's buffer) compares too.
  const auto address = [](const void* p) { return reinterpret_cast<std::uintptr_t>(p); };
  for (std::size_t b = 0; b + 1 < batchData.size(); ++b) {
    const RecordingSource::Read& r = reads[headerReads + b];
    EXPECT_GE(address(r.into), address(batchData[b])) << "batch " << b;
    EXPECT_EQ(address(r.into) + r.bytes, address(batchData[b]) + batch * stride) << "batch " << b;
  }
}

}  // namespace
}  // namespace flipscope
