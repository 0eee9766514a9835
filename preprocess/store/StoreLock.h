// The locks by which any number of writers share one store (BrickStore.h), on one machine or
// over a shared filesystem. Both live in the file `store.lock` of the store directory as open
// file description locks (fcntl F_OFD_*), which the Linux NFS client carries to the server as
// POSIX record locks, so writers on different machines see each other's:
//   byte 0, the writer lock: every convert holds it shared for its whole run. Removing what a
//           dead writer left (temporaries, frame files never listed) needs it exclusive, so only
//           a writer that is alone in the store does that housekeeping.
//   byte 1, the table lock: held exclusive while store.fsh is read, changed and rewritten
//           (creating the store, listing a frame), so concurrent writers never lose each
//           other's frames.
// Readers (info, render) take no lock: store.fsh is replaced atomically and lists only frames
// whose files are complete. On a filesystem without locks (ENOLCK, EOPNOTSUPP: NFS mounted
// `nolock`) both degrade to no locking (locking() is false), and a writer then behaves as if it
// were alone: concurrent writers are not safe there, and convert --append refuses to run.
// A lock taken on a lock file that was unlinked meanwhile is retaken on the file at the path.
#pragma once

#include <filesystem>

namespace flipscope {

inline constexpr char kStoreLockName[] = "store.lock";

/// The writer lock of a store directory that exists, held until destruction.
class StoreWriterLock {
 public:
  /// Opens (creating) store.lock and takes the writer lock exclusive when no other writer holds
  /// it (alone() is then true), else shared. Throws OutputError when the file cannot be opened.
  explicit StoreWriterLock(const std::filesystem::path& storeDir);
  ~StoreWriterLock();
  StoreWriterLock(const StoreWriterLock&) = delete;
  StoreWriterLock& operator=(const StoreWriterLock&) = delete;

  /// No other writer held the lock when this one took it (or the filesystem has no locks).
  bool alone() const { return mAlone; }
  /// The filesystem supports the locks.
  bool locking() const { return mLocking; }
  /// From exclusive to shared (atomically: no other writer can slip in between and find the
  /// store empty of writers); alone() stays as it was. Call once the housekeeping is done.
  void share();
  /// Unlinks store.lock when this writer is (again) the only one: before a directory that
  /// the convert created, and left empty, is removed. False when another writer holds it.
  bool removeFileIfAlone();

 private:
  std::filesystem::path mFile;
  int mFd = -1;
  bool mAlone = false;
  bool mExclusive = false;
  bool mLocking = true;
};

/// The table lock of a store directory that exists, held exclusive until destruction (waits
/// for other writers' table updates, which take milliseconds).
class StoreTableLock {
 public:
  explicit StoreTableLock(const std::filesystem::path& storeDir);
  ~StoreTableLock();
  StoreTableLock(const StoreTableLock&) = delete;
  StoreTableLock& operator=(const StoreTableLock&) = delete;

 private:
  int mFd = -1;
};

}  // namespace flipscope
