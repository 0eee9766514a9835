#include "tools/TemporaryStore.h"

#include <fcntl.h>
#include <stdlib.h>
#include <sys/file.h>
#include <unistd.h>

#include <string>
#include <string_view>
#include <system_error>

#include "core/Error.h"

namespace flipscope::tools {
namespace fs = std::filesystem;
namespace {

constexpr std::string_view kTemporaryStorePrefix = "flipscope-render-";

/// The directory `dir` opened and locked (flock, exclusive), or -1. `wait`: block until it is free.
int lockDirectory(const fs::path& dir, bool wait) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return -1;
  if (::flock(fd, LOCK_EX | (wait ? 0 : LOCK_NB)) == 0) return fd;
  ::close(fd);
  return -1;
}

/// Removes the temporary stores whose process is gone: no process of its pid lives here, and
/// none holds its lock (a process of another pid namespace that shares the directory).
void removeStaleTemporaryStores(const fs::path& temporaryDir) {
  std::error_code ec;
  for (fs::directory_iterator it(temporaryDir, ec), end; !ec && it != end; it.increment(ec)) {
    const long owner = TemporaryStore::ownerOf(it->path().filename().string());
    if (owner <= 0 || processExists(owner)) continue;
    if (const int fd = lockDirectory(it->path(), false); fd >= 0) {
      std::error_code ignored;
      fs::remove_all(it->path(), ignored);
      ::close(fd);
    }
  }
}

}  // namespace

long TemporaryStore::ownerOf(const std::string& name) {
  if (!name.starts_with(kTemporaryStorePrefix)) return 0;
  const std::string_view rest = std::string_view(name).substr(kTemporaryStorePrefix.size());  // <pid>-<random>
  const auto dash = rest.find('-');
  if (dash == 0 || dash == std::string_view::npos || dash > 18 || dash + 1 == rest.size()) return 0;
  long pid = 0;
  for (char c : rest.substr(0, dash)) {
    if (c < '0' || c > '9') return 0;
    pid = pid * 10 + (c - '0');
  }
  return pid;
}

TemporaryStore::TemporaryStore() {
  std::error_code ec;
  const fs::path temporaryDir = fs::temp_directory_path(ec);
  if (ec) throw OutputError("$TMPDIR", "no temporary directory for the store of the particle files: " + ec.message());
  removeStaleTemporaryStores(temporaryDir);
  std::string name = (temporaryDir / (std::string(kTemporaryStorePrefix) + std::to_string(::getpid()) + "-XXXXXX")).string();
  const DeferCleanupSignals step;  // created and registered as one step
  if (!::mkdtemp(name.data()))
    throw OutputError(temporaryDir, "cannot create a temporary store for the particle files: " +
                                        std::system_category().message(errno));
  mPath = name;
  mCleanup.emplace_back(mPath, CleanupOnSignal::Kind::Directory);
  mLock = lockDirectory(mPath, true);  // released by the kernel however the process ends
}

TemporaryStore::~TemporaryStore() {
  std::error_code ignored;
  fs::remove_all(mPath, ignored);
  if (mLock >= 0) ::close(mLock);
}

void TemporaryStore::hold() {
  std::error_code ec;
  for (fs::directory_iterator it(store(), ec), end; !ec && it != end; it.increment(ec))
    mCleanup.emplace_back(it->path(), CleanupOnSignal::Kind::File);
  mCleanup.emplace_back(store(), CleanupOnSignal::Kind::Directory);
}

}  // namespace flipscope::tools
