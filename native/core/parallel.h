// Runs work on a chosen number of threads: TBB's default arena for 0 (all cores), else an arena
// limited to `threads`. Every parallel entry point of the core takes its thread count this way.
#pragma once

#include <tbb/task_arena.h>

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

}  // namespace toyrt
