// VDB point files written by OpenVDB in every way the reader must handle: each vec3s codec for
// P and the velocity, uniform attributes, blosc / zip / no compression, files with grid offsets
// (io::File) and streams without (io::Stream), pages larger than OpenVDB's 1 MiB page, several
// grids, half-float grids, linear transforms, an empty grid. Used by the oracle test, the damage
// test and to make the fuzz seed corpus (FuzzCorpusTest.cpp). The writing is compiled once, in
// VdbTestFiles.cpp (library flipscope_vdb_test_files): this header includes no OpenVDB.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace flipscope::testing {

struct VdbTestFile {
  std::filesystem::path path;
  std::vector<std::string> pointGrids;  ///< in file order
  std::string what;
  bool unreadTail = false;  ///< ends with a grid the reader skips unread (not points, no grid offsets)
};

/// Writes the test files into `dir`. `scale` multiplies the particle counts; `large` adds the
/// files with pages over 1 MiB and many pages; `compact` puts the points into few leaves (small
/// files for the fuzz seeds).
std::vector<VdbTestFile> vdbTestFiles(const std::filesystem::path& dir, double scale = 1.0, bool large = true,
                                      bool compact = false);

}  // namespace flipscope::testing
