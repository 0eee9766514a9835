// SpillFile: see the header.
#include "preprocess/particles/SpillFile.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

#include "core/AtomicFile.h"
#include "core/Error.h"

namespace flipscope::detail {
namespace {

/// An open descriptor of a new unnamed file in `dir`, or -1 (errno set).
int openUnnamed(const std::filesystem::path& dir) {
#ifdef O_TMPFILE
  const int fd = ::open(dir.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
  if (fd >= 0) return fd;  // else a file system without O_TMPFILE: a named file, removed at once
#endif
  std::string name = (dir / ".flipscope-spill-XXXXXX").string();
  const DeferCleanupSignals step;  // no signal between creating and removing the name
  const int named = ::mkstemp(name.data());
  if (named < 0) return -1;
  ::unlink(name.c_str());
  ::fcntl(named, F_SETFD, FD_CLOEXEC);
  return named;
}

}  // namespace

SpillFile::SpillFile(const std::filesystem::path& directory)
    : mDirectory(directory.empty() ? std::filesystem::path(".") : directory) {
  const int fd = openUnnamed(mDirectory);
  if (fd < 0) throw OutputError(mDirectory, "cannot create a temporary file: " + errnoText());
  mFile = ::fdopen(fd, "w+b");
  if (!mFile) {
    const std::string reason = errnoText();
    ::close(fd);
    throw OutputError(mDirectory, "cannot open a temporary file: " + reason);
  }
  mBuffer.attach(mFile);
}

SpillFile::~SpillFile() {
  if (mFile) std::fclose(mFile);
}

void SpillFile::write(const void* data, std::size_t bytes) {
  if (bytes && std::fwrite(data, 1, bytes, mFile) != bytes)
    throw OutputError(mDirectory, "cannot write a temporary file: " + errnoText());
  mSize += bytes;
}

void SpillFile::readBack(const std::function<void(std::span<const std::byte>)>& consume) {
  if (std::fflush(mFile) != 0 || ::fseeko(mFile, 0, SEEK_SET) != 0)
    throw OutputError(mDirectory, "cannot read back a temporary file: " + errnoText());
  std::vector<std::byte> buffer(std::size_t(std::min<std::uint64_t>(kBufferBytes, mSize)));
  for (std::uint64_t done = 0; done < mSize;) {
    const auto n = std::size_t(std::min<std::uint64_t>(buffer.size(), mSize - done));
    if (std::fread(buffer.data(), 1, n, mFile) != n)
      throw OutputError(mDirectory, "cannot read back a temporary file at byte " + std::to_string(done) + ": " +
                                        (std::ferror(mFile) ? errnoText() : std::string("it is shorter")));
    consume(std::span<const std::byte>(buffer.data(), n));
    done += n;
  }
  if (::fseeko(mFile, 0, SEEK_END) != 0)
    throw OutputError(mDirectory, "cannot seek in a temporary file: " + errnoText());
}

}  // namespace flipscope::detail
