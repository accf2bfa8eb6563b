// Runs work on a chosen number of threads: TBB's default arena for 0 (all cores), else an arena
// limited to `threads`. Every parallel entry point of the core takes its thread count this way.
#pragma once

#include <tbb/parallel_for.h>
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

// Whether the arena the caller runs on has more than one thread: the builders make no tasks
// where there is none to take them (a fork-join on one thread only costs).
inline bool several_threads() { return tbb::this_task_arena::max_concurrency() > 1; }

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

// How many chunks of chunk_size(n) cover [0, n).
inline size_t chunk_count(size_t n) { return (n + chunk_size(n) - 1) / chunk_size(n); }

// Calls work(chunk, begin, end) for every chunk of [0, n), in parallel; chunk numbers run from 0
// to chunk_count(n) - 1, so a pass can keep one result a chunk and combine them in order.
template <class F>
void for_each_chunk(size_t n, F&& work) {
  const size_t grain = chunk_size(n);
  tbb::parallel_for(size_t(0), chunk_count(n), [&](size_t c) { work(c, c * grain, std::min(n, (c + 1) * grain)); });
}

}  // namespace toyrt
