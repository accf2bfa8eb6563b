// The closed set of materials, dispatched statically (std::variant): the integrator switches on
// the kind once per hit, so a scene without refractive materials never runs refraction code.
#pragma once

#include "materials/lambert.h"
#include "materials/refraction.h"

#include <variant>

namespace toyrt {

using Material = std::variant<Lambert, PerfectRefraction, FresnelDielectric>;

}  // namespace toyrt
