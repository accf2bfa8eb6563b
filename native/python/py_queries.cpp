// The exact geometric queries of PyScene (py_scene.h): convert, take the shared lock with the GIL
// released, call the core (queries/), wrap the answer.
#include "python/convert.h"
#include "python/py_scene.h"
#include "queries/point_queries.h"
#include "queries/ray_queries.h"

#include <cstring>
#include <mutex>
#include <stdexcept>

namespace toyrt::binding {
namespace {

RayBatch ray_batch(const FloatArray& org, const FloatArray& dir, const PerRay& near, const PerRay& far) {
  // (org and dir come flattened from as_point_grid; intersect's check of equal shapes is rays().)
  if (org.shape(0) != dir.shape(0))
    throw py::value_error("origins and directions must hold the same number of rays, got " +
                          std::to_string(org.shape(0)) + " and " + std::to_string(dir.shape(0)));
  return {org.data(), dir.data(), near.data, near.stride, far.data, far.stride, size_t(org.shape(0))};
}

template <class T>
py::array_t<T> to_array(const std::vector<T>& v) {
  py::array_t<T> a{py::ssize_t(v.size())};
  if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(T));
  return a;
}

}  // namespace

py::array PyScene::count_intersections(py::handle origins, py::handle directions, py::handle tnear, py::handle tfar,
                                       int threads) {
  std::vector<py::ssize_t> leading, dir_leading;
  const FloatArray org = as_point_grid(origins, "origins", leading);
  const FloatArray dir = as_point_grid(directions, "directions", dir_leading);
  const size_t n = size_t(org.shape(0));
  const PerRay near = per_ray(tnear, n, "tnear"), far = per_ray(tfar, n, "tfar");
  const RayBatch batch = ray_batch(org, dir, near, far);
  py::array_t<uint32_t> counts{py::ssize_t(n)};
  uint32_t* out = counts.mutable_data();  // taken with the GIL held
  read([&] { queries::count_intersections(scene_, batch, out, threads); });
  return shaped(counts, leading);
}

py::dict PyScene::list_intersections(py::handle origins, py::handle directions, py::handle tnear, py::handle tfar,
                                     size_t max_hits, int threads) {
  std::vector<py::ssize_t> leading;  // rays of any shape, numbered in C order
  const FloatArray org = as_point_grid(origins, "origins", leading);
  const FloatArray dir = as_point_grid(directions, "directions", leading);
  const size_t n = size_t(org.shape(0));
  const PerRay near = per_ray(tnear, n, "tnear"), far = per_ray(tfar, n, "tfar");
  const RayBatch batch = ray_batch(org, dir, near, far);
  queries::HitList hits;
  try {
    hits = read([&] { return queries::list_intersections(scene_, batch, max_hits, threads); });
  } catch (const std::length_error& e) {
    throw py::value_error(e.what());  // past max_hits: a bad argument, as Python sees it
  }
  py::dict out;
  out["ray_splits"] = to_array(hits.offsets);
  out["ray"] = to_array(hits.ray);
  out["t"] = to_array(hits.t);
  out["mesh"] = to_array(hits.mesh);
  out["instance"] = to_array(hits.instance);
  out["prim"] = to_array(hits.prim);
  out["u"] = to_array(hits.u);
  out["v"] = to_array(hits.v);
  return out;
}

py::array PyScene::compute_occupancy(py::handle points, int threads) {
  std::vector<py::ssize_t> leading;
  const FloatArray p = as_point_grid(points, "points", leading);
  const size_t n = size_t(p.shape(0));
  py::array_t<bool> inside{py::ssize_t(n)};
  static_assert(sizeof(bool) == sizeof(uint8_t));
  uint8_t* out = reinterpret_cast<uint8_t*>(inside.mutable_data());
  read([&] { queries::compute_occupancy(scene_, p.data(), n, out, threads); });
  return shaped(inside, leading);
}

py::dict PyScene::compute_closest_points(py::handle points, int threads) {
  std::vector<py::ssize_t> leading;
  const FloatArray p = as_point_grid(points, "points", leading);
  const size_t n = size_t(p.shape(0));
  py::array_t<float> closest({py::ssize_t(n), py::ssize_t(3)}), normal({py::ssize_t(n), py::ssize_t(3)});
  py::array_t<float> distance(n), u(n), v(n);
  py::array_t<int32_t> mesh(n), instance(n), prim(n);
  const queries::ClosestBatch out{closest.mutable_data(),  distance.mutable_data(), mesh.mutable_data(),
                                  instance.mutable_data(), prim.mutable_data(),     u.mutable_data(),
                                  v.mutable_data(),        normal.mutable_data()};
  read([&] { queries::compute_closest_points(scene_, p.data(), n, out, threads); });
  py::dict d;
  d["points"] = shaped(closest, leading);
  d["distance"] = shaped(distance, leading);
  d["mesh"] = shaped(mesh, leading);
  d["instance"] = shaped(instance, leading);
  d["prim"] = shaped(prim, leading);
  d["u"] = shaped(u, leading);
  d["v"] = shaped(v, leading);
  d["normal"] = shaped(normal, leading);
  return d;
}

py::array PyScene::compute_distance(py::handle points, bool signed_distance, int threads) {
  std::vector<py::ssize_t> leading;
  const FloatArray p = as_point_grid(points, "points", leading);
  const size_t n = size_t(p.shape(0));
  py::array_t<float> distance(n);
  float* out = distance.mutable_data();
  read([&] { queries::compute_distance(scene_, p.data(), n, out, signed_distance, threads); });
  return shaped(distance, leading);
}

void PyScene::hit_extras(const HitBatch& hits, size_t count, float* normal, int32_t* mesh) const {
  for (size_t i = 0; i < count; ++i) {
    const int32_t id = hits.instance[i];
    if (mesh) mesh[i] = id < 0 ? -1 : int32_t(scene_.instance(uint32_t(id)).mesh);
    if (!normal) continue;
    DVec3 n(0.0);
    if (id >= 0) {
      const Instance& inst = scene_.instance(uint32_t(id));
      const Mesh& m = scene_.mesh(inst.mesh);
      const Triangle& tri = m.triangles()[size_t(hits.prim[i])];
      const DVec3 p0(m.vertices()[tri.x]), p1(m.vertices()[tri.y]), p2(m.vertices()[tri.z]);
      n = glm::cross(p1 - p0, p2 - p0);
      // Normals map by the inverse transpose of the object-to-world matrix.
      if (!inst.identity) n = glm::transpose(glm::dmat3(glm::mat3(inst.to_object))) * n;
      n = glm::normalize(n);
    }
    for (int a = 0; a < 3; ++a) normal[3 * i + a] = float(n[a]);
  }
}

}  // namespace toyrt::binding
