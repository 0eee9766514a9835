// UninitializedVector<T>: a std::vector whose resize() leaves new trivial elements
// uninitialized, for large buffers that are overwritten right away (sort keys, scratch):
// no memset, and pages are touched only once, by the writer.
//
// No transparent huge pages: on the virtual machine we measured (the development machine,
// 2026-12-03, `madvise` THP), the first touch of 400 MB advised MADV_HUGEPAGE took 0.3 to 3.1 s
// and of 400 MB of plain pages 0.13 s, every time (most likely because a 2 MiB page comes from
// the blocks the guest has handed back to its host, which must back all of it again).
#pragma once

#include <memory>
#include <new>
#include <type_traits>
#include <vector>

namespace flipscope {

template <class T>
struct DefaultInitAllocator : std::allocator<T> {
  static_assert(std::is_trivially_default_constructible_v<T>);
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() = default;
  template <class U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

template <class T>
using UninitializedVector = std::vector<T, DefaultInitAllocator<T>>;

}  // namespace flipscope
