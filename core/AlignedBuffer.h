// AlignedBuffer: heap memory aligned to kDirectBlock, the unit of direct (O_DIRECT) I/O, for
// spill files (preprocess/DirectFile.h, preprocess/SpillBuckets.h) and input files read around
// the page cache (preprocess/particles/DirectReadAhead.h); in huge pages from 2 MiB up.
#pragma once

#include <cstddef>
#include <memory>

namespace flipscope {

/// Block size of direct I/O: buffer addresses, lengths and file offsets are multiples of it
/// (4096 covers every logical block size Linux file systems use).
inline constexpr std::size_t kDirectBlock = 4096;

/// Whether AlignedBuffers of kHugePageBytes (core/HugePageAdvice.h) and more ask for huge pages,
/// given FLIPSCOPE_HUGE_PAGES's value: unless it is "off" (an unreadable value counts as unset;
/// main() reports it).
bool alignedBuffersAskForHugePages(const char* hugePagesVariable);

/// AlignedBuffers of kHugePageBytes up to this size ask for huge pages whatever the process's
/// first-touch advice (hugePageAdviceOn); larger ones only where it is on: on a VM where huge
/// pages fill slowly (core/HugePageAdvice.h), hundreds of megabytes of them would cost more at
/// their first touch than their reads save. The read-ahead's pieces and the spill files' buffers
/// are 2 MiB or less; a spill bucket's record buffer may be hundreds of megabytes.
inline constexpr std::size_t kAlwaysHugeBufferBytes = std::size_t(32) << 20;

/// A heap buffer aligned to kDirectBlock. One of kHugePageBytes or more (see
/// kAlwaysHugeBufferBytes) starts on a huge page's boundary, spans whole huge pages and asks for
/// them (MADV_HUGEPAGE), unless FLIPSCOPE_HUGE_PAGES is off: on the development VM (virtio disk) a
/// direct read into huge pages took half as long as one into 4 KiB pages, whose every page the
/// device maps (1.2 GB in 2 MiB reads: 0.41 to 0.45 s against 0.88 to 0.93 s, alternating,
/// 2026-12-07), and convert's read of an uncached 100 M particle frame, spacing and domain given,
/// took 0.74 to 0.89 s against 1.24 to 1.63 s. The rounding adds less than a huge page. The heap
/// range such a buffer leaves on free keeps its advice, so later allocations there may be given
/// huge pages too.
class AlignedBuffer {
 public:
  AlignedBuffer() = default;
  explicit AlignedBuffer(std::size_t bytes);  ///< rounded up to kDirectBlock; contents undefined
  std::byte* data() const { return mData.get(); }
  std::size_t size() const { return mSize; }

 private:
  struct Free {
    void operator()(std::byte* p) const;
  };
  std::unique_ptr<std::byte, Free> mData;
  std::size_t mSize = 0;
};

}  // namespace flipscope
