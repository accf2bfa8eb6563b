// What the material tests share: a scene without textures, the shading context over it, and
// Params written as a brace list ({{"roughness", 0.4f}, {"ior", 1.5}}).
#pragma once

#include "core/params.h"
#include "materials/material.h"
#include "materials/texture.h"

#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

namespace toyrt::testing {

inline const std::vector<Texture> kNoTextures;
inline const MaterialContext kContext{&kNoTextures};

inline Params args(std::initializer_list<std::pair<std::string, Params::Value>> values) {
  return Params(std::vector<std::pair<std::string, Params::Value>>(values));
}

}  // namespace toyrt::testing
