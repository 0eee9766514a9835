// The process's own memory use, for the budget reports of convert and the benchmarks.
#pragma once

#include <malloc.h>
#include <sys/resource.h>

#include <cstdint>

namespace flipscope {

/// Peak resident set size of this process so far, in bytes (getrusage ru_maxrss).
inline std::uint64_t peakResidentBytes() {
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

}  // namespace flipscope
