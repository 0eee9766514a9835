// Every seed of the fuzz corpus and every crasher the fuzzers found, replayed through the fuzz
// targets' bodies (FuzzTargets.h) in the ordinary build: a seed must be accepted (the corpus
// holds valid files), a crasher must be refused cleanly (a FileError: no crash, no other
// exception). A crasher found by tests/fuzz/run-fuzz.sh goes into tests/fuzz/regressions/<target>/
// once fixed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "FuzzTargets.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;

std::vector<std::byte> fileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<char> chars((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::byte> bytes(chars.size());
  if (!chars.empty()) std::memcpy(bytes.data(), chars.data(), chars.size());  // an empty crasher has no data()
  return bytes;
}

std::vector<fs::path> filesIn(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (entry.is_regular_file()) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

const fs::path kFuzzDir = FLIPSCOPE_FUZZ_DIR;

TEST(FuzzCorpus, EverySeedIsAccepted) {
  for (const fuzz::Target& target : fuzz::kTargets) {
    const auto seeds = filesIn(kFuzzDir / "corpus" / target.name);
    EXPECT_GE(seeds.size(), 2u) << "no seed corpus in tests/fuzz/corpus/" << target.name;
    for (const auto& seed : seeds)
      EXPECT_EQ(target.run(fileBytes(seed)), fuzz::Result::Accepted)
          << seed << " is refused by its target: regenerate the corpus (tests/fuzz/FuzzCorpusTest.cpp)";
  }
}

TEST(FuzzRegressions, EveryCrasherIsHandled) {
  std::size_t inputs = 0;
  for (const fuzz::Target& target : fuzz::kTargets)
    for (const auto& input : filesIn(kFuzzDir / "regressions" / target.name)) {
      // A clean refusal; an escaping exception fails the test, and a crash fails it too. An input
      // that is valid after all (a crash in the target's own checks) is named *.accepted.
      const fuzz::Result result = target.run(fileBytes(input));
      EXPECT_EQ(result, input.extension() == ".accepted" ? fuzz::Result::Accepted : fuzz::Result::Refused) << input;
      ++inputs;
    }
  std::printf("%zu crasher inputs replayed\n", inputs);
  // Every regressions/ folder is replayed (a renamed target would leave its crashers unread).
  std::size_t folders = 0, inFolders = 0;
  for (const auto& folder : std::filesystem::directory_iterator(kFuzzDir / "regressions")) {
    ++folders;
    inFolders += filesIn(folder.path()).size();
  }
  EXPECT_GT(folders, 0u);
  EXPECT_EQ(inputs, inFolders) << "a regressions/ folder is named after no fuzz target";
}

}  // namespace
}  // namespace flipscope
