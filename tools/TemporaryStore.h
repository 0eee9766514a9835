// TemporaryStore: the place of a brick store in a fresh directory under the system's temporary
// directory ($TMPDIR, else /tmp), removed with what it holds when the object is destroyed.
// `render` given particle files converts the frames it renders into one
// (tools/RenderCommand.cpp).
//
// Contract. The directory is `flipscope-render-<pid>-<random>`, and the store `store` inside
// it, which the convert creates (so that a signal during the convert removes what it made, as
// it would of any store it creates). SIGINT, SIGTERM and SIGHUP remove the directory once it is
// empty, and, once hold() has registered the store's files, all of it (CleanupOnSignal, after
// installCleanupSignalHandlers()). What a killed process leaves (SIGKILL, power loss, a signal
// between two frames of a convert) is removed by the next TemporaryStore made on the machine,
// once no process of that pid lives (processExists), as AtomicFile's stale temporaries are, and
// none holds the directory's lock (flock, which a process holds while its TemporaryStore lives:
// a render in another pid namespace that shares the directory keeps its store).
#pragma once

#include <filesystem>
#include <vector>

#include "core/AtomicFile.h"

namespace flipscope::tools {

class TemporaryStore {
 public:
  /// Creates the directory (an OutputError naming the temporary directory when it cannot), after
  /// removing the stale ones.
  TemporaryStore();
  ~TemporaryStore();
  TemporaryStore(const TemporaryStore&) = delete;
  TemporaryStore& operator=(const TemporaryStore&) = delete;

  /// The store's directory (not made yet: the convert makes it).
  std::filesystem::path store() const { return mPath / "store"; }
  /// Registers the store's files and directory for removal by the cleanup signals.
  void hold();

  /// The pid in the name of a temporary store's directory; 0 when `name` is not one.
  static long ownerOf(const std::string& name);

 private:
  std::filesystem::path mPath;
  int mLock = -1;  ///< the directory, opened and locked
  std::vector<CleanupOnSignal> mCleanup;  ///< the directory, then the store's files and directory
};

}  // namespace flipscope::tools
