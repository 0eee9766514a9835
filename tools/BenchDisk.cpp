#include "tools/BenchDisk.h"

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <memory>

#include "core/Elapsed.h"
#include "core/Error.h"

namespace flipscope::tools {

void dropFromPageCache(const std::vector<std::filesystem::path>& files) {
  for (const auto& file : files) {
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) continue;
    ::fdatasync(fd);
    ::posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED);
    ::close(fd);
  }
}

DiskRead readUncached(const std::vector<std::filesystem::path>& files, std::size_t blockBytes) {
  std::unique_ptr<void, decltype(&std::free)> buffer(std::aligned_alloc(4096, blockBytes), &std::free);
  if (!buffer) throw InputError("bench: cannot allocate the read buffer");
  DiskRead result;
  result.direct = true;
  dropFromPageCache(files);  // also for the O_DIRECT read: no dirty pages of the files left
  const auto start = std::chrono::steady_clock::now();
  for (const auto& file : files) {
    int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_DIRECT);
    if (fd < 0) {  // a filesystem without O_DIRECT (tmpfs): the page cache, dropped above
      result.direct = false;
      fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    }
    if (fd < 0) throw FileError(file, "cannot open");
    for (;;) {
      const ssize_t n = ::read(fd, buffer.get(), blockBytes);
      if (n < 0) {
        ::close(fd);
        throw FileError(file, "read failed");
      }
      if (n == 0) break;
      result.bytes += std::uint64_t(n);
    }
    ::close(fd);
  }
  result.seconds = secondsSince(start);
  return result;
}

}  // namespace flipscope::tools
