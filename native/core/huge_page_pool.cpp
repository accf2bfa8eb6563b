#include "core/huge_page_pool.h"

#include <algorithm>
#include <cstdint>
#include <mutex>
#include <utility>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace toyrt::huge_page_pool {
namespace {

struct Slot {
  void* p = nullptr;
  size_t bytes = 0;
  uint64_t age = 0;  // when it was kept: the smallest is the oldest
};

// A fixed table, not a container: keep() runs inside deallocate(), which may not throw.
struct Pool {
  std::mutex mutex;
  Slot slots[kPoolSlots];
  size_t bytes = 0;
  uint64_t clock = 0;
};

// Never destroyed: arrays in other static objects may be freed into it at exit, after it.
Pool& pool() {
  static Pool* p = new Pool;
  return *p;
}

void unmap(void* p, size_t bytes) {
#if defined(__linux__)
  if (p && bytes) munmap(p, bytes);
#endif
}

}  // namespace

size_t bound_bytes() noexcept {
  static const size_t bound = [] {
    constexpr size_t kMin = size_t(256) << 20, kMax = size_t(1) << 30;
#if defined(__linux__)
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (pages > 0 && page > 0) return std::clamp(size_t(pages) * size_t(page) / 32, kMin, kMax);
#endif
    return kMin;
  }();
  return bound;
}

void* take(size_t bytes) noexcept {
#if defined(__linux__)
  if (bytes == 0) return nullptr;
  Pool& pl = pool();
  void* p;
  Slot cut;  // the tail beyond `bytes`, unmapped outside the lock (other threads allocate too)
  {
    std::lock_guard<std::mutex> lock(pl.mutex);
    Slot* best = nullptr;
    for (Slot& s : pl.slots)
      if (s.p && s.bytes >= bytes && s.bytes <= 2 * bytes && (!best || s.bytes < best->bytes)) best = &s;
    if (!best) return nullptr;
    p = best->p;
    cut = Slot{static_cast<char*>(p) + bytes, best->bytes - bytes};
    pl.bytes -= best->bytes;
    *best = Slot{};
  }
  unmap(cut.p, cut.bytes);
  return p;
#else
  return nullptr;
#endif
}

bool keep(void* p, size_t bytes) noexcept {
#if defined(__linux__)
  const size_t bound = bound_bytes();
  if (!p || bytes == 0 || bytes > bound) return false;
  Pool& pl = pool();
  Slot evicted[kPoolSlots];  // unmapped outside the lock
  int n_evicted = 0;
  {
    std::lock_guard<std::mutex> lock(pl.mutex);
    for (;;) {
      Slot* free_slot = nullptr;
      Slot* oldest = nullptr;
      for (Slot& s : pl.slots) {
        if (!s.p)
          free_slot = free_slot ? free_slot : &s;
        else if (!oldest || s.age < oldest->age)
          oldest = &s;
      }
      if (free_slot && pl.bytes + bytes <= bound) {
        *free_slot = Slot{p, bytes, ++pl.clock};
        pl.bytes += bytes;
        break;
      }
      // Full, by count or by bytes (then something is kept, since bytes <= bound): the oldest goes.
      evicted[n_evicted++] = *oldest;
      pl.bytes -= oldest->bytes;
      *oldest = Slot{};
    }
  }
  for (int i = 0; i < n_evicted; ++i) unmap(evicted[i].p, evicted[i].bytes);
  return true;
#else
  return false;
#endif
}

size_t kept_bytes() noexcept {
  Pool& pl = pool();
  std::lock_guard<std::mutex> lock(pl.mutex);
  return pl.bytes;
}

size_t release() noexcept {
  Pool& pl = pool();
  Slot all[kPoolSlots];
  size_t bytes;
  {
    std::lock_guard<std::mutex> lock(pl.mutex);
    std::copy(std::begin(pl.slots), std::end(pl.slots), all);
    std::fill(std::begin(pl.slots), std::end(pl.slots), Slot{});
    bytes = std::exchange(pl.bytes, 0);
  }
  for (const Slot& s : all) unmap(s.p, s.bytes);
  return bytes;
}

}  // namespace toyrt::huge_page_pool
