#include "python/convert.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>
#include <type_traits>

namespace toyrt::binding {

py::array try_array(py::handle obj) {
  try {
    return py::array::ensure(obj);
  } catch (const py::error_already_set&) {
    return py::array();
  }
}

void throw_copy_failed(py::handle a, const char* name) {
  const py::array source = try_array(a);
  if (source && is_numeric(source)) {
    const std::string what = std::string(name) + ": no memory for a copy of an array of shape " + shape_of(source);
    PyErr_SetString(PyExc_MemoryError, what.c_str());
    throw py::error_already_set();
  }
  throw py::type_error(std::string(name) + " must be an array of numbers");
}

bool is_numeric(const py::array& a) {
  const char k = a.dtype().kind();
  return k == 'f' || k == 'i' || k == 'u';
}

std::string shape_of(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

FloatArray as_points(py::handle obj, const char* name) {
  const py::array a = try_array(obj);
  if (!a) throw py::type_error(std::string(name) + " must be an array of shape (N, 3)");
  if (!is_numeric(a))
    throw py::type_error(std::string(name) + " must hold numbers, not dtype " + std::string(py::str(a.dtype())));
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error(std::string(name) + " must have shape (N, 3), got " + shape_of(a));
  return contiguous<float>(a, name);
}

FloatArray as_point_grid(py::handle obj, const char* name, std::vector<py::ssize_t>& leading) {
  const py::array a = try_array(obj);
  if (!a) throw py::type_error(std::string(name) + " must be an array of shape (N, 3) or (..., 3)");
  if (!is_numeric(a))
    throw py::type_error(std::string(name) + " must hold numbers, not dtype " + std::string(py::str(a.dtype())));
  if (a.ndim() < 2 || a.shape(a.ndim() - 1) != 3)
    throw py::value_error(std::string(name) + " must have shape (N, 3) or (..., 3), got " + shape_of(a));
  leading.assign(a.shape(), a.shape() + a.ndim() - 1);
  if (a.ndim() == 2) return contiguous<float>(a, name);
  return contiguous<float>(a.attr("reshape")(-1, 3), name);
}

py::array shaped(const py::array& a, const std::vector<py::ssize_t>& leading) {
  if (leading.size() == 1) return a;
  py::tuple shape(leading.size() + size_t(a.ndim() - 1));
  size_t i = 0;
  for (py::ssize_t s : leading) shape[i++] = py::int_(s);
  for (py::ssize_t k = 1; k < a.ndim(); ++k) shape[i++] = py::int_(a.shape(k));
  return a.attr("reshape")(shape);
}

std::vector<Vec3> to_vec3s(const FloatArray& a) {
  std::vector<Vec3> out(size_t(a.shape(0)));
  if (!out.empty()) std::memcpy(out.data(), a.data(), out.size() * sizeof(Vec3));
  return out;
}

namespace {
// m triangles' indices of type T (read in place where the array already is C-contiguous T),
// copied in one loop without early exits that also finds the smallest and largest index (a
// 2M-triangle add_mesh with int32 or uint32 indices: 30 ms when every index was converted to
// int64 and checked by a branch, 17 now); the culprit is looked for only when one is out of range.
template <class T>
std::vector<Triangle> indices_to_triangles(py::handle a, size_t m) {
  static_assert(sizeof(Triangle) == 3 * sizeof(uint32_t) && std::is_trivially_copyable_v<Triangle>,
                "Triangle: three packed indices");
  const auto idx = contiguous<T>(a, "triangles");
  const T* p = idx.data();
  std::vector<Triangle> out(m);
  char* bytes = reinterpret_cast<char*>(out.data());  // written index by index as bytes
  T lo = 0, hi = 0;
  for (size_t i = 0; i < 3 * m; ++i) {
    lo = std::min(lo, p[i]);
    hi = std::max(hi, p[i]);
    const uint32_t index = uint32_t(p[i]);
    std::memcpy(bytes + i * sizeof(uint32_t), &index, sizeof index);
  }
  // Each test only where the type can fail it (for uint32, neither).
  bool bad = false;
  if constexpr (std::is_signed_v<T>) bad |= lo < 0;
  if constexpr (sizeof(T) > sizeof(uint32_t)) bad |= uint64_t(hi) > UINT32_MAX;
  if (bad)
    for (size_t i = 0; i < m; ++i)
      for (int k = 0; k < 3; ++k) {
        const T v = p[3 * i + k];
        if constexpr (std::is_signed_v<T>) {
          if (v < 0) throw py::value_error("triangle " + std::to_string(i) + " has a negative vertex index");
        }
        if constexpr (sizeof(T) > sizeof(uint32_t)) {
          if (uint64_t(v) > UINT32_MAX)
            throw py::value_error("triangle " + std::to_string(i) + " has an index out of range");
        }
      }
  return out;
}
}  // namespace

std::vector<Triangle> to_triangles(py::handle obj) {
  const py::array a = try_array(obj);
  if (!a) throw py::type_error("triangles must be an integer array of shape (M, 3)");
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw py::type_error("triangles must be an integer array (vertex indices), not dtype " +
                         std::string(py::str(a.dtype())));
  if (a.ndim() != 2 || a.shape(1) != 3) throw py::value_error("triangles must have shape (M, 3), got " + shape_of(a));
  const size_t m = size_t(a.shape(0));
  // Blender's and numpy's usual index types as they are; narrower ones widened to int64.
  if (a.itemsize() == 4)
    return kind == 'u' ? indices_to_triangles<uint32_t>(a, m) : indices_to_triangles<int32_t>(a, m);
  if (kind == 'u' && a.itemsize() == 8) return indices_to_triangles<uint64_t>(a, m);
  return indices_to_triangles<int64_t>(a, m);
}

Mat4 to_matrix(py::handle obj, const char* name) {
  const py::array a = try_array(obj);
  if (!a || !is_numeric(a))
    throw py::type_error(std::string(name) + " must be a (4, 4) array of numbers (row-major world matrix)");
  if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4)
    throw py::value_error(std::string(name) + " must have shape (4, 4), got " + shape_of(a));
  auto m = contiguous<double>(a, name);
  Mat4 out;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out[c][r] = float(m.data()[4 * r + c]);
  return out;
}

Vec3 to_vec3(py::handle obj, const char* name) {
  const py::array a = try_array(obj);
  if (!a || !is_numeric(a)) throw py::type_error(std::string(name) + " must be numbers");
  auto d = contiguous<double>(a, name);
  if (d.size() != 3) throw py::value_error(std::string(name) + " must have 3 components");
  return Vec3(float(d.data()[0]), float(d.data()[1]), float(d.data()[2]));
}

// tnear / tfar: a number applied to every ray, or one value per ray.
PerRay per_ray(py::handle obj, size_t count, const char* name) {
  PerRay out;
  if (py::isinstance<py::float_>(obj) || py::isinstance<py::int_>(obj)) {
    // A Python int beyond a double's range cannot become a number: name the argument (pybind11's
    // cast only says "Unable to cast Python instance").
    const double value = PyFloat_AsDouble(obj.ptr());
    if (value == -1.0 && PyErr_Occurred()) {
      PyErr_Clear();
      throw py::value_error(std::string(name) + " is too large to be a number");
    }
    out.scalar = float(value);
  } else {
    const py::array a = try_array(obj);
    if (!a || !is_numeric(a))
      throw py::type_error(std::string(name) + " must be a number or an array of numbers, one per ray");
    if (a.ndim() == 0) {
      out.scalar = contiguous<float>(a, name).data()[0];
    } else {
      if (a.ndim() != 1 || size_t(a.shape(0)) != count)
        throw py::value_error(std::string(name) + " must be a number or have shape (" + std::to_string(count) +
                              ",), got " + shape_of(a));
      out.storage = contiguous<float>(a, name);
      out.data = out.storage.data();
      out.stride = 1;
      return out;
    }
  }
  if (std::isnan(out.scalar)) throw py::value_error(std::string(name) + " is NaN");
  out.data = &out.scalar;
  return out;
}

MeshShading to_shading(size_t vertex_count, const std::vector<Triangle>& tris, py::handle normals, py::handle uvs,
                       py::handle material_ids, py::handle tangents) {
  MeshShading sh;
  const size_t m = tris.size();
  // Writes 3 m k floats to `out` (the shading vector's storage: one copy from numpy).
  auto corners = [&](py::handle obj, int k, const char* name, auto& vec) {
    const py::array raw = try_array(obj);
    FloatArray a = raw && is_numeric(raw) ? contiguous<float>(raw, name) : FloatArray();
    if (!a) throw py::type_error(std::string(name) + " must be an array of numbers");
    const size_t floats = m * 3 * size_t(k);
    if (a.ndim() == 3 && size_t(a.shape(0)) == m && a.shape(1) == 3 && a.shape(2) == k) {
      vec.resize(3 * m);
      std::memcpy(vec.data(), a.data(), floats * sizeof(float));
    } else if (a.ndim() == 2 && size_t(a.shape(0)) == vertex_count && a.shape(1) == k) {
      vec.resize(3 * m);
      float* out = reinterpret_cast<float*>(vec.data());
      for (size_t t = 0; t < m; ++t)
        for (int c = 0; c < 3; ++c) {
          // Checked here, before the read: the Mesh that refuses such an index is built later.
          if (tris[t][c] >= vertex_count)
            throw py::value_error("triangle " + std::to_string(t) + " indexes a vertex out of range (" +
                                  std::to_string(vertex_count) + " vertices)");
          std::memcpy(out + (3 * t + size_t(c)) * size_t(k), a.data() + size_t(tris[t][c]) * size_t(k),
                      size_t(k) * sizeof(float));
        }
    } else {
      throw py::value_error(std::string(name) + " must have shape (" + std::to_string(m) + ", 3, " + std::to_string(k) +
                            ") per corner or (" + std::to_string(vertex_count) + ", " + std::to_string(k) +
                            ") per vertex, got " + shape_of(a));
    }
  };
  static_assert(sizeof(Vec3) == 3 * sizeof(float) && sizeof(Vec2) == 2 * sizeof(float) &&
                sizeof(glm::vec4) == 4 * sizeof(float));
  if (!normals.is_none()) corners(normals, 3, "normals", sh.corner_normals);
  if (!uvs.is_none()) corners(uvs, 2, "uvs", sh.corner_uvs);
  if (!tangents.is_none()) corners(tangents, 4, "tangents", sh.corner_tangents);
  if (!material_ids.is_none()) {
    if (py::isinstance<py::int_>(material_ids)) {
      const int64_t id = material_ids.cast<int64_t>();
      if (id < INT32_MIN || id > INT32_MAX) throw py::value_error("material_ids must be >= 0 and below 2^31");
      sh.material_ids.assign(m, int32_t(id));
    } else {
      const py::array a = try_array(material_ids);
      if (!a || (a.dtype().kind() != 'i' && a.dtype().kind() != 'u'))
        throw py::type_error("material_ids must be an integer or an integer array of shape (M,)");
      if (a.ndim() != 1 || size_t(a.shape(0)) != m)
        throw py::value_error("material_ids must have shape (" + std::to_string(m) + ",), got " + shape_of(a));
      auto ids = contiguous<int64_t>(a, "material_ids");
      sh.material_ids.resize(m);
      for (size_t t = 0; t < m; ++t) {
        if (ids.data()[t] < INT32_MIN || ids.data()[t] > INT32_MAX)
          throw py::value_error("material_ids must be >= 0 and below 2^31");
        sh.material_ids[t] = int32_t(ids.data()[t]);
      }
    }
  }
  return sh;
}

Texture to_texture(py::handle pixels, bool srgb) {
  const py::array a = try_array(pixels);
  if (!a) throw py::type_error("pixels must be an array of shape (height, width, 3 or 4)");
  if (a.ndim() != 3 || (a.shape(2) != 3 && a.shape(2) != 4))
    throw py::value_error("pixels must have shape (height, width, 3 or 4), got " + shape_of(a));
  const int h = int(a.shape(0)), w = int(a.shape(1)), c = int(a.shape(2));
  const ColorEncoding enc = srgb ? ColorEncoding::Srgb : ColorEncoding::Linear;
  Texture t;
  if (a.dtype().kind() == 'u' && a.itemsize() == 1) {
    auto b = contiguous<uint8_t>(a, "pixels");
    t = Texture::from_bytes(w, h, c, std::vector<uint8_t>(b.data(), b.data() + b.size()), enc);
  } else if (a.dtype().kind() == 'f') {
    auto f = contiguous<float>(a, "pixels");
    t = Texture::from_floats(w, h, c, std::vector<float>(f.data(), f.data() + f.size()), enc);
  } else {
    throw py::type_error("pixels must be float (0..1) or uint8, not dtype " + std::string(py::str(a.dtype())));
  }
  return t;
}

CameraParams to_camera(const py::dict& camera) {
  static const std::set<std::string> known = {"type",
                                              "lens",
                                              "sensor_width",
                                              "sensor_height",
                                              "sensor_fit",
                                              "shift_x",
                                              "shift_y",
                                              "clip_start",
                                              "clip_end",
                                              "ortho_scale",
                                              "resolution_x",
                                              "resolution_y",
                                              "resolution_percentage",
                                              "pixel_aspect_x",
                                              "pixel_aspect_y",
                                              "use_border",
                                              "border_min_x",
                                              "border_min_y",
                                              "border_max_x",
                                              "border_max_y",
                                              "matrix_world",
                                              "use_dof",
                                              "focus_distance",
                                              "aperture_fstop",
                                              "aperture_blades",
                                              "aperture_rotation",
                                              "aperture_ratio"};
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
      if (t == "PERSP")
        p.type = CameraType::Perspective;
      else if (t == "ORTHO")
        p.type = CameraType::Orthographic;
      else
        throw py::value_error("camera: type must be 'PERSP' or 'ORTHO', got '" + t + "'");
    } else if (key == "sensor_fit") {
      const std::string f = py::str(v);
      if (f == "AUTO")
        p.sensor_fit = SensorFit::Auto;
      else if (f == "HORIZONTAL")
        p.sensor_fit = SensorFit::Horizontal;
      else if (f == "VERTICAL")
        p.sensor_fit = SensorFit::Vertical;
      else
        throw py::value_error("camera: sensor_fit must be 'AUTO', 'HORIZONTAL' or 'VERTICAL', got '" + f + "'");
    } else if (key == "matrix_world") {
      p.matrix_world = to_matrix(v, "camera matrix_world");
    } else if (key == "use_border") {
      p.use_border = PyObject_IsTrue(v.ptr()) == 1;
    } else if (key == "use_dof") {
      p.use_dof = PyObject_IsTrue(v.ptr()) == 1;
    } else if (key == "aperture_blades") {
      p.aperture_blades = count();
    } else if (key == "resolution_x") {
      p.resolution_x = count();
    } else if (key == "resolution_y") {
      p.resolution_y = count();
    } else if (key == "resolution_percentage") {
      p.resolution_percentage = count();
    } else {
      const float x = float(number());
      if (key == "lens")
        p.lens = x;
      else if (key == "sensor_width")
        p.sensor_width = x;
      else if (key == "sensor_height")
        p.sensor_height = x;
      else if (key == "shift_x")
        p.shift_x = x;
      else if (key == "shift_y")
        p.shift_y = x;
      else if (key == "clip_start")
        p.clip_start = x;
      else if (key == "clip_end")
        p.clip_end = x;
      else if (key == "ortho_scale")
        p.ortho_scale = x;
      else if (key == "pixel_aspect_x")
        p.pixel_aspect_x = x;
      else if (key == "pixel_aspect_y")
        p.pixel_aspect_y = x;
      else if (key == "border_min_x")
        p.border_min_x = x;
      else if (key == "border_min_y")
        p.border_min_y = x;
      else if (key == "border_max_x")
        p.border_max_x = x;
      else if (key == "border_max_y")
        p.border_max_y = x;
      else if (key == "focus_distance")
        p.focus_distance = x;
      else if (key == "aperture_fstop")
        p.aperture_fstop = x;
      else if (key == "aperture_rotation")
        p.aperture_rotation = x;
      else if (key == "aperture_ratio")
        p.aperture_ratio = x;
    }
  }
  return p;
}

Params to_params(const py::dict& kwargs) {
  Params params;
  for (auto item : kwargs) {
    const std::string name = py::str(item.first);
    py::handle v = item.second;
    if (v.is_none()) continue;
    if (py::isinstance<py::bool_>(v)) {
      params.set(name, v.cast<bool>());
    } else if (py::isinstance<py::int_>(v) || py::isinstance<py::float_>(v)) {
      const double x = PyFloat_AsDouble(v.ptr());
      if (x == -1.0 && PyErr_Occurred()) {
        PyErr_Clear();
        throw py::value_error(name + " is too large to be a number");
      }
      params.set(name, x);
    } else if (py::isinstance<py::str>(v)) {
      params.set(name, v.cast<std::string>());
    } else {
      const py::array a = try_array(v);
      if (a && is_numeric(a) && a.ndim() == 0) {
        params.set(name, a.cast<double>());
      } else if (a && is_numeric(a) && a.size() == 3 && a.ndim() == 1) {
        params.set(name, to_vec3(v, name.c_str()));
      } else if (a && is_numeric(a) && a.ndim() == 2 && a.shape(0) == 4 && a.shape(1) == 4) {
        params.set(name, to_matrix(v, name.c_str()));
      } else {
        throw py::type_error(name + " must be a bool, a number, text, 3 numbers or a (4, 4) matrix, not " +
                             std::string(py::str(py::type::handle_of(v).attr("__name__"))) +
                             (a ? " of shape " + shape_of(a) : std::string()));
      }
    }
  }
  return params;
}

}  // namespace toyrt::binding
