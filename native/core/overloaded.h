// An overload set from lambdas, for std::visit over the closed variants (Light, Material): one
// lambda per alternative, so a type added to a variant without its case fails to compile.
#pragma once

namespace toyrt {

template <class... Cases>
struct Overloaded : Cases... {
  using Cases::operator()...;
};
template <class... Cases>
Overloaded(Cases...) -> Overloaded<Cases...>;

}  // namespace toyrt
