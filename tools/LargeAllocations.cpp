// The flipscope command's operator new: malloc, and while huge page advice is on
// (core/HugePageAdvice.h, chosen at start by main()), allocations of kHugePageBytes and
// more advised MADV_HUGEPAGE: the particle columns, key batches, brick scratch and frame
// images, which fill in one page fault per 2 MiB instead of one per 4 KiB. What glibc's
// `glibc.malloc.hugetlb=1` tunable does for every malloc, for what we allocate.
//
// Contract: memory comes from malloc, so libstdc++'s operator delete (free) releases it, and
// its nothrow and aligned forms are unchanged. Sanitizer builds keep their own operator new.
#include <cstdlib>
#include <new>

#include "core/HugePageAdvice.h"

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define FLIPSCOPE_SANITIZER_NEW 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define FLIPSCOPE_SANITIZER_NEW 1
#endif

#ifndef FLIPSCOPE_SANITIZER_NEW
// noinline: inlined under LTO, GCC would take malloc's pointer freed by operator delete for a
// mismatch (-Wmismatched-new-delete).
__attribute__((noinline)) void* operator new(std::size_t bytes) {
  void* p = std::malloc(bytes ? bytes : 1);
  if (!p) throw std::bad_alloc();
  if (bytes >= flipscope::kHugePageBytes && flipscope::hugePageAdviceOn()) flipscope::adviseHugePages(p, bytes);
  return p;
}

void* operator new[](std::size_t bytes) { return ::operator new(bytes); }
#endif
