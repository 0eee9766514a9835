// AtomicFile: write a file under a temporary name, then fsync and rename it into place, so a
// reader never sees a half-written file: after a crash the destination holds either the old
// content or the new, complete one. An AtomicFile destroyed without commit() removes its
// temporary file, and so does SIGINT, SIGTERM or SIGHUP once installCleanupSignalHandlers()
// ran (the temporary is registered with CleanupOnSignal). Not thread safe.
//
// A temporary is named `.<name>.tmp-<pid>-<n>`: the PID tells a later process whether the
// writer is gone (temporaryFileOwner, processExists), so that a temporary left by a killed
// process (SIGKILL, power loss) can be recognised as stale and removed.
#pragma once

#include <signal.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/Error.h"
#include "core/StdioBuffer.h"

namespace flipscope {

/// Registers a path to remove when the process is stopped by SIGINT, SIGTERM or SIGHUP, for as
/// long as the object lives (or until release()). Destroying it does not remove the path.
/// installCleanupSignalHandlers() makes those signals unlink every registered file, then rmdir
/// every registered directory (only an empty one goes; twice, so that a directory emptied by
/// the removal of a registered one inside it goes too, one level deep), then end the process by
/// the same signal with its default action. The handler is async-signal-safe: it uses atomics and calls
/// unlink, rmdir, nanosleep and raise only. Registration is thread safe; at most kCleanupSlots paths are
/// registered at once, beyond that a registration does nothing (registered() is false).
class CleanupOnSignal {
 public:
  enum class Kind { File, Directory };
  static constexpr int kCleanupSlots = 4096;

  CleanupOnSignal() = default;
  explicit CleanupOnSignal(const std::filesystem::path& path, Kind kind = Kind::File);
  ~CleanupOnSignal() { release(); }
  CleanupOnSignal(CleanupOnSignal&& other) noexcept : mSlot(other.mSlot) { other.mSlot = -1; }
  CleanupOnSignal& operator=(CleanupOnSignal&& other) noexcept;
  CleanupOnSignal(const CleanupOnSignal&) = delete;
  CleanupOnSignal& operator=(const CleanupOnSignal&) = delete;

  /// Forgets the path: a later signal leaves it alone.
  void release() noexcept;
  bool registered() const { return mSlot >= 0; }

 private:
  int mSlot = -1;
};

/// One step, for the signal handler, of creating or renaming files and changing their
/// CleanupOnSignal registrations (register then create a temporary; rename store.fsh to list a
/// frame, then stop the frame file's registration): while one lives, the cleanup signals are
/// blocked in this thread (delivered when it ends), and a handler running on another thread
/// waits for it to end (up to 5 s) before it removes anything. So the handler never sees a file
/// created but not yet registered, nor removes one just committed. The outermost step opened
/// after a handler started never returns (the process is ending). Nestable.
class DeferCleanupSignals {
 public:
  DeferCleanupSignals();
  ~DeferCleanupSignals();
  DeferCleanupSignals(const DeferCleanupSignals&) = delete;
  DeferCleanupSignals& operator=(const DeferCleanupSignals&) = delete;

 private:
  sigset_t mSavedMask;
};

/// Installs the SIGINT, SIGTERM and SIGHUP handlers of CleanupOnSignal (idempotent). The
/// signals end the process as before, with the registered paths removed first; a signal the
/// process ignores (nohup) stays ignored.
void installCleanupSignalHandlers();

/// The PID in the name of an AtomicFile temporary (`.<name>.tmp-<pid>-<n>`); nullopt when
/// `fileName` (a name, not a path) is not one.
std::optional<long> temporaryFileOwner(std::string_view fileName);

/// False only when there is no process `pid` (kill(pid, 0) fails with ESRCH). A PID reused by
/// an unrelated process counts as existing, so a stale file then stays until that one ends.
bool processExists(long pid);

/// The bytes an AtomicFile gathers before it writes them.
inline constexpr std::size_t kAtomicFileBufferBytes = std::size_t(1) << 20;
/// An AtomicFile asks the kernel to start writing its bytes back each time this many more were
/// written (sync_file_range, without waiting), so that commit()'s fsync waits for the last few
/// only: a frame of a store is fsynced as the next bricks are encoded, not after them all.
inline constexpr std::uint64_t kAtomicFileWritebackBytes = std::uint64_t(2) << 20;

class AtomicFile {
 public:
  /// Creates `<dir>/.<name>.tmp-<pid>-<n>` beside `destination`. Throws FileError.
  explicit AtomicFile(std::filesystem::path destination);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  void write(const void* data, std::size_t bytes);
  void write(std::span<const std::byte> bytes) { write(bytes.data(), bytes.size()); }
  /// Overwrites `bytes` bytes at `offset` (already written: offset + bytes <= offset()), e.g. a
  /// header field known only at the end; later writes append again.
  void writeAt(std::uint64_t offset, const void* data, std::size_t bytes);
  /// Bytes written so far.
  std::uint64_t offset() const { return mOffset; }
  /// Flushes, fsyncs, renames over the destination and fsyncs the directory. Throws FileError.
  void commit();

  const std::filesystem::path& destination() const { return mDestination; }
  const std::filesystem::path& temporaryPath() const { return mTemporary; }

 private:
  std::filesystem::path mDestination;
  std::filesystem::path mTemporary;
  CleanupOnSignal mCleanup;  ///< the temporary, until committed or removed
  StdioBuffer mBuffer{kAtomicFileBufferBytes};  ///< mFile's
  std::FILE* mFile = nullptr;
  std::uint64_t mOffset = 0;
  std::uint64_t mWritebackStarted = 0;  ///< bytes [0, this) were handed to sync_file_range

  /// The error of a failed `what` ("write", "flush"; `atByte`: where a write went) on the
  /// temporary, with the reason of the errno the failing call left (call it at once: it reads
  /// errno before anything else): it names the destination, the file the user asked for, and
  /// the temporary it was written to.
  OutputError temporaryFailure(const char* what, std::optional<std::uint64_t> atByte = std::nullopt) const;
};

/// Writes `bytes` to `destination` atomically.
void writeFileAtomically(const std::filesystem::path& destination, std::span<const std::byte> bytes);

/// Writes `text` to `destination` atomically (JSON, scripts, summaries).
void writeTextAtomically(const std::filesystem::path& destination, std::string_view text);

/// Reads a whole file. Throws FileError when it cannot be opened or read.
std::vector<std::byte> readFile(const std::filesystem::path& path);
/// Reads a whole text file (a camera, a script). Throws FileError naming the file and `what` it
/// is ("cannot open camera file: No such file or directory") when it cannot be opened or read.
std::string readTextFile(const std::filesystem::path& path, std::string_view what);

/// fsyncs a directory so that a rename inside it is durable.
void syncDirectory(const std::filesystem::path& dir);

}  // namespace flipscope
