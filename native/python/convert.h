// Converters from Python values to the core's plain data: numpy arrays (points, triangles, the
// (4, 4) matrix, per-ray values, shading arrays, texture pixels), the camera dict, colours.
// They check types and shapes, raising TypeError / ValueError that name the argument; the
// values themselves (finite, in range, known ids) are the core's to check (std::invalid_argument,
// which the module turns into ValueError).
#pragma once

#include "camera/camera.h"
#include "core/params.h"
#include "geometry/mesh.h"
#include "materials/texture.h"
#include "scene/mesh_shading.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <string>
#include <vector>

namespace toyrt::binding {

namespace py = pybind11;
using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

[[noreturn]] void throw_copy_failed(py::handle a, const char* name);
// A C-contiguous copy (or view) of `a` as T. pybind11's ensure() answers a failed copy with a
// null array and Python's error cleared; for an array of numbers that failure is an allocation
// (a broadcast view of a terabyte, say), and a null array dereferenced here crashed Python. So
// this raises MemoryError naming `name` instead, and TypeError for an array that holds no numbers.
template <class T>
py::array_t<T, py::array::c_style | py::array::forcecast> contiguous(py::handle a, const char* name) {
  using Array = py::array_t<T, py::array::c_style | py::array::forcecast>;
  Array out = Array::ensure(a);
  if (!out) throw_copy_failed(a, name);
  // numpy calls a view C-contiguous at any address (np.frombuffer at an odd offset, a field of a
  // packed record), and ensure() passes it through; the core reads T through T pointers, which
  // must be aligned (a vectorised loop may assume it), so such a view is copied (numpy aligns it).
  if (reinterpret_cast<uintptr_t>(out.data()) % alignof(T) != 0) out = Array::ensure(out.attr("copy")());
  return out;
}

// The object as a numpy array (converting lists and the like), or a null array when it cannot be.
py::array try_array(py::handle obj);
// Whether an array holds numbers (float, signed or unsigned integer).
bool is_numeric(const py::array& a);
// "(3, 4)", "(5,)": shapes in error messages.
std::string shape_of(const py::array& a);

// Any array-like of numbers as a C-contiguous float32 array of shape (N, 3).
FloatArray as_points(py::handle obj, const char* name);
std::vector<Vec3> to_vec3s(const FloatArray& a);
// Query points or ray origins/directions of any leading shape (..., 3), an image's (H, W, 3) for
// instance: flattened to a float32 (N, 3); `leading` receives the leading shape for the answers.
FloatArray as_point_grid(py::handle obj, const char* name, std::vector<py::ssize_t>& leading);
// `a` (N, ...) reshaped to leading + its trailing dimensions: answers in the queries' shape.
py::array shaped(const py::array& a, const std::vector<py::ssize_t>& leading);
// (M, 3) integer vertex indices; negative or beyond 32 bits refused by triangle.
std::vector<Triangle> to_triangles(py::handle obj);
// The one matrix converter: a (4, 4) row-major matrix (Blender's matrix_world layout) as GLM's
// column-major Mat4. Its values are checked by whoever uses it (instances, lights, the camera).
Mat4 to_matrix(py::handle obj, const char* name);
// Three numbers (a colour, a position).
Vec3 to_vec3(py::handle obj, const char* name);

// tnear / tfar: a number applied to every ray (stride 0), or one value per ray.
struct PerRay {
  FloatArray storage;
  float scalar = 0.0f;
  const float* data = nullptr;
  size_t stride = 0;
};
PerRay per_ray(py::handle obj, size_t count, const char* name);

// Shading attributes from their Python forms: per corner (M, 3, k) or per vertex (N, k); material
// ids one int or (M,) ints; tangents (M, 3, 4) or (N, 4). None: the mesh does not have the attribute.
MeshShading to_shading(size_t vertex_count, const std::vector<Triangle>& tris, py::handle normals, py::handle uvs,
                       py::handle material_ids, py::handle tangents = py::none());
// (height, width, 3 or 4) float 0..1 or uint8 pixels, rows from the bottom.
Texture to_texture(py::handle pixels, bool srgb);
CameraParams to_camera(const py::dict& camera);
// Keyword arguments as Params, by the value's Python type: bool -> bool; int, float -> number;
// str -> text; an array-like of 3 numbers -> Vec3; of shape (4, 4) -> Mat4 (row-major, as
// to_matrix); None -> left out (the type's default). Anything else: TypeError naming the argument.
Params to_params(const py::dict& kwargs);

}  // namespace toyrt::binding
