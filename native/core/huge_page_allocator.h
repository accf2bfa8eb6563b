// An allocator for the large arrays that traversal reads at random: the wide BVH's nodes and the
// triangle blocks. From a few MB up, a walk through them misses the TLB on most node and block
// it reads (4 KB pages: 1,500 second-level TLB entries reach 6 MB); 2 MB pages reach 3 GB. Linux
// gives transparent huge pages to memory marked with madvise(MADV_HUGEPAGE) (the default
// setting, "madvise", gives them to nothing else), and only when the mark comes before the
// pages are first touched: so the mark is made here, at allocation, on 2 MB-aligned memory.
// Measured: the exact count queries 1.2x at 1.3M triangles (docs/queries.md).
//
// The large arrays are mapped and unmapped directly (mmap/munmap), not taken from malloc: glibc
// serves a freed mmap-sized block's successors from its heap (its mmap threshold rises to the
// freed size), where freed huge pages stay resident; a 100-frame animation that rebuilt one
// 10 MB mesh per frame grew by 60 MB that way (tests/blender/test_animation_memory.py). A freed
// mapping goes to huge_page_pool.h, which keeps a bounded few for the next commit's arrays.
#pragma once

#include "core/huge_page_pool.h"

#include <cstddef>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <utility>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace toyrt {

inline constexpr size_t kHugePageBytes = size_t(2) << 20;

template <class T>
struct HugePageAllocator {
  using value_type = T;

  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  // Arrays below one huge page: the ordinary aligned new (a huge page would waste most of it).
  static bool is_large(size_t n) { return n * sizeof(T) >= kHugePageBytes; }
  static size_t rounded_bytes(size_t n) {
    return (n * sizeof(T) + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
  }

  T* allocate(size_t n) {
    if (!is_large(n)) return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(alignof(T))));
    const size_t bytes = rounded_bytes(n);
#if defined(__linux__)
    // A mapping the last commits released (already marked, and faulted in as far as it was
    // written), else a new one.
    if (void* kept = huge_page_pool::take(bytes)) return static_cast<T*>(kept);
    // Map one huge page more than needed and unmap the unaligned head and the tail beyond.
    auto map = [&] {
      return mmap(nullptr, bytes + kHugePageBytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    };
    void* raw = map();
    if (raw == MAP_FAILED) {  // the kept mappings first give way
      huge_page_pool::release();
      raw = map();
    }
    if (raw == MAP_FAILED) throw std::bad_alloc();
    const size_t start = reinterpret_cast<size_t>(raw);
    const size_t aligned = (start + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
    if (aligned > start) munmap(raw, aligned - start);
    const size_t tail = start + bytes + kHugePageBytes - (aligned + bytes);
    if (tail) munmap(reinterpret_cast<void*>(aligned + bytes), tail);
    void* p = reinterpret_cast<void*>(aligned);
#if defined(MADV_HUGEPAGE)
    madvise(p, bytes, MADV_HUGEPAGE);  // a hint: ignored where huge pages are off
#endif
#else
    void* p = std::aligned_alloc(kHugePageBytes, bytes);
    if (!p) throw std::bad_alloc();
#endif
    return static_cast<T*>(p);
  }

  void deallocate(T* p, size_t n) noexcept {
    if (!is_large(n)) {
      ::operator delete(p, std::align_val_t(alignof(T)));
      return;
    }
#if defined(__linux__)
    if (!huge_page_pool::keep(p, rounded_bytes(n))) munmap(p, rounded_bytes(n));
#else
    std::free(p);
#endif
  }

  // Elements made without arguments (resize, emplace_back()) are default-initialised, which for
  // the trivial blocks and nodes stored here writes nothing: their builders write every field, and
  // value-initialising first zeroed the 48 MB of blocks of a 1M-triangle mesh on one thread.
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }

  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
  template <class U>
  bool operator!=(const HugePageAllocator<U>&) const noexcept {
    return false;
  }
};

}  // namespace toyrt
