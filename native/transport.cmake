# Sources of the light-transport building blocks, added to toyrt_core (headers beside them):
# camera/ (Blender's camera), sampling/ (header only: counter-based RNG, Sobol-Owen pattern,
# warps, frames), lights/ (point, sphere and area lights, their samplers, the light selector),
# materials/ (Lambert, textures, refraction and Fresnel), render/ (the integrator and the tiled image
# loop built on them).
target_sources(toyrt_core PRIVATE
  camera/camera.cpp
  lights/area_light.cpp
  lights/light_selector.cpp
  lights/point_light.cpp
  lights/spherical_rectangle.cpp
  materials/refraction.cpp
  materials/texture.cpp
  render/integrator.cpp
  render/renderer.cpp
)
