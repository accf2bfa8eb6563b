// Makes one alternative of a closed std::variant (Light, Material) from its type name and its
// parameters: a fold over the variant's alternatives matching each one's `kType`, so the variant
// itself is the one table of types. Each alternative provides
//     static constexpr const char* kType;            // the name users pass ("POINT", "glass")
//     static T from_params(const Params& params);    // reads its settings, with their defaults
//     static constexpr const char* kParams;          // its parameters, for the binding's docstrings
// and a type listed in the variant without them fails to compile here.
#pragma once

#include "core/params.h"

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

namespace toyrt {

namespace detail {

template <class Variant, size_t... I>
std::string type_names(std::index_sequence<I...>) {
  const char* names[] = {std::variant_alternative_t<I, Variant>::kType...};
  std::string out;
  for (size_t i = 0; i < sizeof...(I); ++i)
    out += std::string(i == 0 ? "" : i + 1 == sizeof...(I) ? " or " : ", ") + "'" + names[i] + "'";
  return out;
}

template <class Variant, size_t... I>
std::string type_docs(std::index_sequence<I...>) {
  std::string out;
  ((out += std::string("  '") + std::variant_alternative_t<I, Variant>::kType +
           "': " + std::variant_alternative_t<I, Variant>::kParams + "\n"),
   ...);
  return out;
}

template <class T, class Variant>
bool make_if_named(std::string_view type, Params& params, const char* noun, std::optional<Variant>& made) {
  if (type != T::kType) return false;
  params.set_subject(std::string(T::kType) + " " + noun);
  made.emplace(std::in_place_type<T>, T::from_params(params));
  params.check_all_read();
  return true;
}

template <class Variant, size_t... I>
std::optional<Variant> make_named(std::string_view type, Params& params, const char* noun, std::index_sequence<I...>) {
  std::optional<Variant> made;
  (make_if_named<std::variant_alternative_t<I, Variant>>(type, params, noun, made) || ...);
  return made;
}

}  // namespace detail

// "'POINT' or 'AREA'", "'diffuse', 'refraction' or 'glass'": the names, for messages and docs.
template <class Variant>
std::string type_names() {
  return detail::type_names<Variant>(std::make_index_sequence<std::variant_size_v<Variant>>{});
}

// One line per type, "  'POINT': <its kParams>", for docstrings: each type documents its
// parameters in its own header (static constexpr const char* kParams).
template <class Variant>
std::string type_docs() {
  return detail::type_docs<Variant>(std::make_index_sequence<std::variant_size_v<Variant>>{});
}

// The alternative whose kType is `type`, from `params`; `noun` names the set in messages
// ("light", "material"): "POINT light: power must be ...", "unknown argument 'powr' for a POINT
// light", "unknown light type 'SUN': expected 'POINT' or 'AREA'". Every argument must be read
// (or allowed unread: Params::allow_unread).
template <class Variant>
Variant make_from_params(std::string_view type, Params params, const char* noun, const char* kind_word = "type") {
  std::optional<Variant> made =
      detail::make_named<Variant>(type, params, noun, std::make_index_sequence<std::variant_size_v<Variant>>{});
  if (!made)
    throw std::invalid_argument("unknown " + std::string(noun) + " " + kind_word + " '" + std::string(type) +
                                "': expected " + type_names<Variant>());
  return std::move(*made);
}

}  // namespace toyrt
