// A fixed-size array whose elements are left unconstructed until a parallel loop writes them.
// For the commit's large temporaries: a std::vector constructs (or zeroes) every element on one
// thread before the parallel loop that fills it, and at a million triangles that serial pass,
// most of it the kernel supplying 36 MB of fresh pages, was 15 ms of the 2-thread commit. Here
// the threads that fill the array also touch its fresh pages first, each its own part.
//
// The memory comes from HugePageAllocator: from 2 MB up, huge pages, and the mappings the last
// commit released (huge_page_pool.h), already faulted in. From malloc, a repeated 1M-triangle SAH
// commit spent about a tenth of its time in the kernel's zeroing of fresh pages for these
// temporaries: glibc maps blocks above its threshold (which rises to at most 32 MB) afresh each
// time, and hands a large freed top of its heap back to the system.
//
// Elements are created with emplace() (placement new); T must be trivially destructible, since
// nothing here knows which elements were made.
#pragma once

#include "core/huge_page_allocator.h"

#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>

namespace toyrt {

template <class T>
class UninitializedArray {
  static_assert(std::is_trivially_destructible_v<T>, "elements are never destroyed one by one");

 public:
  UninitializedArray() = default;
  explicit UninitializedArray(size_t n) : data_(n ? HugePageAllocator<T>().allocate(n) : nullptr, Free{n}), size_(n) {}

  template <class... Args>
  void emplace(size_t i, Args&&... args) {
    ::new (static_cast<void*>(data_.get() + i)) T(std::forward<Args>(args)...);
  }
  // Only elements made with emplace() may be read.
  const T& operator[](size_t i) const { return data_[i]; }
  const T* data() const { return data_.get(); }
  T* data() { return data_.get(); }
  size_t size() const { return size_; }

 private:
  struct Free {
    size_t n = 0;
    void operator()(T* p) const noexcept { HugePageAllocator<T>().deallocate(p, n); }
  };
  std::unique_ptr<T[], Free> data_;
  size_t size_ = 0;
};

}  // namespace toyrt
