#include "preprocess/store/StoreLock.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/Error.h"

namespace flipscope {
namespace {

constexpr off_t kWriterByte = 0;
constexpr off_t kTableByte = 1;

int openLockFile(const std::filesystem::path& file) {
  const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) throw OutputError(file, std::string("cannot open the store's lock file: ") + std::strerror(errno));
  return fd;
}

/// fcntl(F_OFD_SETLK[W]) on one byte; false when it is held by another (non-blocking only).
/// Filesystems without locks count as success: there is nothing to wait for.
bool lockByte(int fd, off_t byte, short type, bool wait, const std::filesystem::path& file) {
  struct flock lock {};
  lock.l_type = type;
  lock.l_whence = SEEK_SET;
  lock.l_start = byte;
  lock.l_len = 1;
  while (::fcntl(fd, wait ? F_OFD_SETLKW : F_OFD_SETLK, &lock) != 0) {
    if (errno == EINTR) continue;
    if (errno == EAGAIN || errno == EACCES) return false;
    if (errno == ENOLCK || errno == EOPNOTSUPP || errno == EINVAL || errno == ENOSYS) return true;
    throw FileError(file, std::string("cannot lock: ") + std::strerror(errno));
  }
  return true;
}

}  // namespace

StoreWriterLock::StoreWriterLock(const std::filesystem::path& storeDir)
    : mFile(storeDir / kStoreLockName), mFd(openLockFile(mFile)) {
  try {
    mAlone = lockByte(mFd, kWriterByte, F_WRLCK, false, mFile);
    mExclusive = mAlone;
    if (!mAlone) lockByte(mFd, kWriterByte, F_RDLCK, true, mFile);
  } catch (...) {
    ::close(mFd);
    throw;
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
  if (!mExclusive && !lockByte(mFd, kWriterByte, F_WRLCK, false, mFile)) return false;
  mExclusive = true;
  std::error_code ec;
  std::filesystem::remove(mFile, ec);
  return true;
}

StoreTableLock::StoreTableLock(const std::filesystem::path& storeDir) {
  const auto file = storeDir / kStoreLockName;
  mFd = openLockFile(file);
  try {
    lockByte(mFd, kTableByte, F_WRLCK, true, file);
  } catch (...) {
    ::close(mFd);
    throw;
  }
}

StoreTableLock::~StoreTableLock() {
  if (mFd >= 0) ::close(mFd);
}

}  // namespace flipscope
