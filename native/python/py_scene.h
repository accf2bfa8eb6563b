// The Python-visible scene: the core Scene plus a readers/writer lock, so scripts that query
// from several threads while another edits get consistent answers, never a crash. Each method
// converts its arguments (python/convert.h), takes the lock, releases the GIL where the core
// works for long, and calls the core, which holds the policy (validation, defaults, builder
// choice, cancellation).
#pragma once

#include "scene/scene.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <mutex>
#include <shared_mutex>
#include <string>

namespace toyrt::binding {

namespace py = pybind11;

class PyScene {
 public:
  uint32_t add_mesh(py::handle vertices, py::handle triangles, py::handle transform, py::handle normals, py::handle uvs,
                    py::handle material_ids, bool instance, py::handle tangents);
  void replace_mesh(int64_t mesh, py::handle vertices, py::handle triangles, py::handle normals, py::handle uvs,
                    py::handle material_ids, py::handle tangents);
  uint32_t add_instance(int64_t mesh, py::handle transform, bool visible_shadow, int receiver_set, int blocker_set,
                        bool visible_camera, bool visible_diffuse, bool visible_glossy, bool visible_transmission,
                        uint64_t light_receivers);
  void set_instance_transform(int64_t instance, py::handle transform);
  void clear_instances();

  // Generic over the types: the core makes the material or light from its name and parameters
  // (make_material, make_light), so a new type needs no method here.
  uint32_t add_material(const std::string& kind, const Params& params);
  void set_material(int64_t material, const std::string& kind, const Params& params);
  uint32_t add_texture(py::handle pixels, bool srgb);
  void set_texture(int64_t texture, py::handle pixels, bool srgb);
  uint32_t add_light(const std::string& type, const Params& params, LightVisibility visibility);
  void clear_lights();
  void set_background(py::handle color);
  py::tuple background();
  void set_background_lighting(bool on);
  bool background_lighting();
  void set_background_visible_camera(bool on);
  bool background_visible_camera();
  void set_background_visible_glossy(bool on);
  bool background_visible_glossy();
  void set_background_visible_transmission(bool on);
  bool background_visible_transmission();
  void set_environment(int64_t texture, py::handle strength, py::handle matrix);

  bool commit(const std::string& builder, int threads, py::handle expected_rays, py::object should_cancel);
  py::dict last_commit();
  py::array_t<float> render(const py::dict& camera, int samples, uint32_t seed, int max_specular_depth,
                            const std::string& area_light_sampling, const std::string& light_sampling, int threads,
                            int tile_size, py::object on_tile, py::object should_cancel, int first_sample,
                            int split_depth, py::handle passes, py::handle mist, py::handle object_index,
                            py::handle material_index, py::handle cryptomatte, int cryptomatte_depth,
                            bool use_adaptive_sampling, float adaptive_threshold, int adaptive_min_samples,
                            double time_limit, py::object on_progress, int transparent_max_bounces);
  py::dict last_render() { return last_render_; }
  py::dict last_passes() { return last_passes_; }

  // Ray arrays of any leading shape (..., 3): answers come in that shape. normals / mesh_ids add
  // "normal" (unit geometric normal in world space, 0 on a miss) and "mesh" (-1 on a miss).
  py::dict intersect(py::handle origins, py::handle directions, py::handle tnear, py::handle tfar, int threads,
                     bool normals, bool mesh_ids);
  py::array occluded(py::handle origins, py::handle directions, py::handle tnear, py::handle tfar, int threads);
  py::dict bvh_stats(int64_t mesh);

  // The exact geometric queries (py_queries.cpp; the core's are in queries/).
  py::array count_intersections(py::handle origins, py::handle directions, py::handle tnear, py::handle tfar,
                                int threads);
  py::dict list_intersections(py::handle origins, py::handle directions, py::handle tnear, py::handle tfar,
                              size_t max_hits, int threads);
  py::array compute_occupancy(py::handle points, int threads);
  py::dict compute_closest_points(py::handle points, int threads);
  py::array compute_distance(py::handle points, bool signed_distance, int threads);

  size_t mesh_count();
  size_t instance_count();
  size_t triangle_count();
  size_t memory_bytes();
  bool committed();
  double build_ms();

 private:
  // intersect's opt-in fields from its hits (py_queries.cpp); called under the shared lock.
  void hit_extras(const HitBatch& hits, size_t count, float* normal, int32_t* mesh) const;
  // Runs an edit under the exclusive lock with the GIL released while it waits: a render or
  // commit holding the lock takes the GIL to poll its callbacks, so waiting with it would deadlock.
  template <class F>
  auto write(F&& edit) {
    py::gil_scoped_release release;
    std::unique_lock lock(mutex_);
    return edit();
  }
  // Reads plain values under the shared lock, likewise without the GIL (build Python objects after).
  template <class F>
  auto read(F&& query) {
    py::gil_scoped_release release;
    std::shared_lock lock(mutex_);
    return query();
  }

  Scene scene_;
  py::dict last_render_;
  py::dict last_passes_;
  std::shared_mutex mutex_;
};

}  // namespace toyrt::binding
