// DirectReadAhead: a file read around the page cache gives every byte in order, from any offset,
// through reads of any size, whether its pages are cached or not; a file truncated meanwhile
// ends the read short. InputFile streams the large reads in order of a file read once that is
// not in the cache, and reads anything else through the cache.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "TestSupport.h"
#include "core/AtomicFile.h"
#include "core/Error.h"
#include "preprocess/particles/DirectReadAhead.h"
#include "preprocess/particles/InputFile.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;
constexpr std::size_t kMiB = std::size_t(1) << 20;

/// The byte at `offset` of the test files: no two pieces alike.
std::byte patternByte(std::uint64_t offset) { return std::byte((offset * 2654435761u) >> 13); }

/// A file of `bytes` bytes of patternByte, dropped from the page cache.
struct PatternFile {
  fs::path path;
  bool dropped;  ///< its pages left the cache (not on tmpfs): reads around the cache leave them out
};
PatternFile writePatternFile(const testing::TempDir& dir, const std::string& name, std::size_t bytes) {
  std::vector<std::byte> data(bytes);
  for (std::size_t i = 0; i < bytes; ++i) data[i] = patternByte(i);
  const fs::path path = dir / name;
  AtomicFile file(path);
  file.write(data.data(), data.size());
  file.commit();
  return {path, testing::dropFromPageCache(path)};
}

/// The first offset in [offset, offset + n) whose byte in `data` is not the pattern's, else -1.
std::int64_t firstWrongByte(const std::vector<std::byte>& data, std::uint64_t offset, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i)
    if (data[i] != patternByte(offset + i)) return std::int64_t(offset + i);
  return -1;
}

/// The two descriptors DirectReadAhead reads through, and what is cached of the file.
struct OpenFile {
  explicit OpenFile(const fs::path& path)
      : cached(::open(path.c_str(), O_RDONLY | O_CLOEXEC)),
        direct(::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_DIRECT)),
        size(fs::file_size(path)),
        residency(cached, size) {}
  ~OpenFile() {
    ::close(cached);
    if (direct >= 0) ::close(direct);
  }
  int cached, direct;  // direct: -1 where the file system takes no O_DIRECT
  std::uint64_t size;
  PageCacheResidency residency;
  int directOrCached() const { return direct >= 0 ? direct : cached; }
};

TEST(DirectReadAhead, GivesEveryByteInOrderFromAnUnalignedStartThroughReadsOfAnySize) {
  testing::TempDir dir("direct-read-ahead");
  const std::size_t size = 7 * kMiB + 1237;  // neither whole pieces nor whole blocks
  const auto [path, dropped] = writePatternFile(dir, "pattern.bin", size);
  OpenFile file(path);
  const std::uint64_t start = 4096 + 6;
  DirectReadAhead stream(file.directOrCached(), file.cached, path, file.size, start, 4 * kMiB);
  const std::size_t sizes[] = {1, 4095, kMiB + 13, 3 * kMiB + 7, 100};
  std::uint64_t offset = start;
  for (std::size_t i = 0; offset < size; ++i) {
    const std::size_t want = sizes[i % std::size(sizes)];
    std::vector<std::byte> data(want);
    ASSERT_EQ(stream.position(), offset);
    const std::size_t got = stream.read(data.data(), want);
    ASSERT_EQ(got, std::min<std::uint64_t>(want, size - offset)) << "at " << offset;
    ASSERT_EQ(firstWrongByte(data, offset, got), -1);
    offset += got;
  }
  std::byte byte;
  EXPECT_EQ(stream.read(&byte, 1), 0u);  // the end, again and again
  EXPECT_EQ(stream.read(&byte, 1), 0u);
  // Read around the cache: the pages read stay out of it.
  if (dropped) {
    EXPECT_FALSE(file.residency.cached(3 * kMiB, kMiB));
  }
}

TEST(DirectReadAhead, PagesInTheCacheReadTheSameAroundIt) {
  testing::TempDir dir("direct-read-ahead");
  const std::size_t size = 9 * kMiB + 77;
  const auto [path, dropped] = writePatternFile(dir, "pattern.bin", size);
  OpenFile file(path);
  std::vector<std::byte> data(3 * kMiB);
  ASSERT_EQ(::pread(file.cached, data.data(), data.size(), off_t(2 * kMiB)), ssize_t(data.size()));  // cached now
  ASSERT_TRUE(file.residency.cached(2 * kMiB, 3 * kMiB));
  DirectReadAhead stream(file.directOrCached(), file.cached, path, file.size, 0, 4 * kMiB);
  data.resize(size + 10);
  ASSERT_EQ(stream.read(data.data(), data.size()), size);
  EXPECT_EQ(firstWrongByte(data, 0, size), -1);
  if (dropped) {
    EXPECT_FALSE(file.residency.cached(6 * kMiB, 2 * kMiB));
    // Sampled: one page out of the cache is found where it is a sample, a first or last page.
    // (Read into the cache again: a VM that hands free memory back to its host may have taken
    // the pages since; a CI run saw it, with 73 MB left cached of 24 GB.)
    ASSERT_EQ(::pread(file.cached, data.data(), 3 * kMiB, off_t(2 * kMiB)), ssize_t(3 * kMiB));
    EXPECT_TRUE(file.residency.sampledCached(2 * kMiB, 3 * kMiB, 16));
    EXPECT_FALSE(file.residency.sampledCached(2 * kMiB, 3 * kMiB + 4096, 16));
    EXPECT_FALSE(file.residency.sampledCached(2 * kMiB - 4096, 3 * kMiB, 16));
  }
}

TEST(DirectReadAhead, AFileTruncatedWhileReadEndsTheReadShort) {
  testing::TempDir dir("direct-read-ahead");
  const std::size_t size = 8 * kMiB, truncated = 3 * kMiB + 100;
  const auto [path, dropped] = writePatternFile(dir, "pattern.bin", size);
  OpenFile file(path);
  // Two pieces ahead: after the first MiB, the threads cannot have gone past 4 MiB.
  DirectReadAhead stream(file.directOrCached(), file.cached, path, file.size, 0, 4 * kMiB);
  std::vector<std::byte> data(size);
  ASSERT_EQ(stream.read(data.data(), kMiB), kMiB);
  fs::resize_file(path, truncated);
  const std::size_t rest = stream.read(data.data() + kMiB, size - kMiB);
  // What was read before the truncation, and no more: up to the end of the pieces in the ring.
  EXPECT_GE(kMiB + rest, truncated);
  EXPECT_LE(kMiB + rest, 4 * kMiB);
  EXPECT_EQ(firstWrongByte(data, 0, kMiB + rest), -1);
  std::byte byte;
  EXPECT_EQ(stream.read(&byte, 1), 0u);
}

TEST(DirectReadAhead, AReadErrorReachesTheReaderNamingTheFile) {
  testing::TempDir dir("direct-read-ahead");
  const fs::path path = writePatternFile(dir, "pattern.bin", 5 * kMiB).path;
  OpenFile file(path);
  // A directory in place of the file: every read fails (EISDIR).
  const int directory = ::open(dir.path().c_str(), O_RDONLY | O_CLOEXEC | O_DIRECTORY);
  ASSERT_GE(directory, 0);
  {
    DirectReadAhead stream(directory, directory, path, file.size, 0, 4 * kMiB);
    std::vector<std::byte> data(kMiB);
    try {
      stream.read(data.data(), data.size());
      ADD_FAILURE() << "no error";
    } catch (const FileError& e) {
      EXPECT_NE(std::string(e.what()).find("pattern.bin"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("read failed at byte 0"), std::string::npos) << e.what();
    }
    EXPECT_THROW(stream.read(data.data(), data.size()), FileError);  // and again: the stream is stuck there
  }
  ::close(directory);
}

TEST(InputFile, AFileReadOnceStreamsItsReadsInOrderAndReadsAnythingElseThroughTheCache) {
  testing::TempDir dir("direct-read-ahead");
  const std::size_t size = 11 * kMiB + 4321;
  const auto [path, dropped] = writePatternFile(dir, "pattern.bin", size);
  std::vector<std::byte> data(4 * kMiB);
  {
    InputFile input(path, 4 * kMiB);
    auto expectRead = [&](std::size_t bytes) {
      const std::uint64_t at = input.offset();
      const std::size_t got = input.read(data.data(), bytes);
      EXPECT_EQ(got, std::min<std::uint64_t>(bytes, size - at)) << "at " << at;
      EXPECT_EQ(firstWrongByte(data, at, got), -1) << "at " << at;
    };
    expectRead(100);           // InputFile's buffer fills 64 KiB at the start, through the cache
    expectRead(2 * kMiB + 3);  // the rest of the buffer, then a large read: the stream starts
    expectRead(3 * kMiB);
    input.seek(12345);  // back: from the buffer, then the rest through the cache (too short for a stream)
    expectRead(kMiB);
    expectRead(kMiB + 1);  // a large read that continues the last: a new stream
    std::vector<std::byte> small(64);  // a read elsewhere in between, through the cache
    ASSERT_EQ(input.readAt(size - 64, small.data(), 64), 64u);
    for (std::size_t i = 0; i < 64; ++i) ASSERT_EQ(small[i], patternByte(size - 64 + i));
    while (input.offset() < size) expectRead(4 * kMiB);  // on to the end: the last read is short
    EXPECT_EQ(input.read(data.data(), 1), 0u);
  }
  if (!dropped) return;  // tmpfs: its pages are the file
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  const PageCacheResidency residency(fd, size);
  EXPECT_FALSE(residency.cached(8 * kMiB, kMiB));  // streamed around the cache
  // A file in the cache is read through it: its page 1, no sample of the residency, dropped
  // alone, is read into the cache again (a stream would leave it out).
  std::vector<std::byte> all(size);
  ASSERT_EQ(::pread(fd, all.data(), size, 0), ssize_t(size));
  ::posix_fadvise(fd, 4096, 4096, POSIX_FADV_DONTNEED);
  ASSERT_FALSE(residency.cached(4096, 4096));
  ASSERT_TRUE(residency.cached(0, 4096));
  InputFile cachedInput(path, 4 * kMiB);
  ASSERT_EQ(cachedInput.read(all.data(), kMiB), kMiB);
  ASSERT_EQ(cachedInput.read(all.data() + kMiB, size), size - kMiB);
  EXPECT_EQ(firstWrongByte(all, 0, size), -1);
  EXPECT_TRUE(residency.cached(4096, 4096));
  ::close(fd);
}

}  // namespace
}  // namespace flipscope
