// The pool of released huge-page mappings (native/core/huge_page_pool.h): what it hands back, and
// its bounds.
#include "core/huge_page_pool.h"
#include "core/huge_page_allocator.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <vector>

namespace toyrt {
namespace {

using Bytes = std::vector<uint8_t, HugePageAllocator<uint8_t>>;
constexpr size_t kMB = size_t(1) << 20;

#if defined(__linux__)
TEST(HugePagePool, AFreedArrayIsTheNextOfItsSize) {
  huge_page_pool::release();
  uintptr_t first;
  {
    Bytes a(10 * kMB);
    std::memset(a.data(), 7, a.size());
    first = reinterpret_cast<uintptr_t>(a.data());
  }
  EXPECT_EQ(huge_page_pool::kept_bytes(), 10 * kMB);  // 10 MB: five huge pages exactly
  Bytes b(9 * kMB + 1);                               // rounds up to the same five huge pages
  EXPECT_EQ(reinterpret_cast<uintptr_t>(b.data()), first);
  EXPECT_EQ(huge_page_pool::kept_bytes(), 0u);
  // Usable whole: written and read back at both ends.
  b.front() = 1, b.back() = 2;
  EXPECT_EQ(b.front() + b.back(), 3);
}

TEST(HugePagePool, TheSmallestFittingMappingIsTakenAndCut) {
  huge_page_pool::release();
  uintptr_t small_one, large_one;
  {
    Bytes small(4 * kMB), large(10 * kMB), huge(40 * kMB);
    small_one = reinterpret_cast<uintptr_t>(small.data()), large_one = reinterpret_cast<uintptr_t>(large.data());
  }
  EXPECT_EQ(huge_page_pool::kept_bytes(), 54 * kMB);
  {
    Bytes c(3 * kMB);  // 4 MB: the small mapping, not the larger ones
    EXPECT_EQ(reinterpret_cast<uintptr_t>(c.data()), small_one);
    Bytes d(6 * kMB);  // the 10 MB one, cut to 6 MB (its 4 MB tail unmapped); never the 40 MB one
    EXPECT_EQ(reinterpret_cast<uintptr_t>(d.data()), large_one);
    EXPECT_EQ(huge_page_pool::kept_bytes(), 40 * kMB);
    std::memset(d.data(), 1, d.size());
    Bytes e(2 * kMB);  // nothing kept is at most twice as large: a new mapping
    EXPECT_NE(reinterpret_cast<uintptr_t>(e.data()), small_one);
    EXPECT_EQ(huge_page_pool::kept_bytes(), 40 * kMB);
  }
  // Freed again, each is kept at the size it was cut to.
  EXPECT_EQ(huge_page_pool::kept_bytes(), (40 + 4 + 6 + 2) * kMB);
  huge_page_pool::release();
}

TEST(HugePagePool, StaysWithinItsBounds) {
  huge_page_pool::release();
  const size_t bound = huge_page_pool::bound_bytes();
  EXPECT_GE(bound, 256 * kMB);
  EXPECT_LE(bound, 1024 * kMB);
  {  // over the byte bound on its own: unmapped, not kept (mapped, never touched)
    Bytes huge(bound + 2 * kMB);
  }
  EXPECT_EQ(huge_page_pool::kept_bytes(), 0u);
  // More mappings than slots: the oldest go.
  {
    std::vector<Bytes> arrays;
    for (int k = 0; k < huge_page_pool::kPoolSlots + 3; ++k) arrays.emplace_back(2 * kMB);
  }
  EXPECT_EQ(huge_page_pool::kept_bytes(), size_t(huge_page_pool::kPoolSlots) * 2 * kMB);
  // More bytes than the bound: four arrays of a bit over a third of it, of which the two newest
  // stay (the slots' small ones go first, being older).
  const size_t third = (bound / 3 / (2 * kMB) + 1) * 2 * kMB;  // whole huge pages
  {
    std::vector<Bytes> arrays;
    for (int k = 0; k < 4; ++k) arrays.emplace_back(third);
  }
  EXPECT_EQ(huge_page_pool::kept_bytes(), 2 * third);
  EXPECT_EQ(huge_page_pool::release(), 2 * third);  // what it unmapped
  EXPECT_EQ(huge_page_pool::kept_bytes(), 0u);
}
#endif

TEST(HugePagePool, SmallArraysNeverEnterIt) {
  huge_page_pool::release();
  { Bytes a(kMB); }
  EXPECT_EQ(huge_page_pool::kept_bytes(), 0u);
}

}  // namespace
}  // namespace toyrt
