// DirectFile: what is appended in blocks reads back the same, and the end of the file shows as
// a short read; errors name the file.
#include <gtest/gtest.h>

#include <cstring>

#include "core/Error.h"
#include "preprocess/DirectFile.h"
#include "TestSupport.h"

namespace flipscope {
namespace {

using detail::AlignedBuffer;
using detail::DirectFile;
using detail::kDirectBlock;

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

}  // namespace
}  // namespace flipscope
