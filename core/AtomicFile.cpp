#include "core/AtomicFile.h"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/types.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>
#include <thread>

#include "core/Error.h"

namespace flipscope {
namespace {
std::atomic<unsigned> gTemporaryCounter{0};

// ---- the registry of CleanupOnSignal ------------------------------------------------------
// A slot holds a heap string: 'f' or 'd' (file or directory), then the path, NUL-terminated.
// The handler marks a slot as being read (readers), then loads the string; release() clears
// the slot first and frees the string only when no handler reads it (the hazard pointer
// pattern), so the handler never touches freed memory. All atomics are lock-free.
struct Slot {
  std::atomic<char*> path{nullptr};
  std::atomic<int> readers{0};
};
static_assert(std::atomic<char*>::is_always_lock_free && std::atomic<int>::is_always_lock_free);
Slot gSlots[CleanupOnSignal::kCleanupSlots];
std::atomic<int> gNextSlot{0};  ///< where the search for a free slot starts

/// DeferCleanupSignals sections open, and whether a handler cleans up (Dekker-style: each side
/// announces itself, then checks the other; all seq_cst).
std::atomic<int> gDeferring{0};
std::atomic<bool> gCleaning{false};

void sleepBriefly() {
  const timespec pause{0, 1'000'000};  // 1 ms; nanosleep is async-signal-safe
  ::nanosleep(&pause, nullptr);
}

/// Async-signal-safe: unlinks every registered file, then rmdirs every registered directory,
/// twice: a directory in an earlier slot than a registered one inside it is empty only on the
/// second pass.
void removeRegistered() {
  for (char kind : {'f', 'd', 'd'}) {
    for (Slot& slot : gSlots) {
      slot.readers.fetch_add(1);
      if (const char* entry = slot.path.load(); entry && entry[0] == kind) {
        if (kind == 'f')
          ::unlink(entry + 1);
        else
          ::rmdir(entry + 1);
      }
      slot.readers.fetch_sub(1);
    }
  }
}

constexpr int kCleanupSignals[] = {SIGINT, SIGTERM, SIGHUP};

void cleanupSignalSet(sigset_t& set) {
  sigemptyset(&set);
  for (int s : kCleanupSignals) sigaddset(&set, s);
}

void onCleanupSignal(int signal) {
  const int savedErrno = errno;
  gCleaning.store(true);
  // A step on another thread finishes first; bounded, in case that thread waits on this one.
  for (int waited = 0; gDeferring.load() > 0 && waited < 5000; ++waited) sleepBriefly();
  removeRegistered();
  // SA_RESETHAND restored the default action; the signal is blocked until the handler returns,
  // so the process ends by it right after.
  ::raise(signal);
  errno = savedErrno;
}
}  // namespace

CleanupOnSignal::CleanupOnSignal(const std::filesystem::path& path, Kind kind) {
  const std::string& text = path.native();
  char* entry = new char[text.size() + 2];
  entry[0] = kind == Kind::File ? 'f' : 'd';
  std::memcpy(entry + 1, text.c_str(), text.size() + 1);
  const int start = gNextSlot.load();
  for (int i = 0; i < kCleanupSlots; ++i) {
    const int s = (start + i) % kCleanupSlots;
    char* expected = nullptr;
    if (gSlots[s].path.compare_exchange_strong(expected, entry)) {
      mSlot = s;
      gNextSlot.store((s + 1) % kCleanupSlots);
      return;
    }
  }
  delete[] entry;  // every slot taken: not registered
}

CleanupOnSignal& CleanupOnSignal::operator=(CleanupOnSignal&& other) noexcept {
  if (this != &other) {
    release();
    mSlot = other.mSlot;
    other.mSlot = -1;
  }
  return *this;
}

void CleanupOnSignal::release() noexcept {
  if (mSlot < 0) return;
  Slot& slot = gSlots[mSlot];
  char* entry = slot.path.exchange(nullptr);
  while (slot.readers.load() != 0) std::this_thread::yield();  // a handler is reading it
  delete[] entry;
  mSlot = -1;
}

thread_local int tStepDepth = 0;

DeferCleanupSignals::DeferCleanupSignals() {
  if (tStepDepth++ > 0) return;  // inside a step of this thread: the handler waits for that one
  sigset_t block;
  cleanupSignalSet(block);
  ::pthread_sigmask(SIG_BLOCK, &block, &mSavedMask);
  gDeferring.fetch_add(1);
  if (gCleaning.load()) {  // a handler already removes files: do not start a step
    gDeferring.fetch_sub(1);
    for (;;) sleepBriefly();  // the handler ends the process
  }
}

DeferCleanupSignals::~DeferCleanupSignals() {
  if (--tStepDepth > 0) return;
  gDeferring.fetch_sub(1);
  ::pthread_sigmask(SIG_SETMASK, &mSavedMask, nullptr);
}

void installCleanupSignalHandlers() {
  static std::atomic<bool> installed{false};
  if (installed.exchange(true)) return;
  struct sigaction action {};
  action.sa_handler = onCleanupSignal;
  action.sa_flags = SA_RESETHAND;
  cleanupSignalSet(action.sa_mask);  // one cleanup at a time per thread
  for (int s : kCleanupSignals) {
    struct sigaction previous {};
    ::sigaction(s, nullptr, &previous);
    if (previous.sa_handler == SIG_IGN) continue;  // e.g. nohup: keep ignoring it
    ::sigaction(s, &action, nullptr);
  }
}

std::optional<long> temporaryFileOwner(std::string_view name) {
  constexpr std::string_view kMark = ".tmp-";
  const auto mark = name.rfind(kMark);
  if (name.size() < 2 || name[0] != '.' || mark == std::string_view::npos || mark < 2) return std::nullopt;
  const std::string_view rest = name.substr(mark + kMark.size());  // <pid>-<n>
  const auto dash = rest.find('-');
  if (dash == 0 || dash == std::string_view::npos || dash + 1 == rest.size() || dash > 18) return std::nullopt;
  long pid = 0;
  for (std::size_t i = 0; i < rest.size(); ++i) {
    if (i == dash) continue;
    if (rest[i] < '0' || rest[i] > '9') return std::nullopt;
    if (i < dash) pid = pid * 10 + (rest[i] - '0');
  }
  if (pid <= 0) return std::nullopt;
  return pid;
}

bool processExists(long pid) {
  if (pid <= 0 || pid != long(pid_t(pid))) return false;
  return ::kill(pid_t(pid), 0) == 0 || errno != ESRCH;
}

AtomicFile::AtomicFile(std::filesystem::path destination) : mDestination(std::move(destination)) {
  auto dir = mDestination.parent_path();
  if (dir.empty()) dir = ".";
  mTemporary = dir / ("." + mDestination.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                      std::to_string(gTemporaryCounter++));
  const DeferCleanupSignals step;          // registered and created as one step
  mCleanup = CleanupOnSignal(mTemporary);
  mFile = std::fopen(mTemporary.c_str(), "wb");
  if (!mFile) {
    // Name what the user asked for, and the directory when it is what is missing.
    const std::string reason = errnoText();
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec))
      throw OutputError(mDestination, "cannot be written: the directory " + dir.string() + " does not exist");
    throw OutputError(mDestination, "cannot be written (its temporary " + mTemporary.filename().string() +
                                        " cannot be created: " + reason + ")");
  }
  mBuffer.attach(mFile);
}

AtomicFile::~AtomicFile() {
  if (mFile) {
    std::fclose(mFile);
    std::error_code ec;
    std::filesystem::remove(mTemporary, ec);
  }
}

void AtomicFile::write(const void* data, std::size_t bytes) {
  FLIPSCOPE_CHECK(mFile, "write after commit");
  if (bytes && std::fwrite(data, 1, bytes, mFile) != bytes) throw temporaryFailure("write");
  mOffset += bytes;
  if (mOffset - mWritebackStarted >= kAtomicFileWritebackBytes) {
    if (std::fflush(mFile) != 0) throw temporaryFailure("flush");
    // Only a hint: where it fails (a file system without it), commit()'s fsync writes all.
    ::sync_file_range(::fileno(mFile), off64_t(mWritebackStarted), off64_t(mOffset - mWritebackStarted),
                      SYNC_FILE_RANGE_WRITE);
    mWritebackStarted = mOffset;
  }
}

void AtomicFile::writeAt(std::uint64_t offset, const void* data, std::size_t bytes) {
  FLIPSCOPE_CHECK(mFile, "write after commit");
  FLIPSCOPE_CHECK(offset + bytes <= mOffset, "offset=" << offset << " bytes=" << bytes << " written=" << mOffset);
  if (::fseeko(mFile, static_cast<off_t>(offset), SEEK_SET) != 0 ||
      (bytes && std::fwrite(data, 1, bytes, mFile) != bytes) ||
      ::fseeko(mFile, static_cast<off_t>(mOffset), SEEK_SET) != 0)
    throw temporaryFailure("write", offset);
}

OutputError AtomicFile::temporaryFailure(const char* what, std::optional<std::uint64_t> atByte) const {
  const int error = errno;  // first: building the message allocates
  return OutputError(mDestination, "cannot be written: " + std::string(what) +
                                       (atByte ? " at byte " + std::to_string(*atByte) : std::string()) +
                                       " of its temporary " + mTemporary.filename().string() +
                                       " failed: " + std::strerror(error));
}

void AtomicFile::commit() {
  FLIPSCOPE_CHECK(mFile, "commit twice");
  if (std::fflush(mFile) != 0) throw temporaryFailure("flush");
  if (::fsync(::fileno(mFile)) != 0) throw temporaryFailure("fsync");
  std::fclose(mFile);
  mFile = nullptr;
  if (std::rename(mTemporary.c_str(), mDestination.c_str()) != 0) {
    auto reason = errnoText();
    std::error_code ec;
    std::filesystem::remove(mTemporary, ec);
    throw OutputError(mDestination, "cannot rename temporary file into place: " + reason);
  }
  mCleanup.release();  // the temporary name is gone
  auto dir = mDestination.parent_path();
  syncDirectory(dir.empty() ? std::filesystem::path(".") : dir);
}

void writeFileAtomically(const std::filesystem::path& destination, std::span<const std::byte> bytes) {
  AtomicFile file(destination);
  file.write(bytes);
  file.commit();
}

void writeTextAtomically(const std::filesystem::path& destination, std::string_view text) {
  writeFileAtomically(destination, std::as_bytes(std::span(text.data(), text.size())));
}

namespace {
/// The bytes of `path`, appended to `out` (a byte or char container); `what` names the file in
/// errors ("" for none).
template <class Bytes>
void readWhole(const std::filesystem::path& path, std::string_view what, Bytes& out) {
  const std::string named = what.empty() ? std::string() : " " + std::string(what);
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw FileError(path, "cannot open" + named + ": " + errnoText());
  char buffer[1 << 16];
  for (;;) {
    std::size_t n = std::fread(buffer, 1, sizeof buffer, f);
    const auto* begin = reinterpret_cast<const typename Bytes::value_type*>(buffer);
    out.insert(out.end(), begin, begin + n);
    if (n < sizeof buffer) break;
  }
  bool failed = std::ferror(f);
  std::fclose(f);
  if (failed) throw FileError(path, "read failed" + (what.empty() ? std::string() : " (" + std::string(what) + ")"));
}
}  // namespace

std::vector<std::byte> readFile(const std::filesystem::path& path) {
  std::vector<std::byte> bytes;
  readWhole(path, "", bytes);
  return bytes;
}

std::string readTextFile(const std::filesystem::path& path, std::string_view what) {
  std::string text;
  readWhole(path, what, text);
  return text;
}

void syncDirectory(const std::filesystem::path& dir) {
  int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd < 0) return;  // best effort: some filesystems refuse to open directories
  ::fsync(fd);
  ::close(fd);
}

}  // namespace flipscope
