// UninitializedVector<T>: a std::vector whose resize() leaves new trivial elements
// uninitialized, for large buffers that are overwritten right away (sort keys, scratch):
// no memset, and pages are touched only once, by the writer.
//
// Huge pages are not this allocator's business: whether large allocations ask for them is
// chosen per machine for the whole process (core/HugePageAdvice.h).
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
