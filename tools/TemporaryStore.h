// TemporaryStore: a directory under the system's temporary directory ($TMPDIR, else /tmp) for a
// brick store one command makes and reads, removed with what it holds when the object is
// destroyed. `render` given particle files converts the frames it renders into one.
//
// Contract:
//  - the directory is `flipscope-render-<pid>-<random>` (mode 0700), locked (flock) while the
//    object lives; the store is store() inside it, which the convert makes;
//  - SIGINT, SIGTERM and SIGHUP remove the directory when it is empty (a convert stopped by one
//    removes the store it made), and all of it once registerForSignalCleanup() has registered
//    the store's files (installCleanupSignalHandlers() must have run);
//  - the constructor first removes this user's temporary stores that no process locks: those a
//    SIGKILL or a power loss left, or a signal between two frames of the convert.
#pragma once

#include <filesystem>
#include <string_view>
#include <vector>

#include "core/AtomicFile.h"

namespace flipscope::tools {

/// What the errors of a temporary store suggest.
inline constexpr std::string_view kTemporaryStoreHint =
    "(the store of particle files goes under $TMPDIR: set TMPDIR to a directory with room, or convert into a store "
    "and render that)";

class TemporaryStore {
 public:
  /// Throws OutputError naming the temporary directory when the store's cannot be made there.
  TemporaryStore();
  ~TemporaryStore();
  TemporaryStore(const TemporaryStore&) = delete;
  TemporaryStore& operator=(const TemporaryStore&) = delete;

  /// The store's directory (the convert makes it).
  std::filesystem::path store() const { return mPath / "store"; }
  /// Registers the store's files and directory for removal by the cleanup signals (at most
  /// CleanupOnSignal::kCleanupSlots in all; beyond, the rest is left to the next TemporaryStore).
  void registerForSignalCleanup();

 private:
  std::filesystem::path mPath;
  int mLock = -1;                         ///< mPath, opened and locked
  std::vector<CleanupOnSignal> mCleanup;  ///< mPath, then the store's files and directory
};

}  // namespace flipscope::tools
