// Disk reads for the benchmarks that compare with "disk speed" (bench preprocess, bench farm):
// the uncached read of a set of files, and dropping them from the page cache so that the next
// reader reads them from the disk too.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace flipscope::tools {

/// Asks the kernel to drop the files' pages from the page cache (fdatasync, then
/// POSIX_FADV_DONTNEED: clean pages go at once).
void dropFromPageCache(const std::vector<std::filesystem::path>& files);

struct DiskRead {
  std::uint64_t bytes = 0;
  double seconds = 0;
  bool direct = false;  ///< O_DIRECT (like `dd iflag=direct`); else after dropFromPageCache
  double bytesPerSecond() const { return seconds > 0 ? double(bytes) / seconds : 0; }
};

/// Reads every file once from the disk: with O_DIRECT in aligned reads of `blockBytes` (a
/// multiple of 4096) where the filesystem allows it, else through the page cache after dropping
/// the files from it. Throws FileError naming a file that cannot be read.
DiskRead readUncached(const std::vector<std::filesystem::path>& files, std::size_t blockBytes = 16 << 20);

}  // namespace flipscope::tools
