// Converters from Python values to the render API's structs (camera dict, colours, enums),
// shared by module.cpp. Every failure raises a Python exception naming the argument.
#pragma once

#include "camera/camera.h"
#include "lights/light.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

namespace toyrt::binding {

namespace py = pybind11;

// The object as a numpy array (converting lists and the like), or a null array when it cannot be.
inline py::array try_array(py::handle obj) {
  try {
    return py::array::ensure(obj);
  } catch (const py::error_already_set&) {
    return py::array();
  }
}

// Whether an array holds numbers (float, signed or unsigned integer).
inline bool is_numeric(const py::array& a) {
  const char k = a.dtype().kind();
  return k == 'f' || k == 'i' || k == 'u';
}

Vec3 to_color(py::handle obj, const char* name);
Vec3 to_point(py::handle obj, const char* name);
Mat4 to_matrix4(py::handle obj, const char* name);
CameraParams to_camera(const py::dict& camera);
AreaShape to_area_shape(const std::string& shape);
AreaSampling to_area_sampling(const std::string& name);

}  // namespace toyrt::binding
