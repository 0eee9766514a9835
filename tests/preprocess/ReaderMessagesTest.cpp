// Reader errors of issue 12: a message quoting bytes of the file is not cut at a NUL byte; an
// ascii PLY cut inside its last number is refused, not read with the wrong value; an input with
// no particles (Mantaflow's real empty first frame among them) gives an error naming the file.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <string>

#include "ParticleTestSupport.h"
#include "TestSupport.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;
using namespace std::string_literals;
using testing::expectFileError;
using testing::TempDir;

TEST(FileErrorMessage, ControlBytesArePrintedNotCut) {
  const FileError e("f.ply", "unknown keyword 'ab\0cd\x01\x7f'\nnext"s);
  EXPECT_EQ(std::string(e.what()), "f.ply: unknown keyword 'ab\\x00cd\\x01\\x7f'\nnext");
  EXPECT_EQ(std::strlen(e.what()), std::string(e.what()).size());
}

TEST(FileErrorMessage, NulByteReadFromAPlyHeader) {
  TempDir dir("nul");
  const std::string header = "ply\nformat ascii 1.0\nele\0ment vertex 1\n"s +
                             "property float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n";
  testing::writeBytes(dir / "nul.ply", header);
  expectFileError([&] { testing::readFile(dir / "nul.ply"); }, {"nul.ply", "ele\\x00ment"});
  const auto run = testing::runFlipscope("convert nul.ply -o store", dir.path());
  EXPECT_EQ(run.exitCode, 3) << run.output;
  EXPECT_NE(run.output.find("'ele\\x00ment'"), std::string::npos) << run.output;
}

TEST(AsciiPly, CutInsideTheLastNumberIsRefused) {
  TempDir dir("ply-cut");
  const std::string full =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n1.5 2.5 3.5\n-0.25 0.125 7.0625\n";
  testing::writeBytes(dir / "full.ply", full);
  const ParticleChunk read = testing::readFile(dir / "full.ply");
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read.positions[1].z, 7.0625f);
  // Cut anywhere inside the last line, its line break included: refused.
  const std::size_t lastLine = full.rfind('\n', full.size() - 2) + 1;
  for (std::size_t length = lastLine + 1; length < full.size(); ++length) {
    testing::writeBytes(dir / "cut.ply", full.substr(0, length));
    expectFileError([&] { testing::readFile(dir / "cut.ply"); }, {"cut.ply", "line 9"});
  }
  // CRLF line breaks are line breaks.
  testing::writeBytes(dir / "crlf.ply",
                      "ply\r\nformat ascii 1.0\r\nelement vertex 1\r\nproperty float x\r\n"
                      "property float y\r\nproperty float z\r\nend_header\r\n1 2 3\r\n");
  EXPECT_EQ(testing::readFile(dir / "crlf.ply").size(), 1u);
}

TEST(EmptyInput, ConvertNamesTheFile) {
  TempDir dir("empty-input");
  const fs::path mantaflow = flipscope::testing::mantaflowFile("particles", "fluid_particles_0001.vdb");
  ASSERT_TRUE(fs::exists(mantaflow));
  EXPECT_EQ(testing::readFile(mantaflow).size(), 0u);  // a real, valid, empty frame
  testing::writeBytes(dir / "empty.bin", "");
  testing::writeBytes(dir / "empty.ply",
                      "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n"
                      "property float y\nproperty float z\nend_header\n");
  for (const std::string& input : {mantaflow.string(), std::string("empty.bin"), std::string("empty.ply")}) {
    const auto run = testing::runFlipscope("convert '" + input + "' -o store -q", dir.path());
    EXPECT_NE(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find(fs::path(input).filename().string() + ": no finite particle positions"),
              std::string::npos)
        << run.output;
  }
  // An empty VDB file (0 bytes) is not an OpenVDB file, and says so with its name.
  testing::writeBytes(dir / "zero.vdb", "");
  expectFileError([&] { testing::readFile(dir / "zero.vdb"); }, {"zero.vdb", "empty file"});
}

}  // namespace
}  // namespace flipscope
