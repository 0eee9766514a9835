// AlignedBuffer (see the header).
#include "core/AlignedBuffer.h"

#include <cstdlib>
#include <new>

#include "core/Error.h"
#include "core/HugePageAdvice.h"

namespace flipscope {

bool alignedBuffersAskForHugePages(const char* hugePagesVariable) {
  try {
    return hugePagePolicyFromEnvironment(hugePagesVariable).value_or(true);
  } catch (const InputError&) {
    return true;
  }
}

AlignedBuffer::AlignedBuffer(std::size_t bytes) : mSize((bytes + kDirectBlock - 1) / kDirectBlock * kDirectBlock) {
  if (mSize == 0) return;
  static const bool askForHugePages = alignedBuffersAskForHugePages(std::getenv("FLIPSCOPE_HUGE_PAGES"));
  const bool huge =
      mSize >= kHugePageBytes && askForHugePages && (mSize <= kAlwaysHugeBufferBytes || hugePageAdviceOn());
  const std::size_t alignment = huge ? kHugePageBytes : kDirectBlock;
  const std::size_t allocated = (mSize + alignment - 1) / alignment * alignment;
  auto* p = static_cast<std::byte*>(std::aligned_alloc(alignment, allocated));
  if (!p) throw std::bad_alloc();
  mData.reset(p);
  if (huge) adviseHugePages(p, allocated);
}

void AlignedBuffer::Free::operator()(std::byte* p) const { std::free(p); }

}  // namespace flipscope
