// DirectFile (see the header).
#include "preprocess/DirectFile.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>

#include "core/Error.h"

namespace flipscope::detail {

AlignedBuffer::AlignedBuffer(std::size_t bytes) : mSize((bytes + kDirectBlock - 1) / kDirectBlock * kDirectBlock) {
  if (mSize == 0) return;
  auto* p = static_cast<std::byte*>(std::aligned_alloc(kDirectBlock, mSize));
  if (!p) throw std::bad_alloc();
  mData.reset(p);
}

void AlignedBuffer::Free::operator()(std::byte* p) const { std::free(p); }

DirectFile::DirectFile(const std::filesystem::path& path, Mode mode) : mPath(path) {
  const int flags = mode == Mode::Create ? O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC : O_RDONLY | O_CLOEXEC;
  mFd = ::open(path.c_str(), flags | O_DIRECT, 0644);
  if (mFd < 0 && errno == EINVAL) mFd = ::open(path.c_str(), flags, 0644);  // tmpfs and others: no O_DIRECT
  if (mFd < 0)
    throw FileError(path, std::string(mode == Mode::Create ? "cannot create spill file: " : "cannot reopen spill file: ") +
                              std::strerror(errno));
}

DirectFile::~DirectFile() {
  if (mFd >= 0) ::close(mFd);
}

void DirectFile::append(std::span<const std::byte> bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(mFd, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw FileError(mPath, std::string("spill write failed (disk full?): ") + std::strerror(n < 0 ? errno : ENOSPC));
    bytes = bytes.subspan(std::size_t(n));
  }
}

std::size_t DirectFile::read(std::span<std::byte> into) {
  std::size_t done = 0;
  while (done < into.size()) {
    const ssize_t n = ::read(mFd, into.data() + done, into.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw FileError(mPath, std::string("cannot read spill file: ") + std::strerror(errno));
    if (n == 0) break;
    done += std::size_t(n);
  }
  return done;
}

}  // namespace flipscope::detail
