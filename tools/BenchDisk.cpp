#include "tools/BenchDisk.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "core/AlignedBuffer.h"
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

namespace {

/// `bytes` of 4 KiB pages from a mapping of their own, advised against huge pages.
class SmallPageBuffer {
 public:
  explicit SmallPageBuffer(std::size_t bytes) : mBytes(bytes) {
    mData = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (mData == MAP_FAILED) throw InputError("bench: cannot map the read buffer");
    ::madvise(mData, bytes, MADV_NOHUGEPAGE);
  }
  ~SmallPageBuffer() { ::munmap(mData, mBytes); }
  SmallPageBuffer(const SmallPageBuffer&) = delete;
  SmallPageBuffer& operator=(const SmallPageBuffer&) = delete;
  void* data() const { return mData; }

 private:
  void* mData;
  std::size_t mBytes;
};

}  // namespace

DiskRead readUncached(const std::vector<std::filesystem::path>& files, std::size_t blockBytes, ReadPages pages) {
  if (blockBytes == 0 || blockBytes % kDirectBlock != 0)
    throw InputError("bench: a direct read's size is a whole number of 4 KiB blocks, not " +
                     std::to_string(blockBytes));
  std::optional<AlignedBuffer> huge;
  std::optional<SmallPageBuffer> small;
  void* const buffer =
      pages == ReadPages::Huge ? static_cast<void*>(huge.emplace(blockBytes).data()) : small.emplace(blockBytes).data();
  std::memset(buffer, 0, blockBytes);  // its pages in place before the clock starts
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
      const ssize_t n = ::read(fd, buffer, blockBytes);
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
