#include "python/render_binding.h"

#include <cmath>
#include <set>

namespace toyrt::binding {

namespace {
py::array_t<double, py::array::c_style | py::array::forcecast> numbers(py::handle obj, const char* name) {
  const py::array a = try_array(obj);
  if (!a || !is_numeric(a)) throw py::type_error(std::string(name) + " must be numbers");
  return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
}

Vec3 three(py::handle obj, const char* name) {
  auto a = numbers(obj, name);
  if (a.size() != 3) throw py::value_error(std::string(name) + " must have 3 components");
  Vec3 v(float(a.data()[0]), float(a.data()[1]), float(a.data()[2]));
  if (!is_finite(v)) throw py::value_error(std::string(name) + " is not finite");
  return v;
}
}  // namespace

Vec3 to_color(py::handle obj, const char* name) {
  const Vec3 c = three(obj, name);
  if (c.x < 0 || c.y < 0 || c.z < 0) throw py::value_error(std::string(name) + " must not be negative");
  return c;
}

Vec3 to_point(py::handle obj, const char* name) { return three(obj, name); }

Mat4 to_matrix4(py::handle obj, const char* name) {
  auto a = numbers(obj, name);
  if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4) throw py::value_error(std::string(name) + " must have shape (4, 4)");
  Mat4 m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) {
      const double v = a.data()[4 * r + c];
      if (!std::isfinite(v)) throw py::value_error(std::string(name) + " is not finite");
      m[c][r] = float(v);
    }
  return m;
}

CameraParams to_camera(const py::dict& camera) {
  static const std::set<std::string> known = {
      "type", "lens", "sensor_width", "sensor_height", "sensor_fit", "shift_x", "shift_y", "clip_start", "clip_end",
      "ortho_scale", "resolution_x", "resolution_y", "resolution_percentage", "pixel_aspect_x", "pixel_aspect_y",
      "use_border", "border_min_x", "border_min_y", "border_max_x", "border_max_y", "matrix_world"};
  CameraParams p;
  for (auto item : camera) {
    const std::string key = py::str(item.first);
    if (!known.count(key)) throw py::value_error("camera: unknown setting '" + key + "'");
    py::handle v = item.second;
    auto number = [&]() {
      try {
        return v.cast<double>();
      } catch (const py::cast_error&) {
        throw py::type_error("camera: '" + key + "' must be a number");
      }
    };
    // A whole count: converting a double outside int's range (or NaN) to int is undefined
    // behaviour, so it is checked first and refused by name.
    auto count = [&]() {
      const double x = number();
      if (!(x >= 0.0 && x <= 1.0e9) || x != std::floor(x))
        throw py::value_error("camera: '" + key + "' must be a whole number from 0 to 1e9, got " + std::to_string(x));
      return int(x);
    };
    if (key == "type") {
      const std::string t = py::str(v);
      if (t == "PERSP") p.type = CameraType::Perspective;
      else if (t == "ORTHO") p.type = CameraType::Orthographic;
      else throw py::value_error("camera: type must be 'PERSP' or 'ORTHO', got '" + t + "'");
    } else if (key == "sensor_fit") {
      const std::string f = py::str(v);
      if (f == "AUTO") p.sensor_fit = SensorFit::Auto;
      else if (f == "HORIZONTAL") p.sensor_fit = SensorFit::Horizontal;
      else if (f == "VERTICAL") p.sensor_fit = SensorFit::Vertical;
      else throw py::value_error("camera: sensor_fit must be 'AUTO', 'HORIZONTAL' or 'VERTICAL', got '" + f + "'");
    } else if (key == "matrix_world") {
      p.matrix_world = to_matrix4(v, "camera matrix_world");
    } else if (key == "use_border") {
      p.use_border = PyObject_IsTrue(v.ptr()) == 1;
    } else if (key == "resolution_x") {
      p.resolution_x = count();
    } else if (key == "resolution_y") {
      p.resolution_y = count();
    } else if (key == "resolution_percentage") {
      p.resolution_percentage = count();
    } else {
      const float x = float(number());
      if (key == "lens") p.lens = x;
      else if (key == "sensor_width") p.sensor_width = x;
      else if (key == "sensor_height") p.sensor_height = x;
      else if (key == "shift_x") p.shift_x = x;
      else if (key == "shift_y") p.shift_y = x;
      else if (key == "clip_start") p.clip_start = x;
      else if (key == "clip_end") p.clip_end = x;
      else if (key == "ortho_scale") p.ortho_scale = x;
      else if (key == "pixel_aspect_x") p.pixel_aspect_x = x;
      else if (key == "pixel_aspect_y") p.pixel_aspect_y = x;
      else if (key == "border_min_x") p.border_min_x = x;
      else if (key == "border_min_y") p.border_min_y = x;
      else if (key == "border_max_x") p.border_max_x = x;
      else if (key == "border_max_y") p.border_max_y = x;
    }
  }
  return p;
}

AreaShape to_area_shape(const std::string& shape) {
  if (shape == "RECTANGLE") return AreaShape::Rectangle;
  if (shape == "SQUARE") return AreaShape::Square;
  if (shape == "DISK") return AreaShape::Disk;
  if (shape == "ELLIPSE") return AreaShape::Ellipse;
  throw py::value_error("area light shape must be 'RECTANGLE', 'SQUARE', 'DISK' or 'ELLIPSE', got '" + shape + "'");
}

AreaSampling to_area_sampling(const std::string& name) {
  if (name == "solid_angle") return AreaSampling::SolidAngle;
  if (name == "area") return AreaSampling::Area;
  throw py::value_error("area_light_sampling must be 'solid_angle' or 'area', got '" + name + "'");
}

}  // namespace toyrt::binding
