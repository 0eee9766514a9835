// DirectFile: what is appended in blocks reads back the same, and the end of the file shows as
// a short read; errors name the file.
#include <gtest/gtest.h>

#include <cstring>

#include "TestSupport.h"
#include "core/Error.h"
#include "preprocess/DirectFile.h"

namespace flipscope {
namespace {

using detail::DirectFile;

TEST(DirectFile, BlocksReadBackInOrderAndTheEndIsAShortRead) {
  testing::TempDir dir("direct-file");
  const auto path = dir / "spill";
  AlignedBuffer block(3 * kDirectBlock);
  ASSERT_EQ(reinterpret_cast<std::uintptr_t>(block.data()) % kDirectBlock, 0u);
  {
    DirectFile file(path, DirectFile::Mode::Create);
    for (int b = 0; b < 5; ++b) {  // 5 appends of 3 blocks, each byte telling its place
      for (std::size_t i = 0; i < block.size(); ++i) block.data()[i] = std::byte((b * 7 + i * 13) & 0xff);
      file.append({block.data(), block.size()});
    }
  }
  EXPECT_EQ(std::filesystem::file_size(path), 15 * kDirectBlock);
  DirectFile file(path, DirectFile::Mode::Read);
  AlignedBuffer into(4 * kDirectBlock);  // pieces that straddle the appends
  std::size_t offset = 0, got = 0;
  while ((got = file.read({into.data(), into.size()})) > 0) {
    for (std::size_t i = 0; i < got; ++i) {
      const std::size_t at = offset + i, b = at / (3 * kDirectBlock), within = at % (3 * kDirectBlock);
      ASSERT_EQ(into.data()[i], std::byte((b * 7 + within * 13) & 0xff)) << "byte " << at;
    }
    offset += got;
    if (got < into.size()) break;
  }
  EXPECT_EQ(offset, 15 * kDirectBlock);
  EXPECT_EQ(got, 3 * kDirectBlock);  // the last read is short
}

TEST(DirectFile, AFileThatCannotBeCreatedOrOpenedIsNamed) {
  testing::TempDir dir("direct-file-missing");
  const auto path = dir / "no" / "such";
  try {
    DirectFile file(path, DirectFile::Mode::Create);
    FAIL() << "created a file in a missing folder";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  EXPECT_THROW(DirectFile(path, DirectFile::Mode::Read), FileError);
}

TEST(BackgroundAppender, WritesEachFilesBlocksInOrderWhileTheCallerGoesOn) {
  // Two files, blocks queued to them in turn through buffers taken from the appender; each file
  // holds its blocks in the order queued once drained.
  testing::TempDir dir("background-appender");
  constexpr int kBlocks = 40;
  {
    DirectFile a(dir / "a", DirectFile::Mode::Create), b(dir / "b", DirectFile::Mode::Create);
    detail::BackgroundAppender appender(kDirectBlock, 3);
    for (int i = 0; i < kBlocks; ++i) {
      for (DirectFile* file : {&a, &b}) {
        AlignedBuffer block = appender.take();
        ASSERT_EQ(block.size(), kDirectBlock);
        std::memset(block.data(), file == &a ? i : 100 + i, block.size());
        appender.append(*file, std::move(block), kDirectBlock);
      }
    }
    appender.drain();
  }
  for (const char* name : {"a", "b"}) {
    DirectFile file(dir / name, DirectFile::Mode::Read);
    AlignedBuffer block(kDirectBlock);
    for (int i = 0; i < kBlocks; ++i) {
      ASSERT_EQ(file.read({block.data(), block.size()}), kDirectBlock) << name << " block " << i;
      EXPECT_EQ(block.data()[kDirectBlock - 1], std::byte(name[0] == 'a' ? i : 100 + i)) << name << " block " << i;
    }
    EXPECT_EQ(file.read({block.data(), block.size()}), 0u) << name;
  }
}

TEST(BackgroundAppender, AWriteErrorComesBackFromTheNextCall) {
  testing::TempDir dir("background-appender-error");
  { DirectFile(dir / "readonly", DirectFile::Mode::Create); }
  DirectFile readOnly(dir / "readonly", DirectFile::Mode::Read);  // writes to it fail
  detail::BackgroundAppender appender(kDirectBlock, 2);
  AlignedBuffer block = appender.take();
  std::memset(block.data(), 0, block.size());
  appender.append(readOnly, std::move(block), kDirectBlock);
  try {
    appender.drain();
    FAIL() << "the failed write was not reported";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("readonly"), std::string::npos) << e.what();
  }
  appender.drain();  // reported once
}

}  // namespace
}  // namespace flipscope
