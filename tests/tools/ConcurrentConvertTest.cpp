// Concurrent writers without a scheduler (BrickStore.h, StoreLock.h): several `flipscope
// convert` processes add interleaved frames to one store at the same time, again and again; no
// frame is lost or damaged, every frame equals a serial convert's, and `info --verify` passes.
// Also: writers that create the store together agree on one header, and two writers of one
// frame leave one complete file.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "StoreComparison.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;
using flipscope::testing::CommandRun;
using flipscope::testing::runFlipscope;

constexpr int kFrames = 8;

/// Rounds of a race: `usual`, or FLIPSCOPE_RACE_ROUNDS where set. tests/run-asan.sh sets 1: the
/// plain run repeats the races, and under the sanitizers one round checks each path's memory
/// (each round is a dozen processes, ten times slower there).
int raceRounds(int usual) {
  return int(flipscope::testing::positiveCountFromEnvironment("FLIPSCOPE_RACE_ROUNDS", usual));
}

class ConcurrentConvert : public ::testing::Test {
 protected:
  void SetUp() override {
    CommandRun synth = runFlipscope("synth -o " + path("in_####.bin") + " --particles 30k --frames 1-" +
                                    std::to_string(kFrames));
    ASSERT_EQ(synth.exitCode, 0) << synth.output;
    CommandRun serial = runFlipscope("convert " + path("in_####.bin") + " -o " + path("serial") + " -q");
    ASSERT_EQ(serial.exitCode, 0) << serial.output;
  }
  std::string path(const std::string& name) const { return (temp.path() / name).string(); }

  /// Runs every command (a flipscope argument line) as its own process, all at once; the exit
  /// codes in order.
  static std::vector<int> runTogether(const std::vector<std::string>& commands) {
    std::vector<pid_t> pids;
    for (const auto& command : commands) {
      const std::string line = "'" FLIPSCOPE_BINARY "' " + command + " >/dev/null 2>&1";
      const pid_t pid = ::fork();
      if (pid == 0) {
        ::execl("/bin/sh", "sh", "-c", line.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
      }
      pids.push_back(pid);
    }
    std::vector<int> codes;
    for (pid_t pid : pids) {
      int status = 0;
      ::waitpid(pid, &status, 0);
      codes.push_back(WIFEXITED(status) ? WEXITSTATUS(status) : -1);
    }
    return codes;
  }

  flipscope::testing::TempDir temp{"concurrent"};
};

TEST_F(ConcurrentConvert, InterleavedFramesIntoAPreparedStoreAreAllThereAndIntact) {
  for (int round = 0; round < raceRounds(6); ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    const std::string store = path("s" + std::to_string(round));
    CommandRun prepare = runFlipscope("convert " + path("in_####.bin") + " -o " + store + " --prepare -q");
    ASSERT_EQ(prepare.exitCode, 0) << prepare.output;
    // Four writers, frames dealt round-robin (1 5, 2 6, ...), each frame its own convert.
    std::vector<std::string> commands;
    for (int f = 1; f <= kFrames; ++f)
      commands.push_back("convert " + path("in_####.bin") + " --frames " + std::to_string(f) + " -o " + store +
                         " --append -q");
    // Readers beside the writers see only complete frames: intact ones, or none yet, never a
    // damaged or missing one (`info --verify` would name it "damaged").
    for (int r = 0; r < 3; ++r)
      commands.push_back("info --verify " + store +
                         " 2>&1 | grep -v 'incomplete store' | grep -q '^damaged:' && exit 9 || exit 0");
    const std::vector<int> codes = runTogether(commands);
    for (int code : codes) EXPECT_EQ(code, 0);
    CommandRun verify = runFlipscope("info --verify " + store);
    EXPECT_EQ(verify.exitCode, 0) << verify.output;
    flipscope::testing::expectSameFrames(path("serial"), store);
  }
}

TEST_F(ConcurrentConvert, WritersThatCreateTheStoreTogetherAgreeOnOneHeader) {
  // No --prepare: the first writer to take the table lock creates the store, the others join it;
  // the same --domain and --cell-size make the same header.
  CommandRun info = runFlipscope("info --json " + path("serial"));
  ASSERT_EQ(info.exitCode, 0) << info.output;
  const flipscope::BrickStore serial = flipscope::BrickStore::open(path("serial"));
  const auto& h = serial.header();
  const glm::dvec3 max = h.domainMax();
  char domain[256];
  std::snprintf(domain, sizeof domain, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", h.origin.x, h.origin.y, h.origin.z,
                max.x, max.y, max.z);
  for (int round = 0; round < raceRounds(6); ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    const std::string store = path("c" + std::to_string(round));
    std::vector<std::string> commands;
    for (int w = 0; w < 4; ++w)
      commands.push_back("convert " + path("in_####.bin") + " --frames " + std::to_string(2 * w + 1) + "-" +
                         std::to_string(2 * w + 2) + " -o " + store + " --domain " + domain + " --cell-size " +
                         std::to_string(h.cellSize) + " -q");
    for (int code : runTogether(commands)) EXPECT_EQ(code, 0);
    CommandRun verify = runFlipscope("info --verify " + store);
    EXPECT_EQ(verify.exitCode, 0) << verify.output;
    EXPECT_EQ(flipscope::BrickStore::open(store).frames().size(), std::size_t(kFrames));
  }
}

TEST_F(ConcurrentConvert, TwoWritersOfTheSameFrameLeaveOneCompleteFile) {
  for (int round = 0; round < raceRounds(4); ++round) {
    const std::string store = path("same" + std::to_string(round));
    ASSERT_EQ(runFlipscope("convert " + path("in_####.bin") + " -o " + store + " --prepare -q").exitCode, 0);
    const std::string frame3 = "convert " + path("in_####.bin") + " --frames 3 -o " + store + " --append -q";
    for (int code : runTogether({frame3, frame3, frame3})) EXPECT_EQ(code, 0);
    CommandRun verify = runFlipscope("info --verify " + store);
    EXPECT_EQ(verify.exitCode, 0) << verify.output;
    const flipscope::BrickStore s = flipscope::BrickStore::open(store);
    ASSERT_EQ(s.frames(), std::vector<int>{3});
    for (const auto& entry : fs::directory_iterator(store))  // no temporary left behind
      EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
  }
}

}  // namespace
