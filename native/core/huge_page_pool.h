// Huge-page mappings released by one commit, kept for the next. A commit's traced arrays (the
// triangle blocks and the wide nodes: 55 MB at a million triangles) are mapped fresh
// (huge_page_allocator.h), and the kernel zeroes every page on first touch: 16 % of the CPU time
// of a 1M-triangle LBVH commit went to that zeroing. Rebuilding a scene (an animation's frames,
// the viewport's edits, a benchmark's repeats) frees arrays of the same sizes as it makes, so the
// mappings freed are kept here, up to a bound, and the next allocation that fits takes one:
// backed by huge pages, and faulted in as far as its last owner wrote it (a commit's arrays are
// written whole). What glibc does for smaller blocks (its heap keeps freed memory), but bounded:
// bound_bytes() at most stay mapped once every scene is gone (glibc's heap had grown without bound
// here; huge_page_allocator.h). The allocator also empties the pool and retries when the kernel
// refuses a new mapping, so what is kept is given back before an allocation fails for want of it.
#pragma once

#include <cstddef>

namespace toyrt::huge_page_pool {

// At most bound_bytes(), in at most kPoolSlots mappings, are kept: a 32nd of the machine's memory,
// from 256 MB to 1 GB (768 MB on 24 GB: all of a 4M-triangle LBVH commit's arrays and temporaries,
// about 470 MB; that commit took 249-251 ms with this bound, 296-305 ms with a 256 MB one).
inline constexpr int kPoolSlots = 12;
size_t bound_bytes() noexcept;

// A kept mapping of `bytes` to twice that (`bytes` a multiple of the huge page), cut to exactly
// `bytes` (the tail beyond is unmapped), or nullptr. The smallest that fits, and none more than
// twice as large: a small array does not take (and cut) a large one's mapping while that one's
// owner is about to come back for it.
void* take(size_t bytes) noexcept;

// Keeps the mapping [p, p + bytes) for a later take(); the oldest kept ones are unmapped to stay
// within the bounds. False (the caller unmaps it) for a mapping over bound_bytes() (or none).
bool keep(void* p, size_t bytes) noexcept;

// Bytes kept now (for tests and memory reports).
size_t kept_bytes() noexcept;

// Unmaps everything kept (the allocator, when a new mapping fails; toyrt.release_cached_memory();
// tests); returns how many bytes that was.
size_t release() noexcept;

}  // namespace toyrt::huge_page_pool
