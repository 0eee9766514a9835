#include "preprocess/store/StoreLock.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/Error.h"

namespace flipscope {
namespace {

constexpr off_t kWriterByte = 0;
constexpr off_t kTableByte = 1;

enum class LockResult { Taken, Busy, Unsupported };

int openLockFile(const std::filesystem::path& file) {
  const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) throw OutputError(file, std::string("cannot open the store's lock file: ") + std::strerror(errno));
  return fd;
}

/// fcntl(F_OFD_SETLK[W]) on one byte.
LockResult lockByte(int fd, off_t byte, short type, bool wait, const std::filesystem::path& file) {
  struct flock lock {};
  lock.l_type = type;
  lock.l_whence = SEEK_SET;
  lock.l_start = byte;
  lock.l_len = 1;
  while (::fcntl(fd, wait ? F_OFD_SETLKW : F_OFD_SETLK, &lock) != 0) {
    if (errno == EINTR) continue;
    if (errno == EAGAIN || errno == EACCES) return LockResult::Busy;
    if (errno == ENOLCK || errno == EOPNOTSUPP || errno == EINVAL || errno == ENOSYS) return LockResult::Unsupported;
    throw FileError(file, std::string("cannot lock: ") + std::strerror(errno));
  }
  return LockResult::Taken;
}

/// Whether `fd` is still the file at `file`: a lock taken on a lock file that a writer unlinked
/// meanwhile (removeFileIfAlone) would lock nothing others see.
bool stillThere(int fd, const std::filesystem::path& file) {
  struct stat open {}, named {};
  if (::fstat(fd, &open) != 0 || ::stat(file.c_str(), &named) != 0) return false;
  return open.st_dev == named.st_dev && open.st_ino == named.st_ino && open.st_nlink > 0;
}

}  // namespace

StoreWriterLock::StoreWriterLock(const std::filesystem::path& storeDir) : mFile(storeDir / kStoreLockName) {
  for (;;) {
    mFd = openLockFile(mFile);
    try {
      LockResult r = lockByte(mFd, kWriterByte, F_WRLCK, false, mFile);
      mExclusive = r == LockResult::Taken;
      if (r == LockResult::Busy) r = lockByte(mFd, kWriterByte, F_RDLCK, true, mFile);
      mLocking = r != LockResult::Unsupported;
      mAlone = mExclusive || !mLocking;
    } catch (...) {
      ::close(mFd);
      throw;
    }
    if (!mLocking || stillThere(mFd, mFile)) return;
    ::close(mFd);  // locked a file another writer removed: lock the one at the path now
  }
}

StoreWriterLock::~StoreWriterLock() {
  if (mFd >= 0) ::close(mFd);  // releases the lock
}

void StoreWriterLock::share() {
  if (!mExclusive) return;
  lockByte(mFd, kWriterByte, F_RDLCK, true, mFile);  // converting a record lock is atomic
  mExclusive = false;
}

bool StoreWriterLock::removeFileIfAlone() {
  if (!mLocking) return false;
  if (!mExclusive && lockByte(mFd, kWriterByte, F_WRLCK, false, mFile) != LockResult::Taken) return false;
  mExclusive = true;
  std::error_code ec;
  std::filesystem::remove(mFile, ec);
  return true;
}

StoreTableLock::StoreTableLock(const std::filesystem::path& storeDir) {
  const auto file = storeDir / kStoreLockName;
  for (;;) {
    mFd = openLockFile(file);
    LockResult r;
    try {
      r = lockByte(mFd, kTableByte, F_WRLCK, true, file);
    } catch (...) {
      ::close(mFd);
      throw;
    }
    if (r == LockResult::Unsupported || stillThere(mFd, file)) return;
    ::close(mFd);
  }
}

StoreTableLock::~StoreTableLock() {
  if (mFd >= 0) ::close(mFd);
}

}  // namespace flipscope
