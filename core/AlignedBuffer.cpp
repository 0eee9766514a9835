// AlignedBuffer (see the header).
#include "core/AlignedBuffer.h"

#include <cstdlib>
#include <new>

namespace flipscope {

AlignedBuffer::AlignedBuffer(std::size_t bytes) : mSize((bytes + kDirectBlock - 1) / kDirectBlock * kDirectBlock) {
  if (mSize == 0) return;
  auto* p = static_cast<std::byte*>(std::aligned_alloc(kDirectBlock, mSize));
  if (!p) throw std::bad_alloc();
  mData.reset(p);
}

void AlignedBuffer::Free::operator()(std::byte* p) const { std::free(p); }

}  // namespace flipscope
