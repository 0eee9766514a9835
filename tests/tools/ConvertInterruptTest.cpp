// Interrupted converts, end to end: `flipscope convert` killed (SIGKILL) or interrupted
// (SIGINT) at every stage of a three-frame, partly out-of-core conversion, at instrumented
// points (FLIPSCOPE_CONVERT_STOP, Convert.h) and after increasing delays. After SIGINT nothing
// is left but complete, listed frames; after SIGKILL the store holds its complete frames or
// reports itself incomplete; either way the next convert removes what is stale and finishes.
// Then the integrity checks of `info`: incomplete stores, missing frames, foreign frames.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "TestSupport.h"
#include "core/Elapsed.h"
#include "preprocess/store/BrickStore.h"
#include "preprocess/store/StoreLock.h"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using flipscope::testing::CommandRun;
using flipscope::testing::runFlipscope;

/// Starts `flipscope args...` with FLIPSCOPE_CONVERT_STOP=`stop` (none when empty), output to
/// `log`. Only async-signal-safe calls between fork and exec.
pid_t start(const std::vector<std::string>& args, const std::string& stop, const fs::path& log) {
  std::vector<std::string> strings = {FLIPSCOPE_BINARY};
  strings.insert(strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& s : strings) argv.push_back(s.data());
  argv.push_back(nullptr);
  std::vector<std::string> env;
  for (char** e = environ; *e; ++e)
    if (std::strncmp(*e, "FLIPSCOPE_CONVERT_STOP=", 23) != 0) env.emplace_back(*e);
  if (!stop.empty()) env.push_back("FLIPSCOPE_CONVERT_STOP=" + stop);
  std::vector<char*> envp;
  for (auto& s : env) envp.push_back(s.data());
  envp.push_back(nullptr);
  const std::string logPath = log.string();
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(logPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      ::dup2(fd, 1);
      ::dup2(fd, 2);
    }
    ::execve(argv[0], argv.data(), envp.data());
    ::_exit(127);
  }
  return pid;
}

int waitFor(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return status;
}

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

bool isStale(const std::string& name) {
  return name.find(".tmp-") != std::string::npos || name.rfind(".flipscope-spill-", 0) == 0;
}

std::vector<std::string> namesIn(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

/// The JSON document in `output` (stdout and stderr together: stderr lines come first).
nlohmann::json parseJson(const std::string& output) {
  const std::size_t at = output.rfind('{', 0) == 0 ? 0 : output.find("\n{");
  if (at == std::string::npos) return nlohmann::json();
  return nlohmann::json::parse(output.substr(at));
}

std::string join(const std::vector<std::string>& names) {
  std::string text;
  for (const auto& n : names) text += n + " ";
  return text;
}

/// Three frames: 1 and 3 small (2.5 k particles, 1 is where the spacing is measured), 2 with
/// 120 k particles, which under --mem 1M is binned out of core (spill files).
class ConvertInterrupt : public ::testing::Test {
 protected:
  void SetUp() override {
    for (auto [frame, count] : {std::pair{1, "2500"}, std::pair{2, "120k"}, std::pair{3, "2500"}}) {
      CommandRun synth = runFlipscope("synth -o " + (dir / "in_####.bin").string() + " --particles " + count +
                                      " --frames " + std::to_string(frame) + " --seed " + std::to_string(frame));
      ASSERT_EQ(synth.exitCode, 0) << synth.output;
    }
  }

  std::vector<std::string> convertArgs(const fs::path& store) const {
    return {"convert", (dir / "in_####.bin").string(), "-o", store.string(), "--mem", "1M",
            "--resolution", "96", "--brick-size", "32", "-q"};
  }
  std::string convertCommand(const fs::path& store) const {
    std::string command;
    for (const auto& a : convertArgs(store)) command += "'" + a + "' ";
    return command;
  }

  /// Runs convert, stopped by `stop` ("" for none); returns the wait status.
  int convertStopped(const fs::path& store, const std::string& stop) {
    return waitFor(start(convertArgs(store), stop, dir / "log"));
  }

  /// Frames `info --json --verify` lists; exit code in `code`.
  std::vector<int> verifiedFrames(const fs::path& store, int& code, std::string& output) {
    CommandRun info = runFlipscope("info --json --verify '" + store.string() + "'");
    code = info.exitCode;
    output = info.output;
    std::vector<int> frames;
    if (code != 0) return frames;
    const nlohmann::json j = parseJson(info.output);
    for (const auto& f : j["frames"]) frames.push_back(f["frame"].get<int>());
    return frames;
  }

  /// The checks after `signal` stopped a convert into `store` (`existed`: it held frames 1-3
  /// before): what is left, then the next convert.
  void checkAfter(int signal, const fs::path& store, bool existed, const std::string& what) {
    SCOPED_TRACE(what);
    const std::vector<std::string> names = namesIn(store);
    std::vector<std::string> stale;
    for (const auto& n : names)
      if (isStale(n)) stale.push_back(n);
    int code = 0;
    std::string output;
    const std::vector<int> frames = verifiedFrames(store, code, output);
    std::set<std::string> frameFiles;
    for (int f : frames) frameFiles.insert("frame_00000" + std::to_string(f) + ".fsf");

    if (signal == SIGINT) {
      EXPECT_TRUE(stale.empty()) << "left after SIGINT: " << join(stale);
      if (!existed && !fs::exists(store)) {
        // Stopped before the first frame: nothing at all is left.
      } else {
        EXPECT_EQ(code, 0) << output;
        EXPECT_FALSE(frames.empty()) << "a store without frames after SIGINT: " << join(names);
        for (const auto& n : names)
          if (n.rfind("frame_", 0) == 0) {
            EXPECT_TRUE(frameFiles.count(n)) << n << " left but not listed";
          }
      }
    } else if (!fs::exists(store / "store.fsh")) {
      EXPECT_FALSE(existed);
      CommandRun info = runFlipscope("info '" + store.string() + "'");
      EXPECT_EQ(info.exitCode, 3) << info.output;
    } else if (code != 0) {
      // No frame yet: incomplete, exit 3 for info, 1 for --verify.
      EXPECT_FALSE(existed) << output;
      EXPECT_EQ(code, 1) << output;
      EXPECT_NE(output.find("incomplete store: no frames"), std::string::npos) << output;
      CommandRun info = runFlipscope("info '" + store.string() + "'");
      EXPECT_EQ(info.exitCode, 3) << info.output;
      EXPECT_NE(info.output.find("store.fsh: incomplete store"), std::string::npos) << info.output;
    } else {
      EXPECT_FALSE(frames.empty());
      for (int f : frames) EXPECT_TRUE(f >= 1 && f <= 3) << f;
    }
    if (existed) {
      EXPECT_EQ(frames, (std::vector<int>{1, 2, 3})) << "a frame was lost: " << output;
    }

    // The next convert removes what is stale, and finishes the store.
    CommandRun next = runFlipscope(convertCommand(store));
    ASSERT_EQ(next.exitCode, 0) << next.output;
    if (!stale.empty()) {
      EXPECT_NE(next.output.find("removed"), std::string::npos) << join(stale) << next.output;
    }
    const std::vector<std::string> after = namesIn(store);
    EXPECT_EQ(after, (std::vector<std::string>{"frame_000001.fsf", "frame_000002.fsf", "frame_000003.fsf",
                                               "store.fsh", "store.lock"}))
        << join(after);
    EXPECT_EQ(verifiedFrames(store, code, output), (std::vector<int>{1, 2, 3})) << output;
    EXPECT_EQ(code, 0) << output;
  }

  /// Bricks of frame 1 (to place a stop inside frame 2).
  int bricksOfFrame1() {
    const fs::path store = dir / "probe";
    EXPECT_EQ(convertStopped(store, ""), 0);
    CommandRun info = runFlipscope("info --json '" + store.string() + "'");
    const auto j = parseJson(info.output);
    return j["frames"][0]["bricks"].get<int>();
  }

  void stopEverywhere(int signal) {
    const std::string name = signal == SIGINT ? "INT" : "KILL";
    const int bricks1 = bricksOfFrame1();
    ASSERT_GT(bricks1, 2);
    // Each a different state: the lock file being created; the directory alone; store.fsh
    // without frames; frame 1 being read; its temporary being written; committed but not listed;
    // listed; frame 2 read in core; spill files written; frame 2's temporary written while its
    // spill files exist; committed but not listed; the last frame listed.
    const std::vector<std::string> points = {"lock:1",
                                             "directory:1",
                                             "header:1",
                                             "chunk:1",
                                             "brick:2",
                                             "frame-file:1",
                                             "frame:1",
                                             "chunk:12",
                                             "spill:1",
                                             "spill:7",
                                             "brick:" + std::to_string(bricks1 + 2),
                                             "frame-file:2",
                                             "frame:3"};
    int index = 0;
    for (const auto& point : points) {
      const fs::path store = dir / ("s" + std::to_string(index++));
      const int status = convertStopped(store, point + ":" + name);
      ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal)
          << point << ": not stopped there (status " << status << ") " << readText(dir / "log");
      checkAfter(signal, store, false, point + " " + name);
    }
    // Into a store that holds the frames already: converting them again never loses one.
    for (const std::string point : {"header:1", "spill:1", "frame-file:2"}) {
      const fs::path store = dir / ("again" + std::to_string(index++));
      ASSERT_EQ(convertStopped(store, ""), 0) << readText(dir / "log");
      const int status = convertStopped(store, point + ":" + name);
      ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal) << point << " " << readText(dir / "log");
      checkAfter(signal, store, true, "again " + point + " " + name);
    }
  }

  flipscope::testing::TempDir temp{"interrupt"};
  const fs::path& dir = temp.path();
};

TEST_F(ConvertInterrupt, SigkillAtEveryStageLeavesCompleteFramesOrAnIncompleteStore) { stopEverywhere(SIGKILL); }

TEST_F(ConvertInterrupt, SigintAtEveryStageLeavesNoTemporaryOrSpillFile) { stopEverywhere(SIGINT); }

TEST_F(ConvertInterrupt, AnOutOfCoreFramesSpillFilesAreGoneWhenItsFileIsCommitted) {
  // Each bucket's file is removed once read (SpillBuckets::remove): killed the moment frame 2's
  // file is committed, its convert leaves no spill file.
  const fs::path store = dir / "committed";
  const int status = convertStopped(store, "frame-file:2:KILL");
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << readText(dir / "log");
  EXPECT_TRUE(fs::exists(store / "frame_000002.fsf"));
  for (const auto& name : namesIn(store)) EXPECT_NE(name.rfind(".flipscope-spill-", 0), 0u) << name;
}

TEST_F(ConvertInterrupt, SignalsAfterIncreasingDelays) {
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(convertStopped(dir / "timing", ""), 0) << readText(dir / "log");
  const double full = flipscope::secondsSince(t0);
  int killed = 0;
  for (int i = 1; i <= 6; ++i) {
    const int signal = i % 2 ? SIGKILL : SIGINT;
    const fs::path store = dir / ("d" + std::to_string(i));
    const pid_t pid = start(convertArgs(store), "", dir / "log");
    std::this_thread::sleep_for(std::chrono::duration<double>(full * i / 7));
    ::kill(pid, signal);
    const int status = waitFor(pid);
    if (WIFSIGNALED(status)) {
      ++killed;
      EXPECT_EQ(WTERMSIG(status), signal);
      checkAfter(signal, store, false, "after " + std::to_string(full * i / 7) + " s");
    } else {
      EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;  // finished first
      checkAfter(SIGINT, store, false, "finished");
    }
  }
  EXPECT_GT(killed, 0) << "every convert finished before its signal";
}

// ---- integrity as `info` reports it ------------------------------------------------------

class StoreIntegrityCli : public ::testing::Test {
 protected:
  void SetUp() override {
    CommandRun synth = runFlipscope("synth -o " + path("f_####.bin") + " --particles 2k --frames 1-4");
    ASSERT_EQ(synth.exitCode, 0) << synth.output;
  }
  std::string path(const std::string& name) const { return (dir / name).string(); }
  void convert(const std::string& store, const std::string& extra = "") {
    CommandRun c =
        runFlipscope("convert " + path("f_####.bin") + " -o " + path(store) + " --resolution 64 -q " + extra);
    ASSERT_EQ(c.exitCode, 0) << c.output;
  }
  flipscope::testing::TempDir temp{"integrity"};
  const fs::path& dir = temp.path();
};

TEST_F(StoreIntegrityCli, DeletedFramesAreEachReported) {
  convert("s");
  fs::remove(dir / "s" / "frame_000002.fsf");
  fs::remove(dir / "s" / "frame_000003.fsf");
  CommandRun info = runFlipscope("info " + path("s"));
  EXPECT_EQ(info.exitCode, 3) << info.output;
  EXPECT_NE(info.output.find("frame_000002.fsf: missing: store.fsh lists frame 2"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("and 1 more listed frame(s) missing"), std::string::npos) << info.output;
  CommandRun verify = runFlipscope("info --verify " + path("s"));
  EXPECT_EQ(verify.exitCode, 1) << verify.output;
  EXPECT_NE(verify.output.find("damaged: " + path("s/frame_000002.fsf") + ": missing"), std::string::npos)
      << verify.output;
  EXPECT_NE(verify.output.find("damaged: " + path("s/frame_000003.fsf") + ": missing"), std::string::npos)
      << verify.output;
  EXPECT_NE(verify.output.find("2 damaged or missing"), std::string::npos) << verify.output;
  CommandRun json = runFlipscope("info --json --verify " + path("s"));
  EXPECT_EQ(json.exitCode, 1);
  const auto j = parseJson(json.output);
  EXPECT_EQ(j["frames_missing"], nlohmann::json::array({2, 3}));
  EXPECT_FALSE(j["verified"].get<bool>());
  EXPECT_EQ(j["frames"].size(), 2u);
  // Converting the frames again mends it.
  convert("s");
  EXPECT_EQ(runFlipscope("info --verify " + path("s")).exitCode, 0);
}

TEST_F(StoreIntegrityCli, AFrameOfAnotherStoreIsRefusedNamingTheFile) {
  convert("a");
  convert("b");
  const auto idOf = [&](const std::string& store) {
    return parseJson(runFlipscope("info --json " + path(store)).output)["store_id"].get<std::string>();
  };
  const std::string idA = idOf("a"), idB = idOf("b");
  EXPECT_EQ(idA.size(), 32u);
  EXPECT_NE(idA, idB);
  fs::copy_file(dir / "a" / "frame_000002.fsf", dir / "b" / "frame_000002.fsf", fs::copy_options::overwrite_existing);
  CommandRun verify = runFlipscope("info --verify " + path("b"));
  EXPECT_EQ(verify.exitCode, 1) << verify.output;
  EXPECT_NE(verify.output.find(path("b/frame_000002.fsf") + ": belongs to another store (its store id is " + idA +
                               ", this store's is " + idB + ")"),
            std::string::npos)
      << verify.output;
  EXPECT_EQ(runFlipscope("info " + path("b")).exitCode, 3);
  // Another store's store.fsh (same grid) over a's frames: every frame refused.
  fs::copy_file(dir / "b" / "store.fsh", dir / "a" / "store.fsh", fs::copy_options::overwrite_existing);
  CommandRun swapped = runFlipscope("info --verify " + path("a"));
  EXPECT_EQ(swapped.exitCode, 1) << swapped.output;
  EXPECT_NE(swapped.output.find("4 damaged or missing"), std::string::npos) << swapped.output;
}

TEST_F(StoreIntegrityCli, AStoreWithoutFramesIsIncomplete) {
  // SIGKILL right after store.fsh was written: a store without frames.
  const pid_t pid = start({"convert", path("f_####.bin"), "-o", path("s"), "-q"}, "header:1:KILL", dir / "log");
  const int status = waitFor(pid);
  ASSERT_TRUE(WIFSIGNALED(status)) << readText(dir / "log");
  ASSERT_TRUE(fs::exists(dir / "s" / "store.fsh"));
  CommandRun info = runFlipscope("info " + path("s"));
  EXPECT_EQ(info.exitCode, 3) << info.output;
  EXPECT_NE(info.output.find(path("s/store.fsh") + ": incomplete store: no frames"), std::string::npos) << info.output;
  CommandRun verify = runFlipscope("info --verify " + path("s"));
  EXPECT_EQ(verify.exitCode, 1) << verify.output;
  EXPECT_NE(verify.output.find("incomplete store"), std::string::npos) << verify.output;
  EXPECT_EQ(verify.output.find("intact"), std::string::npos) << verify.output;
  // The next convert starts it anew, with its own options.
  CommandRun again = runFlipscope("convert " + path("f_####.bin") + " -o " + path("s") + " --resolution 32");
  EXPECT_EQ(again.exitCode, 0) << again.output;
  EXPECT_NE(again.output.find("has no frames"), std::string::npos) << again.output;
  EXPECT_NE(again.output.find("32 cells along the longest axis"), std::string::npos) << again.output;
  EXPECT_EQ(runFlipscope("info --verify " + path("s")).exitCode, 0);
}

TEST_F(StoreIntegrityCli, AFailedConvertLeavesNoStore) {
  CommandRun big = runFlipscope("synth -o " + path("big.bin") + " --particles 200k");
  ASSERT_EQ(big.exitCode, 0) << big.output;
  CommandRun failed =
      runFlipscope("convert " + path("big.bin") + " -o " + path("s") + " --mem 1M --scratch " + path("none/x"));
  EXPECT_EQ(failed.exitCode, 3) << failed.output;
  EXPECT_NE(failed.output.find("spill"), std::string::npos) << failed.output;
  EXPECT_FALSE(fs::exists(dir / "s")) << join(namesIn(dir / "s"));
}

TEST_F(StoreIntegrityCli, AConvertBesideAnotherWriterLeavesItsFilesAlone) {
  convert("s");
  // What a writer may have in the store while it runs: a temporary (its PID, here one that no
  // process has) and a complete frame file not listed yet.
  const fs::path temporary = dir / "s" / ".frame_000009.fsf.tmp-999999999-1";
  std::ofstream(temporary) << "partial";
  fs::copy_file(dir / "s" / "frame_000004.fsf", dir / "s" / "frame_000005.fsf");
  {
    flipscope::StoreWriterLock other(dir / "s");  // as a running convert holds it
    other.share();
    CommandRun beside = runFlipscope("convert " + path("f_####.bin") + " --frames 2 -o " + path("s"));
    EXPECT_EQ(beside.exitCode, 0) << beside.output;
    EXPECT_TRUE(fs::exists(temporary));
    EXPECT_TRUE(fs::exists(dir / "s" / "frame_000005.fsf"));
    EXPECT_EQ(beside.output.find("removed"), std::string::npos) << beside.output;
  }
  // Alone, a convert removes both: their writer is gone.
  CommandRun alone = runFlipscope("convert " + path("f_####.bin") + " --frames 3 -o " + path("s"));
  EXPECT_EQ(alone.exitCode, 0) << alone.output;
  EXPECT_FALSE(fs::exists(temporary));
  EXPECT_FALSE(fs::exists(dir / "s" / "frame_000005.fsf"));
  EXPECT_EQ(runFlipscope("info --verify " + path("s")).exitCode, 0);
}

TEST_F(StoreIntegrityCli, AppendNeedsAStoreAndPrepareMakesOneWithoutFrames) {
  CommandRun append = runFlipscope("convert " + path("f_####.bin") + " -o " + path("s") + " --append");
  EXPECT_EQ(append.exitCode, 3) << append.output;
  EXPECT_NE(append.output.find(path("s") + ": --append: not a brick store"), std::string::npos) << append.output;
  EXPECT_FALSE(fs::exists(dir / "s"));
  CommandRun prepare =
      runFlipscope("convert " + path("f_####.bin") + " -o " + path("s") + " --prepare --resolution 64");
  ASSERT_EQ(prepare.exitCode, 0) << prepare.output;
  EXPECT_NE(prepare.output.find("no frames yet"), std::string::npos) << prepare.output;
  EXPECT_EQ(runFlipscope("info " + path("s")).exitCode, 3);  // incomplete until a frame is added
  // --append joins the prepared store (its id and header) instead of starting it anew.
  const flipscope::StoreId id = flipscope::BrickStore::open(dir / "s").header().id;
  CommandRun first = runFlipscope("convert " + path("f_####.bin") + " --frames 1 -o " + path("s") + " --append");
  ASSERT_EQ(first.exitCode, 0) << first.output;
  EXPECT_EQ(first.output.find("starting it anew"), std::string::npos) << first.output;
  EXPECT_EQ(flipscope::BrickStore::open(dir / "s").header().id, id);
  EXPECT_EQ(runFlipscope("info --verify " + path("s")).exitCode, 0);
}

TEST_F(StoreIntegrityCli, AnOutputPathThatCannotBeCreatedIsNamed) {
  std::ofstream(path("file")) << "x";
  CommandRun c = runFlipscope("convert " + path("f_####.bin") + " -o " + path("file/s") + " -q");
  EXPECT_EQ(c.exitCode, 4) << c.output;  // an output that cannot be created
  EXPECT_NE(c.output.find(path("file/s")), std::string::npos) << c.output;
  EXPECT_EQ(c.output.find("internal error"), std::string::npos) << c.output;
}

}  // namespace
