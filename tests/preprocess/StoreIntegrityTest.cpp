// Store integrity (format version 3): the store id in store.fsh and every frame footer, the
// frame table (missing, unlisted and foreign frames, incomplete stores), old versions, and the
// clean-up of what an interrupted convert leaves (stale temporaries and spill files, signals).
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include "core/AtomicFile.h"
#include "core/Bytes.h"
#include "core/Error.h"
#include "core/Hash.h"
#include "preprocess/store/BrickStore.h"
#include "preprocess/Convert.h"
#include "preprocess/store/FrameFile.h"
#include "preprocess/store/StoreInspection.h"
#include "TestSupport.h"
#include "VectorSource.h"

namespace flipscope {
namespace {

namespace fs = std::filesystem;

/// `what` throws FileError whose message holds every one of `parts`.
template <class Fn>
void expectFileError(Fn&& what, std::initializer_list<std::string> parts) {
  try {
    what();
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& e) {
    for (const auto& part : parts) EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

ConvertOptions smallOptions() {
  ConvertOptions options;
  options.cellSize = 0.25;
  options.brickSize = 32;
  options.progress = Progress::Mode::Silent;
  return options;
}

const Box kDomain{{0, 0, 0}, {20, 20, 20}};

/// A store at `dir` with the given frames, 300 random particles each.
BrickStore makeStore(const fs::path& dir, const std::vector<int>& frames, unsigned seed = 3) {
  const ConvertOptions options = smallOptions();
  BrickStore store = BrickStore::createOrAppend(dir, makeStoreHeader(kDomain, options));
  for (int f : frames) {
    testing::VectorSource source(testing::randomParticles(300, seed + unsigned(f), 20.0f));
    convertFrame(source, store, f, options);
  }
  return store;
}

std::vector<std::string> namesIn(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

void touch(const fs::path& file, std::size_t bytes = 10) { std::ofstream(file) << std::string(bytes, 'x'); }

/// The PID of a process that has ended (forked, exited and reaped).
long deadPid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return long(child);
}

TEST(StoreHeaderV3, RoundTripsTheIdAndTheFrameTableAndRefusesEveryCorruption) {
  StoreHeader h;
  h.version = 3;  // the layout of version 3 (version 4 adds the attribute name and range)
  h.brickSize = 64;
  h.cellSize = 0.5;
  h.brickGrid = {3, 2, 1};
  h.id = randomStoreId();
  const std::vector<int> frames = {0, 1, 2, 3, 7, 9, 10, 500, 999999};
  const auto bytes = serializeStoreHeader(h, frames);
  EXPECT_EQ(bytes.size(), 100u + 8 * 5) << "fixed part, then 8 bytes a run of consecutive frames";
  std::vector<int> back;
  const StoreHeader parsed = parseStoreHeader(bytes, "store.fsh", &back);
  EXPECT_EQ(parsed.version, 3u);
  EXPECT_EQ(parsed.id, h.id);
  EXPECT_EQ(back, frames);
  for (std::size_t n = 0; n < bytes.size(); ++n)
    EXPECT_THROW(parseStoreHeader(std::span(bytes).first(n), "store.fsh"), FileError) << "length " << n;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    auto bad = bytes;
    bad[i] ^= std::byte{0x08};
    EXPECT_THROW(parseStoreHeader(bad, "store.fsh"), FileError) << "byte " << i;
  }
}

/// store.fsh bytes with a hand-made frame table and a valid checksum.
std::vector<std::byte> headerWithRuns(const std::vector<std::pair<std::int32_t, std::uint32_t>>& runs) {
  StoreHeader h;
  h.cellSize = 1;
  h.brickGrid = {1, 1, 1};
  auto bytes = serializeStoreHeader(h);  // no runs: the count is the last field before the checksum
  bytes.resize(bytes.size() - 12);
  ByteWriter w;
  w.append(bytes.data(), bytes.size());
  w.put(std::uint32_t(runs.size()));
  for (auto [first, count] : runs) {
    w.put(first);
    w.put(count);
  }
  w.put(checksum64(w.view()));
  return std::move(w.bytes());
}

TEST(StoreHeaderV3, RefusesAFrameTableThatIsNotAscendingRuns) {
  std::vector<int> frames;
  parseStoreHeader(headerWithRuns({{0, 3}, {5, 1}}), "store.fsh", &frames);
  EXPECT_EQ(frames, (std::vector<int>{0, 1, 2, 5}));
  for (auto runs : std::vector<std::vector<std::pair<std::int32_t, std::uint32_t>>>{
           {{5, 1}, {0, 3}},         // descending
           {{0, 3}, {3, 1}},         // adjacent: one run
           {{0, 3}, {2, 4}},         // overlapping
           {{0, 0}},                 // empty
           {{-1, 2}},                // negative frame
           {{999999, 2}},            // past kMaxFrame
           {{0, 0xffffffffu}}})      // 4 G frames
    expectFileError([&] { parseStoreHeader(headerWithRuns(runs), "s/store.fsh"); }, {"s/store.fsh", "frame table run"});
  // A run count larger than the file: refused before anything is allocated.
  auto bytes = headerWithRuns({{0, 1}});
  std::uint32_t huge = 0x7fffffff;
  std::memcpy(bytes.data() + 96, &huge, 4);
  EXPECT_THROW(parseStoreHeader(bytes, "store.fsh"), FileError);
}

TEST(StoreHeaderV3, VersionTwoStoresAndFramesAreRefusedAskingToConvertAgain) {
  // store.fsh as version 2 wrote it: no id and no frame table (80 bytes).
  ByteWriter w;
  w.append("FSSTORE1", 8);
  w.put(std::uint32_t(2));
  w.put(std::uint32_t(32));
  w.put(0.25);
  for (double o : {0.0, 0.0, 0.0}) w.put(o);
  for (std::uint32_t g : {3u, 3u, 3u}) w.put(g);
  w.put(std::uint32_t(0));
  w.put(0.0);
  w.put(checksum64(w.view()));
  ASSERT_EQ(w.size(), 80u);
  expectFileError(
      [&] { parseStoreHeader(w.view(), "old/store.fsh"); },
      {"old/store.fsh", "unsupported store version 2", "reads versions 3 to " + std::to_string(kStoreVersion),
       "convert the particle files again"});

  // A version 2 frame file (88-byte footer, version 24 bytes before the end) is named as one.
  testing::TempDir temp("v2-frame");
  BrickStore store = makeStore(temp / "s", {1});
  auto frame = readFile(store.framePath(1));
  const std::uint32_t two = 2;
  std::memcpy(frame.data() + frame.size() - 24, &two, 4);
  const fs::path old = temp / "s" / "frame_000002.fsf";
  std::ofstream(old, std::ios::binary)
      .write(reinterpret_cast<const char*>(frame.data()), std::streamsize(frame.size()));
  expectFileError([&] { readFrameIndex(old, store.header()); },
                  {"frame_000002.fsf", "unsupported frame version 2", "convert the particle files again"});
}

TEST(StoreIdentity, EachStoreGetsItsOwnIdAndEveryFrameCarriesIt) {
  testing::TempDir temp("identity");
  BrickStore a = makeStore(temp / "a", {1, 2});
  BrickStore b = makeStore(temp / "b", {1});
  EXPECT_NE(a.header().id, StoreId{});
  EXPECT_NE(a.header().id, b.header().id);
  EXPECT_EQ(BrickStore::open(temp / "a").header().id, a.header().id);
  const auto frame = readFile(a.framePath(2));
  const std::size_t idAt = frame.size() - 40;  // the footer: ... store id, version, reserved, checksum, magic
  EXPECT_EQ(std::memcmp(frame.data() + idAt, a.header().id.data(), 16), 0);

  // A frame file of store a copied into store b under a frame b lists: refused, naming the file.
  fs::copy_file(a.framePath(2), b.framePath(1), fs::copy_options::overwrite_existing);
  BrickStore reopened = BrickStore::open(temp / "b");
  expectFileError([&] { reopened.frame(1); }, {(temp / "b" / "frame_000001.fsf").string(), "another store",
                                                storeIdText(a.header().id), storeIdText(b.header().id)});
  // And another store's store.fsh over a's frames (same grid): a's frames are refused.
  fs::copy_file(temp / "b" / kStoreHeaderName, temp / "a" / kStoreHeaderName, fs::copy_options::overwrite_existing);
  BrickStore swapped = BrickStore::open(temp / "a");
  expectFileError([&] { swapped.frame(1); }, {"frame_000001.fsf", "another store"});
}

TEST(FrameTable, ADeletedMiddleFrameIsMissingAndNamed) {
  testing::TempDir temp("missing");
  const fs::path dir = temp / "s";
  makeStore(dir, {1, 2, 3, 4, 5});
  fs::remove(dir / "frame_000003.fsf");
  fs::remove(dir / "frame_000004.fsf");
  fs::create_directory(dir / "frame_000004.fsf");  // something else in its place
  BrickStore store = BrickStore::open(dir);
  EXPECT_EQ(store.frames(), (std::vector<int>{1, 2, 3, 4, 5})) << "the table, not the directory";
  EXPECT_EQ(store.missingFrames(), (std::vector<int>{3, 4}));
  expectFileError([&] { store.frame(3); }, {"frame_000003.fsf", "missing", "lists frame 3", "its file is gone"});
  expectFileError([&] { store.frame(4); },
                  {"frame_000004.fsf", "missing", "lists frame 4", "a directory has its name"});
  EXPECT_NO_THROW(store.frame(2));
  EXPECT_EQ(store.missingFrameReason(2), "");
  const auto problems = checkFrameTable(store);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_NE(problems[0].find("frame_000003.fsf: missing"), std::string::npos) << problems[0];
  EXPECT_NE(problems[1].find("frame_000004.fsf: missing: store.fsh lists frame 4, but a directory has its name"),
            std::string::npos)
      << problems[1];
}

TEST(FrameTable, AStoreWithoutFramesIsIncompleteAndTheNextStoreReplacesIt) {
  testing::TempDir temp("incomplete");
  const fs::path dir = temp / "s";
  BrickStore empty = BrickStore::createOrAppend(dir, makeStoreHeader(kDomain, smallOptions()));
  EXPECT_TRUE(BrickStore::open(dir).incomplete());
  const auto problems = checkFrameTable(BrickStore::open(dir));
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("store.fsh: incomplete store: no frames"), std::string::npos) << problems[0];

  // Another domain is no conflict for a store without frames: it starts anew, with a new id.
  ConvertOptions other = smallOptions();
  other.cellSize = 0.5;
  BrickStore fresh = BrickStore::createOrAppend(dir, makeStoreHeader(kDomain, other));
  EXPECT_EQ(fresh.header().cellSize, 0.5);
  EXPECT_NE(fresh.header().id, empty.header().id);
  // Once it has a frame, it keeps its header.
  testing::VectorSource source(testing::randomParticles(100, 1, 20.0f));
  convertFrame(source, fresh, 0, other);
  EXPECT_FALSE(BrickStore::open(dir).incomplete());
  EXPECT_THROW(BrickStore::createOrAppend(dir, makeStoreHeader(kDomain, smallOptions())), FileError);
}

TEST(FrameTable, AFrameFileTheTableDoesNotListIsNotPartOfTheStore) {
  testing::TempDir temp("unlisted");
  const fs::path dir = temp / "s";
  BrickStore store = makeStore(dir, {1});
  {  // frame 2 written but never listed: a convert killed between the two renames
    FrameWriter writer(store.framePath(2), store.header(), 2);
    writer.finish({});
  }
  BrickStore reopened = BrickStore::open(dir);
  EXPECT_EQ(reopened.frames(), std::vector<int>{1});
  EXPECT_FALSE(reopened.hasFrame(2));
  EXPECT_THROW(reopened.frame(2), InputError);
  EXPECT_EQ(reopened.unlistedFrameFiles(), std::vector<fs::path>{dir / "frame_000002.fsf"});
  EXPECT_TRUE(checkFrameTable(reopened).empty());
}

TEST(FrameTable, ListingAFrameRewritesTheTableOnceAndOpenReadsNoDirectory) {
  testing::TempDir temp("table");
  const fs::path dir = temp / "s";
  BrickStore store = makeStore(dir, {4, 5, 9});
  std::vector<int> frames;
  parseStoreHeader(readFile(dir / kStoreHeaderName), dir / kStoreHeaderName, &frames);
  EXPECT_EQ(frames, (std::vector<int>{4, 5, 9}));
  // Converting a listed frame again replaces its file and leaves the table as it is.
  const auto before = readFile(dir / kStoreHeaderName);
  testing::VectorSource source(testing::randomParticles(50, 8, 20.0f));
  convertFrame(source, store, 5, smallOptions());
  EXPECT_EQ(readFile(dir / kStoreHeaderName), before);
  EXPECT_EQ(BrickStore::open(dir).frame(5)->stats.particles, 50u);
  EXPECT_EQ(namesIn(dir), (std::vector<std::string>{"frame_000004.fsf", "frame_000005.fsf", "frame_000009.fsf",
                                                    "store.fsh", "store.lock"}));
}

TEST(StaleFiles, TemporaryNamesCarryTheWritersPid) {
  EXPECT_EQ(temporaryFileOwner(".frame_000001.fsf.tmp-1234-0"), 1234);
  EXPECT_EQ(temporaryFileOwner(".store.fsh.tmp-77-12"), 77);
  EXPECT_EQ(temporaryFileOwner("frame_000001.fsf"), std::nullopt);
  EXPECT_EQ(temporaryFileOwner(".x.tmp-12"), std::nullopt);
  EXPECT_EQ(temporaryFileOwner(".x.tmp--3"), std::nullopt);
  EXPECT_EQ(temporaryFileOwner(".x.tmp-1a-3"), std::nullopt);
  EXPECT_EQ(temporaryFileOwner(".x.tmp-0-3"), std::nullopt);
  EXPECT_TRUE(processExists(long(::getpid())));
  EXPECT_FALSE(processExists(deadPid()));
  testing::TempDir temp("tmpname");
  AtomicFile file(temp / "frame_000003.fsf");
  EXPECT_EQ(temporaryFileOwner(file.temporaryPath().filename().string()), long(::getpid()));
}

/// RLIMIT_FSIZE at `bytes`, with SIGXFSZ ignored, for its lifetime: a write past it fails with
/// EFBIG (File too large), as a full disk fails one with ENOSPC.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &mSaved);
    struct sigaction ignore {};
    ignore.sa_handler = SIG_IGN;
    ::sigaction(SIGXFSZ, &ignore, &mSavedAction);
    rlimit limit = mSaved;
    limit.rlim_cur = bytes;
    mSet = ::setrlimit(RLIMIT_FSIZE, &limit) == 0;
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &mSaved);
    ::sigaction(SIGXFSZ, &mSavedAction, nullptr);
  }
  bool set() const { return mSet; }

 private:
  rlimit mSaved{};
  struct sigaction mSavedAction {};
  bool mSet = false;
};

TEST(AtomicFile, AFailedWriteNamesTheDestinationAndItsTemporaryAndLeavesNeither) {
  testing::TempDir temp("atomicfull");
  const std::vector<std::byte> bytes(std::size_t(3) << 20, std::byte{7});
  writeFileAtomically(temp / "kept.bin", std::span(bytes).first(100));
  for (const bool large : {false, true}) {  // fails in commit's flush, or in a write past the buffer
    SCOPED_TRACE(large ? "write" : "flush");
    // Nothing is checked while the limit holds: gtest's own output could meet it.
    std::string message;
    fs::path named;
    bool limited = false;
    {
      AtomicFile file(temp / "out.bin");
      const FileSizeLimit limit(64);
      limited = limit.set();
      try {
        file.write(bytes.data(), large ? bytes.size() : 1000);  // 1000: within the buffer
        file.commit();
      } catch (const OutputError& e) {
        named = e.path();
        message = e.what();
      }
    }
    ASSERT_TRUE(limited);
    EXPECT_EQ(named, temp / "out.bin");
    EXPECT_NE(message.find("out.bin: cannot be written: " + std::string(large ? "write" : "flush") +
                           " of its temporary .out.bin.tmp-"),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("File too large"), std::string::npos) << message;
    // Neither the destination nor a temporary is left, and the other file is whole.
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(temp.path())) names.push_back(entry.path().filename().string());
    EXPECT_EQ(names, std::vector<std::string>{"kept.bin"});
    EXPECT_EQ(fs::file_size(temp / "kept.bin"), 100u);
  }
}

TEST(AtomicFile, SmallWritesAreGatheredInItsBufferUntilCommit) {
  testing::TempDir temp("atomicbuffer");
  AtomicFile file(temp / "out.bin");
  const std::vector<std::byte> piece(1000, std::byte{3});
  const std::size_t pieces = kAtomicFileBufferBytes / piece.size() - 1;  // 1 MiB: far beyond 4 KiB
  for (std::size_t i = 0; i < pieces; ++i) file.write(piece.data(), piece.size());
  EXPECT_EQ(fs::file_size(file.temporaryPath()), 0u);  // nothing written yet: one write at commit
  file.commit();
  EXPECT_EQ(fs::file_size(temp / "out.bin"), pieces * piece.size());
}

TEST(AtomicFile, ItsBytesGoToTheKernelEachWritebackStepAndAFieldWrittenBackBeforeIsRewritten) {
  testing::TempDir temp("atomicwriteback");
  std::vector<std::byte> expected;
  {
    AtomicFile file(temp / "out.bin");
    std::vector<std::byte> piece(1000003);
    for (int p = 0; p < 7; ++p) {
      for (std::size_t i = 0; i < piece.size(); ++i) piece[i] = std::byte((i * 7 + std::size_t(p) * 13) & 0xff);
      file.write(piece.data(), piece.size());
      expected.insert(expected.end(), piece.begin(), piece.end());
      if (p == 2) {
        // The first step was crossed by this write: everything so far is flushed, for its writeback.
        ASSERT_GE(file.offset(), kAtomicFileWritebackBytes);
        EXPECT_EQ(fs::file_size(file.temporaryPath()), file.offset());
      }
    }
    ASSERT_GT(file.offset(), 3 * kAtomicFileWritebackBytes);
    const std::uint32_t field = 0xfeedf00d;  // a header field, written back long ago
    file.writeAt(16, &field, sizeof field);
    std::memcpy(expected.data() + 16, &field, sizeof field);
    file.commit();
  }
  EXPECT_EQ(readFile(temp / "out.bin"), expected);
}

TEST(StaleFiles, OnlyFilesOfProcessesThatAreGoneAreRemoved) {
  testing::TempDir temp("stale");
  const fs::path dir = temp.path();
  const std::string dead = std::to_string(deadPid()), live = std::to_string(long(::getppid()));
  const std::string self = std::to_string(long(::getpid()));
  const std::vector<std::string> gone = {".frame_000001.fsf.tmp-" + dead + "-0", ".store.fsh.tmp-" + dead + "-3",
                                         ".flipscope-spill-" + dead + "-1-0", ".flipscope-spill-" + dead + "-1-4-1"};
  const std::vector<std::string> kept = {".frame_000001.fsf.tmp-" + live + "-0", ".flipscope-spill-" + live + "-2-1",
                                         ".flipscope-spill-" + self + "-2-1", ".store.fsh.tmp-" + self + "-0",
                                         "notes.txt", ".spill-notes", "frame_000001.fsf"};
  for (const auto& n : gone) touch(dir / n, 100);
  for (const auto& n : kept) touch(dir / n);
  // A scratch directory: spill files only.
  StaleFiles scratch = removeStaleFiles(dir, false);
  EXPECT_EQ(scratch.files, 2u);
  EXPECT_TRUE(fs::exists(dir / gone[0]));
  StaleFiles store = removeStaleFiles(dir, true);
  EXPECT_EQ(store.files, 2u);
  EXPECT_EQ(store.bytes, 200u);
  std::vector<std::string> expected = kept;
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(namesIn(dir), expected);
}

/// Forks; the child runs `body` then raises `signal`. Returns the child's wait status.
template <class Fn>
int inChildRaising(int signal, Fn&& body) {
  const pid_t child = ::fork();
  if (child == 0) {
    installCleanupSignalHandlers();
    body();
    ::raise(signal);
    ::_exit(99);  // not reached: the handler ends the process by the signal
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  return status;
}

TEST(CleanupOnSignal, SigintSigtermAndSighupRemoveTheRegisteredPathsThenEndTheProcess) {
  for (int signal : {SIGINT, SIGTERM, SIGHUP}) {
    testing::TempDir temp("signal");
    const fs::path dir = temp / "made";
    const int status = inChildRaising(signal, [&] {
      static CleanupOnSignal registered[6];
      fs::create_directories(dir);
      registered[0] = CleanupOnSignal(dir, CleanupOnSignal::Kind::Directory);
      touch(dir / "a");
      registered[1] = CleanupOnSignal(dir / "a");
      // A directory inside one registered before it: both go.
      fs::create_directories(dir / "inner");
      registered[4] = CleanupOnSignal(dir / "inner", CleanupOnSignal::Kind::Directory);
      touch(dir / "inner" / "e");
      registered[5] = CleanupOnSignal(dir / "inner" / "e");
      touch(temp / "b");
      registered[2] = CleanupOnSignal(temp / "b");
      touch(temp / "c");
      registered[3] = CleanupOnSignal(temp / "c");
      registered[3].release();  // c is kept
      static AtomicFile* pending = new AtomicFile(temp / "d");  // its temporary goes too
      pending->write("x", 1);
    });
    ASSERT_TRUE(WIFSIGNALED(status)) << "signal " << signal << ", status " << status;
    EXPECT_EQ(WTERMSIG(status), signal);
    EXPECT_EQ(namesIn(temp.path()), std::vector<std::string>{"c"}) << "signal " << signal;
  }
}

TEST(CleanupOnSignal, TheHandlerWaitsForAStepOnAnotherThread) {
  // A thread commits inside a step (renames its registered temporary, then releases it) while
  // SIGINT arrives on the main thread: the handler waits, so the committed file stays.
  testing::TempDir temp("step");
  const fs::path pending = temp / "pending", committed = temp / "committed";
  const pid_t child = ::fork();
  if (child == 0) {
    installCleanupSignalHandlers();
    std::atomic<bool> inStep{false};
    std::thread writer([&] {
      const DeferCleanupSignals step;
      CleanupOnSignal registration(pending);
      touch(pending);
      inStep = true;
      ::usleep(200'000);
      fs::rename(pending, committed);
      registration.release();
    });
    while (!inStep) ::usleep(1000);
    ::raise(SIGINT);  // handled on this thread, during the writer's step
    ::_exit(99);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << status;
  EXPECT_EQ(WTERMSIG(status), SIGINT);
  EXPECT_EQ(namesIn(temp.path()), std::vector<std::string>{"committed"});
}

TEST(CleanupOnSignal, AnIgnoredSignalStaysIgnoredAndReleasedSlotsAreReused) {
  for (int i = 0; i < 3 * CleanupOnSignal::kCleanupSlots; ++i) {
    CleanupOnSignal slot("/nonexistent/" + std::to_string(i));
    ASSERT_TRUE(slot.registered()) << i;
  }
  std::vector<CleanupOnSignal> all;
  for (int i = 0; i < CleanupOnSignal::kCleanupSlots + 5; ++i) all.emplace_back("/nonexistent/x");
  int registered = 0;
  for (const auto& s : all) registered += s.registered();
  EXPECT_LE(registered, CleanupOnSignal::kCleanupSlots);
  EXPECT_GE(registered, CleanupOnSignal::kCleanupSlots - 16);  // other tests may hold a few
  all.clear();

  const pid_t child = ::fork();
  if (child == 0) {
    ::signal(SIGHUP, SIG_IGN);  // as under nohup
    installCleanupSignalHandlers();
    ::raise(SIGHUP);
    ::_exit(7);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 7);
}

TEST(ConvertCleanup, AConvertRemovesTheStaleFilesAndUnlistedFramesOfAKilledOne) {
  testing::TempDir temp("convert-stale");
  const fs::path dir = temp / "s";
  BrickStore store = makeStore(dir, {1});
  {
    FrameWriter writer(store.framePath(2), store.header(), 2);  // never listed
    writer.finish({});
  }
  const std::string dead = std::to_string(deadPid());
  touch(dir / (".frame_000003.fsf.tmp-" + dead + "-0"), 1000);
  touch(dir / (".flipscope-spill-" + dead + "-3-1"), 1000);
  const fs::path scratch = temp / "scratch";
  fs::create_directories(scratch);
  touch(scratch / (".flipscope-spill-" + dead + "-3-0"), 1000);
  // A frame file of another store that the table does not list is left alone, with a warning.
  BrickStore other = makeStore(temp / "other", {7});
  fs::copy_file(other.framePath(7), dir / "frame_000007.fsf");

  // Input: one raw float32 file as frame 4.
  const fs::path input = temp / "p.bin";
  {
    auto particles = testing::randomParticles(200, 9, 20.0f);
    std::ofstream(input, std::ios::binary)
        .write(reinterpret_cast<const char*>(particles.data()), std::streamsize(particles.size() * 12));
  }
  ConvertOptions options = smallOptions();
  options.scratchDir = scratch;
  const ConvertReport report = convert({FrameInput{4, {input}}}, dir, options);
  std::string warnings;
  for (const auto& w : report.warnings) warnings += w + "\n";
  EXPECT_NE(warnings.find("removed 2 stale temporary or spill file(s)"), std::string::npos) << warnings;
  EXPECT_NE(warnings.find("removed 1 stale temporary or spill file(s)"), std::string::npos) << warnings;
  EXPECT_NE(warnings.find("frame files never listed"), std::string::npos) << warnings;
  EXPECT_NE(warnings.find("frame_000007.fsf: not in the store's frame table"), std::string::npos) << warnings;
  EXPECT_EQ(namesIn(dir), (std::vector<std::string>{"frame_000001.fsf", "frame_000004.fsf", "frame_000007.fsf",
                                                    "store.fsh", "store.lock"}));
  EXPECT_TRUE(fs::is_empty(scratch));
  EXPECT_EQ(BrickStore::open(dir).frames(), (std::vector<int>{1, 4}));
}

TEST(ConvertCleanup, AFailedConvertLeavesNoStoreBehind) {
  testing::TempDir temp("convert-failed");
  const fs::path input = temp / "p.bin";
  {
    auto particles = testing::randomParticles(100000, 2, 20.0f);
    std::ofstream(input, std::ios::binary)
        .write(reinterpret_cast<const char*>(particles.data()), std::streamsize(particles.size() * 12));
  }
  ConvertOptions options = smallOptions();
  options.memoryBudget = 1 << 20;                // spills
  options.scratchDir = temp / "no" / "such" / "dir";  // and cannot
  expectFileError([&] { convert({FrameInput{0, {input}}}, temp / "store", options); }, {"spill"});
  EXPECT_FALSE(fs::exists(temp / "store"));
  // Into an existing directory: the directory stays, store.fsh goes.
  fs::create_directories(temp / "mine");
  EXPECT_THROW(convert({FrameInput{0, {input}}}, temp / "mine", options), FileError);
  EXPECT_TRUE(fs::is_empty(temp / "mine"));
  // A store with frames keeps them: the failed frame is not listed.
  options.scratchDir.clear();
  convert({FrameInput{0, {input}}}, temp / "kept", options);
  options.scratchDir = temp / "no" / "such" / "dir";
  EXPECT_THROW(convert({FrameInput{1, {input}}}, temp / "kept", options), FileError);
  EXPECT_EQ(namesIn(temp / "kept"), (std::vector<std::string>{"frame_000000.fsf", "store.fsh", "store.lock"}));
  EXPECT_EQ(BrickStore::open(temp / "kept").frames(), std::vector<int>{0});
}

TEST(ConvertCleanup, FrameNumbersBeyondTheFileNamesAreRefused) {
  testing::TempDir temp("frame-range");
  touch(temp / "p.bin", 12);
  EXPECT_THROW(convert({FrameInput{1000000, {temp / "p.bin"}}}, temp / "s", smallOptions()), InputError);
  EXPECT_FALSE(fs::exists(temp / "s"));
}

}  // namespace
}  // namespace flipscope
