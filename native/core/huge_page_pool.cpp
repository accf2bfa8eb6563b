#include "core/huge_page_pool.h"

#include <cstdint>
#include <mutex>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

#include <algorithm>

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

Pool& pool() {
  static Pool p;
  return p;
}

void unmap(void* p, size_t bytes) {
#if defined(__linux__)
  munmap(p, bytes);
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
  Pool& pl = pool();
  std::lock_guard<std::mutex> lock(pl.mutex);
  Slot* best = nullptr;
  for (Slot& s : pl.slots)
    if (s.p && s.bytes >= bytes && (!best || s.bytes < best->bytes)) best = &s;
  if (!best) return nullptr;
  void* p = best->p;
  if (best->bytes > bytes) unmap(static_cast<char*>(p) + bytes, best->bytes - bytes);
  pl.bytes -= best->bytes;
  *best = Slot{};
  return p;
#else
  return nullptr;
#endif
}

bool keep(void* p, size_t bytes) noexcept {
#if defined(__linux__)
  const size_t bound = bound_bytes();
  if (bytes > bound) return false;
  Pool& pl = pool();
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
      return true;
    }
    // Full, by count or by bytes (then something is kept, since bytes <= bound): the oldest goes.
    unmap(oldest->p, oldest->bytes);
    pl.bytes -= oldest->bytes;
    *oldest = Slot{};
  }
#else
  return false;
#endif
}

size_t kept_bytes() noexcept {
  Pool& pl = pool();
  std::lock_guard<std::mutex> lock(pl.mutex);
  return pl.bytes;
}

void release() noexcept {
  Pool& pl = pool();
  std::lock_guard<std::mutex> lock(pl.mutex);
  for (Slot& s : pl.slots)
    if (s.p) {
      unmap(s.p, s.bytes);
      s = Slot{};
    }
  pl.bytes = 0;
}

}  // namespace toyrt::huge_page_pool
