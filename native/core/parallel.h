// Runs work on a chosen number of threads: TBB's default arena for 0 (all cores), else an arena
// limited to `threads`. Every parallel entry point of the core takes its thread count this way.
#pragma once

#include <tbb/task_arena.h>

#include <algorithm>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>

namespace toyrt {

// Throws std::invalid_argument unless threads >= 0 (0: all cores); returns it.
inline int check_threads(int threads) {
  if (threads < 0)
    throw std::invalid_argument("threads must be >= 0 (0 means all cores), got " + std::to_string(threads));
  return threads;
}

template <class F>
void run_with_threads(int threads, F&& work) {
  if (threads <= 0) {
    std::forward<F>(work)();
    return;
  }
  tbb::task_arena arena(threads);
  arena.execute(std::forward<F>(work));
}

// Primitives a chunk of a commit's fixed-chunk passes (mesh preparation, Morton codes, the radix
// scatter): 16K, fewer on small meshes, so that both cores share even a 10K-triangle commit (with
// 16K chunks its passes were one chunk each, serial; a pass's fork-join costs a few
// microseconds). A function of n alone, so the chunks, and all a pass derives from them, do not
// depend on the thread count.
inline size_t chunk_size(size_t n) { return std::clamp(n / 8, size_t(2048), size_t(16384)); }

}  // namespace toyrt
