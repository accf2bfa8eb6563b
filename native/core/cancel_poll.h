// How a long call (Scene::commit, render) learns that its caller wants it stopped: a function
// the core polls on the calling thread every ~10 ms while the work runs on other threads, so a
// caller that must hold a lock to answer (Python's GIL, Blender's test_break) can answer. An
// empty function never cancels; an exception from it stops the work and reaches the caller.
#pragma once

#include <functional>

namespace toyrt {

using CancelPoll = std::function<bool()>;

}  // namespace toyrt
