#include "tools/TemporaryStore.h"

#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <string>
#include <string_view>
#include <system_error>

#include "core/Error.h"

namespace flipscope::tools {
namespace fs = std::filesystem;
namespace {

constexpr std::string_view kTemporaryStorePrefix = "flipscope-render-";
/// A directory is made under this name, locked, then renamed to its kTemporaryStorePrefix name:
/// the sweep never meets one of its names unlocked while its process lives.
constexpr std::string_view kUnlockedPrefix = ".flipscope-render-making-";

/// `dir` opened (not through a symlink) and locked, exclusively; -1 when it cannot be opened or,
/// without `wait`, another open file description holds its lock. Locks end with the process.
int lockDirectory(const fs::path& dir, bool wait) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return -1;
  if (::flock(fd, LOCK_EX | (wait ? 0 : LOCK_NB)) == 0) return fd;
  ::close(fd);
  return -1;
}

/// Removes the temporary stores of this user that no process locks. Other users' entries, and
/// anything that is not a directory (a symlink), are left alone.
void removeStaleTemporaryStores(const fs::path& temporaryDir) {
  std::error_code ec;
  for (fs::directory_iterator it(temporaryDir, ec), end; !ec && it != end; it.increment(ec)) {
    const fs::path& path = it->path();
    if (!path.filename().string().starts_with(kTemporaryStorePrefix)) continue;
    struct stat entry {};
    if (::lstat(path.c_str(), &entry) != 0 || !S_ISDIR(entry.st_mode) || entry.st_uid != ::geteuid()) continue;
    const int fd = lockDirectory(path, false);
    if (fd < 0) continue;
    struct stat locked {};
    std::error_code ignored;
    if (::fstat(fd, &locked) == 0 && locked.st_dev == entry.st_dev && locked.st_ino == entry.st_ino)
      fs::remove_all(path, ignored);
    ::close(fd);
  }
}

}  // namespace

TemporaryStore::TemporaryStore() {
  std::error_code ec;
  const fs::path temporaryDir = fs::temp_directory_path(ec);
  if (ec) {
    const char* named = std::getenv("TMPDIR");
    throw OutputError(named ? named : "$TMPDIR", "no temporary directory for the store of the particle files: " +
                                                     ec.message() + " " + std::string(kTemporaryStoreHint));
  }
  removeStaleTemporaryStores(temporaryDir);
  const std::string pid = std::to_string(::getpid());
  std::string making = (temporaryDir / (std::string(kUnlockedPrefix) + pid + "-XXXXXX")).string();
  {
    const DeferCleanupSignals step;  // created and registered as one step
    if (!::mkdtemp(making.data()))
      throw OutputError(temporaryDir, "cannot create a temporary store for the particle files: " + errnoText() + " " +
                                          std::string(kTemporaryStoreHint));
    mCleanup.emplace_back(making, CleanupOnSignal::Kind::Directory);
  }
  mLock = lockDirectory(making, true);
  const fs::path path =
      temporaryDir / (std::string(kTemporaryStorePrefix) + pid + "-" + making.substr(making.size() - 6));
  int renamed = -1;
  if (mLock >= 0) {
    const DeferCleanupSignals step;  // renamed and registered under its name as one step
    renamed = ::renameat2(AT_FDCWD, making.c_str(), AT_FDCWD, path.c_str(), RENAME_NOREPLACE);
    if (renamed != 0 && errno == EINVAL)  // a filesystem without RENAME_NOREPLACE
      renamed = ::rename(making.c_str(), path.c_str());
    if (renamed == 0) mCleanup.back() = CleanupOnSignal(path, CleanupOnSignal::Kind::Directory);
  }
  if (renamed != 0) {
    const std::string reason = errnoText();
    if (mLock >= 0) ::close(mLock);
    ::rmdir(making.c_str());
    throw OutputError(making, "cannot lock and name the temporary store for the particle files: " + reason);
  }
  mPath = path;
}

TemporaryStore::~TemporaryStore() {
  std::error_code ignored;
  fs::remove_all(mPath, ignored);
  ::close(mLock);
}

void TemporaryStore::registerForSignalCleanup() {
  std::error_code ec;
  for (fs::directory_iterator it(store(), ec), end; !ec && it != end; it.increment(ec))
    mCleanup.emplace_back(it->path(), CleanupOnSignal::Kind::File);
  mCleanup.emplace_back(store(), CleanupOnSignal::Kind::Directory);
}

}  // namespace flipscope::tools
