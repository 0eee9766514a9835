// AlignedBuffer: heap memory aligned to kDirectBlock, the unit of direct (O_DIRECT) I/O, for
// spill files (preprocess/DirectFile.h) and input files read around the page cache
// (preprocess/particles/DirectReadAhead.h).
#pragma once

#include <cstddef>
#include <memory>

namespace flipscope {

/// Block size of direct I/O: buffer addresses, lengths and file offsets are multiples of it
/// (4096 covers every logical block size Linux file systems use).
inline constexpr std::size_t kDirectBlock = 4096;

/// A heap buffer aligned to kDirectBlock.
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
