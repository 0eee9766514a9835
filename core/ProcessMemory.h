// The process's own memory use, for the budget reports of convert and the benchmarks.
#pragma once

#include <malloc.h>
#include <sys/resource.h>

#include <cstdint>
#include <cstdio>

namespace flipscope {

/// Peak resident set size of this process image so far, in bytes: VmHWM of /proc/self/status,
/// which starts afresh at exec (getrusage's ru_maxrss does not: a child spawned by a large
/// process would report its parent's peak). getrusage where /proc is missing.
inline std::uint64_t peakResidentBytes() {
  if (std::FILE* status = std::fopen("/proc/self/status", "r")) {
    char line[256];
    unsigned long long kib = 0;
    bool found = false;
    while (!found && std::fgets(line, sizeof line, status)) found = std::sscanf(line, "VmHWM: %llu kB", &kib) == 1;
    std::fclose(status);
    if (found) return std::uint64_t(kib) * 1024;
  }
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  return std::uint64_t(usage.ru_maxrss) * 1024;
}

/// Keeps freed memory from staying resident. glibc serves large blocks with mmap and returns
/// them on free, but raises that threshold each time such a block is freed (up to 32 MiB), so
/// a convert that allocates and frees big key buffers ends up keeping them on its heap: peak
/// RSS grew to twice the --mem budget. A fixed threshold stops the raising. Call once, first.
inline void limitHeapRetention() {
  ::mallopt(M_MMAP_THRESHOLD, 256 << 10);
  ::mallopt(M_TRIM_THRESHOLD, 1 << 20);
}

/// The renderer's policy, the opposite of limitHeapRetention's: keeps freed memory for reuse.
/// Brick-sized buffers (a decoded brick's cells, counts and attributes) are freed and allocated
/// again on every thread; served by mmap, or by thread arenas that hand their freed top back to
/// the kernel, each costs a first touch of its pages again, the kernel zeroing them: 0.8 M page
/// faults for the first image of a 500 M particle frame, 2 s of system time (0.11 M and 0.7 s
/// with this and decodeBrick's reused buffer). Peak RSS grew by 1%. Call at the start of a
/// command that renders.
inline void keepHeapForReuse() {
  ::mallopt(M_MMAP_THRESHOLD, 32 << 20);
  ::mallopt(M_TRIM_THRESHOLD, 256 << 20);
  ::mallopt(M_TOP_PAD, 64 << 20);
}

}  // namespace flipscope
