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

/// The pages of the buffer a direct read lands in. On the development VM (virtio disk) a direct
/// read into huge pages took half as long as one into 4 KiB pages, `dd`'s: 1.2 GB in 0.41 to
/// 0.45 s against 0.88 to 0.93 s, 2 MiB reads, alternating (2026-12-07): the device maps a
/// buffer page by page.
enum class ReadPages {
  Huge,   ///< an AlignedBuffer: huge pages for reads of 2 MiB up, as convert's own reads
  Small,  ///< 4 KiB pages (MADV_NOHUGEPAGE), as `dd iflag=direct` reads where THP is not "always"
};

/// Reads every file once from the disk: with O_DIRECT in aligned reads of `blockBytes` (a
/// multiple of 4096) into a buffer of `pages` where the filesystem allows it, else through the
/// page cache after dropping the files from it. Throws FileError naming a file that cannot be
/// read.
DiskRead readUncached(const std::vector<std::filesystem::path>& files, std::size_t blockBytes = 16 << 20,
                      ReadPages pages = ReadPages::Huge);

}  // namespace flipscope::tools
