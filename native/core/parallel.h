// Runs work on a chosen number of threads: TBB's default arena for 0 (all cores), else an arena
// limited to `threads`. Every parallel entry point of the core takes its thread count this way.
#pragma once

#include <tbb/task_arena.h>

#include <utility>

namespace toyrt {

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
