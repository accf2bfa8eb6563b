// Light linking (Blender 4.0+, as Cycles interprets it): which objects a light lights, and which
// objects shadow it. Blender groups the objects named by the lights' receiver (blocker)
// collections into at most 64 sets, one per distinct combination of include / exclude entries
// (set 0: the objects no collection names); each instance carries the index of its receiver set
// and of its blocker set, each light a bitmask of the receiver sets it lights and one of the
// blocker sets whose objects stop its shadow rays. The add-on computes both (light_linking.py);
// a scene without linking keeps every mask full and pays nothing (docs/lights.md).
#pragma once

#include <cstdint>

namespace toyrt {

inline constexpr int kLightSets = 64;
inline constexpr uint64_t kAllLightSets = ~uint64_t(0);

// Whether a light whose membership mask is `sets` reaches set `set` (of a receiver or a blocker).
inline bool in_light_sets(uint64_t sets, uint8_t set) { return ((sets >> set) & 1u) != 0; }

}  // namespace toyrt
