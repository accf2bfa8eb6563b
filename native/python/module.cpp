// The Python module `toyrt`: a thin binding that checks and converts numpy arrays, releases the
// GIL, and calls the core. Every misuse raises a Python exception naming what is wrong.
#include "geometry/offset_ray.h"
#include "python/render_binding.h"
#include "render/renderer.h"
#include "scene/scene.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <future>
#include <thread>
#include <variant>
#include <mutex>
#include <shared_mutex>
#include <string>

namespace py = pybind11;
using namespace toyrt;
using namespace toyrt::binding;

namespace {

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

std::string shape_of(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// Any array-like of numbers becomes a C-contiguous float32 array of shape (N, 3).
FloatArray as_points(py::handle obj, const char* name) {
  const py::array a = try_array(obj);
  if (!a) throw py::type_error(std::string(name) + " must be an array of shape (N, 3)");
  if (!is_numeric(a))
    throw py::type_error(std::string(name) + " must hold numbers, not dtype " + std::string(py::str(a.dtype())));
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error(std::string(name) + " must have shape (N, 3), got " + shape_of(a));
  return FloatArray::ensure(a);
}

std::vector<Vec3> to_vec3s(const FloatArray& a) {
  std::vector<Vec3> out(size_t(a.shape(0)));
  if (!out.empty()) std::memcpy(out.data(), a.data(), out.size() * sizeof(Vec3));
  return out;
}

std::vector<Triangle> to_triangles(py::handle obj) {
  const py::array a = try_array(obj);
  if (!a) throw py::type_error("triangles must be an integer array of shape (M, 3)");
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw py::type_error("triangles must be an integer array (vertex indices), not dtype " + std::string(py::str(a.dtype())));
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error("triangles must have shape (M, 3), got " + shape_of(a));
  auto idx = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
  if (kind == 'u' && a.itemsize() == 8) {
    // uint64 above 2^63 would wrap to negative int64: check the originals.
    auto u = py::array_t<uint64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    for (py::ssize_t i = 0; i < u.size(); ++i)
      if (u.data()[i] > UINT32_MAX) throw py::value_error("triangle " + std::to_string(i / 3) + " has an index out of range");
  }
  std::vector<Triangle> out(size_t(a.shape(0)));
  const int64_t* p = idx.data();
  for (size_t i = 0; i < out.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const int64_t v = p[3 * i + k];
      if (v < 0) throw py::value_error("triangle " + std::to_string(i) + " has a negative vertex index");
      if (v > int64_t(UINT32_MAX)) throw py::value_error("triangle " + std::to_string(i) + " has an index out of range");
      out[i][k] = uint32_t(v);
    }
  }
  return out;
}

// A (4, 4) row-major matrix (Blender's matrix_world layout) becomes GLM's column-major Mat4.
Mat4 to_matrix(py::handle obj) {
  const py::array a = try_array(obj);
  if (!a || !is_numeric(a))
    throw py::type_error("transform must be a (4, 4) array of numbers (row-major world matrix)");
  if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4)
    throw py::value_error("transform must have shape (4, 4), got " + shape_of(a));
  auto m = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  Mat4 out;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out[c][r] = float(m.data()[4 * r + c]);
  return out;
}

int check_threads(int threads) {
  if (threads < 0) throw py::value_error("threads must be >= 0 (0 means all cores), got " + std::to_string(threads));
  return threads;
}

// tnear / tfar: a number applied to every ray, or one value per ray.
struct PerRay {
  FloatArray storage;
  float scalar = 0.0f;
  const float* data = nullptr;
  size_t stride = 0;
};

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
      out.scalar = FloatArray::ensure(a).data()[0];
    } else {
      if (a.ndim() != 1 || size_t(a.shape(0)) != count)
        throw py::value_error(std::string(name) + " must be a number or have shape (" + std::to_string(count) + ",), got " + shape_of(a));
      out.storage = FloatArray::ensure(a);
      out.data = out.storage.data();
      out.stride = 1;
      return out;
    }
  }
  if (std::isnan(out.scalar)) throw py::value_error(std::string(name) + " is NaN");
  out.data = &out.scalar;
  return out;
}

// The Python-visible scene: the core Scene plus a readers/writer lock, so scripts that query
// from several threads while another adds geometry get consistent answers, never a crash.
class PyScene {
 public:
  uint32_t add_mesh(py::handle vertices, py::handle triangles, py::handle transform, py::handle normals,
                    py::handle uvs, py::handle material_ids) {
    std::vector<Vec3> verts = to_vec3s(as_points(vertices, "vertices"));
    std::vector<Triangle> tris = to_triangles(triangles);
    const Mat4 m = transform.is_none() ? Mat4(1.0f) : to_matrix(transform);
    MeshShading shading = to_shading(verts.size(), tris, normals, uvs, material_ids);
    std::unique_lock lock(mutex_);
    Scene::checked_inverse(m);  // before the mesh is added, so a bad call leaves the scene unchanged
    const uint32_t id = scene_.add_mesh(std::move(verts), std::move(tris));
    scene_.add_instance(id, m);
    render_.shading.resize(scene_.mesh_count());
    render_.shading[id] = std::move(shading);
    return id;
  }

  uint32_t add_material(const std::string& kind, py::handle color, int64_t texture, float ior) {
    const Vec3 c = to_color(color, "color");
    std::unique_lock lock(mutex_);
    render_.materials.push_back(make_material(kind, c, texture, ior));
    return uint32_t(render_.materials.size() - 1);
  }

  // In place, so the meshes using material `material` pick up the edit without re-export.
  void set_material(int64_t material, const std::string& kind, py::handle color, int64_t texture, float ior) {
    const Vec3 c = to_color(color, "color");
    std::unique_lock lock(mutex_);
    if (material < 0 || size_t(material) >= render_.materials.size())
      throw py::value_error("unknown material id " + std::to_string(material));
    render_.materials[size_t(material)] = make_material(kind, c, texture, ior);
  }

  Material make_material(const std::string& kind, const Vec3& c, int64_t texture, float ior) const {
    if (kind == "diffuse") {
      if (texture < -1 || texture >= int64_t(render_.textures.size()))
        throw py::value_error("unknown texture id " + std::to_string(texture) + " (the scene has " +
                              std::to_string(render_.textures.size()) + " textures)");
      return Lambert{c, int32_t(texture)};
    }
    if (kind == "refraction") return PerfectRefraction::make(ior);
    if (kind == "glass") return FresnelDielectric::make(ior);
    throw py::value_error("material kind must be 'diffuse', 'refraction' or 'glass', got '" + kind + "'");
  }

  uint32_t add_texture(py::handle pixels, bool srgb) {
    Texture t = make_texture(pixels, srgb);
    std::unique_lock lock(mutex_);
    render_.textures.push_back(std::move(t));
    return uint32_t(render_.textures.size() - 1);
  }

  void set_texture(int64_t texture, py::handle pixels, bool srgb) {
    Texture t = make_texture(pixels, srgb);
    std::unique_lock lock(mutex_);
    if (texture < 0 || size_t(texture) >= render_.textures.size())
      throw py::value_error("unknown texture id " + std::to_string(texture));
    render_.textures[size_t(texture)] = std::move(t);
  }

  static Texture make_texture(py::handle pixels, bool srgb) {
    const py::array a = try_array(pixels);
    if (!a) throw py::type_error("pixels must be an array of shape (height, width, 3 or 4)");
    if (a.ndim() != 3 || (a.shape(2) != 3 && a.shape(2) != 4))
      throw py::value_error("pixels must have shape (height, width, 3 or 4), got " + shape_of(a));
    const int h = int(a.shape(0)), w = int(a.shape(1)), c = int(a.shape(2));
    const ColorEncoding enc = srgb ? ColorEncoding::Srgb : ColorEncoding::Linear;
    Texture t;
    if (a.dtype().kind() == 'u' && a.itemsize() == 1) {
      auto b = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>::ensure(a);
      t = Texture::from_bytes(w, h, c, std::vector<uint8_t>(b.data(), b.data() + b.size()), enc);
    } else if (a.dtype().kind() == 'f') {
      auto f = FloatArray::ensure(a);
      t = Texture::from_floats(w, h, c, std::vector<float>(f.data(), f.data() + f.size()), enc);
    } else {
      throw py::type_error("pixels must be float (0..1) or uint8, not dtype " + std::string(py::str(a.dtype())));
    }
    return t;
  }

  // Lights are re-sent as a whole on an edit: they are few and cheap.
  void clear_lights() {
    std::unique_lock lock(mutex_);
    render_.lights.clear();
    render_.light_visibility.clear();
  }

  void replace_mesh(int64_t mesh, py::handle vertices, py::handle triangles, py::handle normals, py::handle uvs,
                    py::handle material_ids) {
    std::vector<Vec3> verts = to_vec3s(as_points(vertices, "vertices"));
    std::vector<Triangle> tris = to_triangles(triangles);
    MeshShading shading = to_shading(verts.size(), tris, normals, uvs, material_ids);
    std::unique_lock lock(mutex_);
    if (mesh < 0 || size_t(mesh) >= scene_.mesh_count())
      throw py::value_error("unknown mesh id " + std::to_string(mesh) + " (the scene has " +
                            std::to_string(scene_.mesh_count()) + " meshes)");
    scene_.replace_mesh(uint32_t(mesh), std::move(verts), std::move(tris));
    render_.shading.resize(scene_.mesh_count());
    render_.shading[size_t(mesh)] = std::move(shading);
  }

  void set_instance_transform(int64_t instance, py::handle transform) {
    const Mat4 m = to_matrix(transform);
    std::unique_lock lock(mutex_);
    if (instance < 0) throw py::value_error("unknown instance id " + std::to_string(instance));
    scene_.set_instance_transform(uint32_t(instance), m);
  }

  void clear_instances() {
    std::unique_lock lock(mutex_);
    scene_.clear_instances();
  }

  uint32_t add_point_light(py::handle position, float power, py::handle color, float radius, bool visible_camera,
                           bool visible_specular) {
    const PointLight l = PointLight::make(to_point(position, "position"), power, to_color(color, "color"), radius);
    std::unique_lock lock(mutex_);
    render_.lights.push_back(l);
    render_.light_visibility.push_back({visible_camera, visible_specular});
    return uint32_t(render_.lights.size() - 1);
  }

  uint32_t add_area_light(py::handle matrix, const std::string& shape, float size, py::handle size_y, float power,
                          py::handle color, bool visible_camera, bool visible_specular) {
    const float sy = size_y.is_none() ? size : size_y.cast<float>();
    const AreaLight l = AreaLight::make(to_area_shape(shape), size, sy, to_matrix4(matrix, "matrix"), power,
                                        to_color(color, "color"));
    std::unique_lock lock(mutex_);
    render_.lights.push_back(l);
    render_.light_visibility.push_back({visible_camera, visible_specular});
    return uint32_t(render_.lights.size() - 1);
  }

  void set_background(py::handle color) {
    const Vec3 c = to_color(color, "background");
    std::unique_lock lock(mutex_);
    render_.background = c;
  }
  void set_background_lighting(bool on) {
    std::unique_lock lock(mutex_);
    render_.background_lights_surfaces = on;
  }
  bool background_lighting() {
    std::shared_lock lock(mutex_);
    return render_.background_lights_surfaces;
  }
  py::tuple background() {
    std::shared_lock lock(mutex_);
    return py::make_tuple(render_.background.x, render_.background.y, render_.background.z);
  }

  py::array_t<float> render(const py::dict& camera_settings, int samples, uint32_t seed, int max_specular_depth,
                            const std::string& area_light_sampling, const std::string& light_sampling, int threads,
                            int tile_size, py::object on_tile, py::object should_cancel, int first_sample,
                            int split_depth) {
    const Camera camera = Camera::make(to_camera(camera_settings));
    if (samples < 1) throw py::value_error("samples must be at least 1");
    if (first_sample < 0) throw py::value_error("first_sample must be >= 0");
    if (tile_size < 1) throw py::value_error("tile_size must be at least 1");
    if (max_specular_depth < 0) throw py::value_error("max_specular_depth must be >= 0");
    if (split_depth < 0) throw py::value_error("split_depth must be >= 0");
    const AreaSampling area = to_area_sampling(area_light_sampling);
    RenderSettings settings;
    settings.samples = samples;
    settings.first_sample = first_sample;
    settings.tile_size = tile_size;
    settings.threads = check_threads(threads);
    settings.integrator.seed = seed;
    settings.integrator.max_specular_depth = max_specular_depth;
    settings.integrator.split_depth = split_depth;
    std::shared_lock lock(mutex_);
    require_committed();
    RenderScene rs = render_;  // a private copy: lights take this render's estimator
    rs.geometry = &scene_;
    for (Light& l : rs.lights)
      if (auto* a = std::get_if<AreaLight>(&l)) a->sampling = a->is_rectangle() ? area : AreaSampling::Area;
    if (light_sampling == "all") settings.integrator.light_sampling = LightSampling::All;
    else if (light_sampling == "one") settings.integrator.light_sampling = LightSampling::One;
    else if (light_sampling == "auto")
      settings.integrator.light_sampling = rs.lights.size() > kAllLightsUpTo ? LightSampling::One : LightSampling::All;
    else throw py::value_error("light_sampling must be 'auto', 'all' or 'one', got '" + light_sampling + "'");
    check_material_ids(rs);

    // Tiles and cancel polls arrive on this thread with the GIL released: take it for Python.
    TileSink sink;
    if (!on_tile.is_none()) {
      sink = [&](const Tile& t, const RenderResult& r) {
        py::gil_scoped_acquire gil;
        py::array_t<float> pixels({py::ssize_t(t.height), py::ssize_t(t.width), py::ssize_t(4)});
        float* out = pixels.mutable_data();
        for (int j = 0; j < t.height; ++j)
          std::memcpy(out + size_t(j) * t.width * 4, &r.rgba[(size_t(t.y + j) * r.width + t.x) * 4], size_t(t.width) * 4 * sizeof(float));
        on_tile(t.x, t.y, t.width, t.height, pixels);
      };
    }
    CancelPoll poll = [&]() {
      py::gil_scoped_acquire gil;
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();  // Ctrl-C cancels too
      return !should_cancel.is_none() && py::bool_(should_cancel());
    };
    RenderResult result;
    {
      py::gil_scoped_release release;
      result = toyrt::render(rs, camera, settings, sink, poll);
    }
    last_render_ = py::dict();
    last_render_["cancelled"] = result.cancelled;
    last_render_["tiles_done"] = result.tiles_done;
    last_render_["tiles_total"] = result.tiles_total;
    last_render_["render_ms"] = result.render_ms;
    last_render_["cancel_latency_ms"] = result.cancel_latency_ms;
    last_render_["samples"] = samples;
    last_render_["first_sample"] = first_sample;
    last_render_["light_sampling"] = settings.integrator.light_sampling == LightSampling::One ? "one" : "all";
    py::array_t<float> image({py::ssize_t(result.height), py::ssize_t(result.width), py::ssize_t(4)});
    std::memcpy(image.mutable_data(), result.rgba.data(), result.rgba.size() * sizeof(float));
    return image;
  }

  py::dict last_render() { return last_render_; }

  uint32_t add_instance(int64_t mesh, py::handle transform) {
    const Mat4 m = to_matrix(transform);
    std::unique_lock lock(mutex_);
    if (mesh < 0 || size_t(mesh) >= scene_.mesh_count())
      throw py::value_error("unknown mesh id " + std::to_string(mesh) + " (the scene has " +
                            std::to_string(scene_.mesh_count()) + " meshes)");
    return scene_.add_instance(uint32_t(mesh), m);
  }

  bool commit(const std::string& builder, int threads, py::handle expected_rays, py::object should_cancel) {
    CommitOptions opt;
    opt.builder = parse_builder(builder);
    opt.threads = check_threads(threads);
    if (!expected_rays.is_none()) {
      if (!py::isinstance<py::int_>(expected_rays) && !py::isinstance<py::float_>(expected_rays))
        throw py::type_error("expected_rays must be a number (or None when unknown)");
      opt.expected_rays = expected_rays.cast<double>();
      if (!(opt.expected_rays >= 0.0) || !std::isfinite(opt.expected_rays))
        throw py::value_error("expected_rays must be a finite number >= 0 (or None when unknown)");
    }
    std::string warning;
    bool cancelled = false;
    {
      std::unique_lock lock(mutex_);
      py::gil_scoped_release release;
      if (should_cancel.is_none()) {
        scene_.commit(opt);
      } else {
        // The build runs on its own thread while this one polls should_cancel every 10 ms (with
        // the GIL, as Blender's test_break needs); a true answer, or an exception from it, sets
        // the flag the builders poll. Joined before anything else happens, exceptions included.
        std::atomic<bool> cancel{false};
        opt.cancel = &cancel;
        std::packaged_task<void()> task([&] { scene_.commit(opt); });
        std::future<void> done = task.get_future();
        std::thread worker(std::move(task));
        std::exception_ptr poll_error;
        while (done.wait_for(std::chrono::milliseconds(10)) != std::future_status::ready) {
          if (cancel.load() || poll_error) continue;
          py::gil_scoped_acquire gil;
          try {
            if (should_cancel().cast<bool>()) cancel.store(true);
          } catch (...) {
            poll_error = std::current_exception();
            cancel.store(true);
          }
        }
        worker.join();
        try {
          done.get();
        } catch (const BuildCancelled&) {
          cancelled = true;
        }
        if (poll_error) {
          py::gil_scoped_acquire gil;
          std::rethrow_exception(poll_error);
        }
      }
      warning = scene_.commit_stats().warning;
    }
    // One clear warning when the LBVH could not run and the SAH builder stood in.
    if (!warning.empty() && PyErr_WarnEx(PyExc_RuntimeWarning, warning.c_str(), 1) != 0) throw py::error_already_set();
    return !cancelled;
  }

  py::dict last_commit() {
    std::shared_lock lock(mutex_);
    const CommitStats& st = scene_.commit_stats();
    py::dict d;
    d["build_ms"] = st.build_ms;
    d["lbvh_compile_ms"] = st.lbvh_compile_ms;
    d["meshes_built"] = st.meshes_built;
    d["sah_meshes"] = st.sah_meshes;
    d["lbvh_meshes"] = st.lbvh_meshes;
    d["warning"] = st.warning;
    return d;
  }

  py::dict intersect(py::handle origins, py::handle directions, py::handle tnear, py::handle tfar, int threads) {
    auto [org, dir] = rays(origins, directions);
    const size_t n = size_t(org.shape(0));
    const PerRay near = per_ray(tnear, n, "tnear"), far = per_ray(tfar, n, "tfar");
    py::array_t<float> t(n), u(n), v(n);
    py::array_t<int32_t> prim(n), instance(n);
    const RayBatch batch{org.data(), dir.data(), near.data, near.stride, far.data, far.stride, n};
    const HitBatch hits{t.mutable_data(), u.mutable_data(), v.mutable_data(), prim.mutable_data(), instance.mutable_data()};
    {
      py::gil_scoped_release release;
      std::shared_lock lock(mutex_);
      require_committed();
      scene_.intersect(batch, hits, check_threads(threads));
    }
    py::dict out;
    out["t"] = t;
    out["prim"] = prim;
    out["instance"] = instance;
    out["u"] = u;
    out["v"] = v;
    return out;
  }

  py::array_t<bool> occluded(py::handle origins, py::handle directions, py::handle tnear, py::handle tfar, int threads) {
    auto [org, dir] = rays(origins, directions);
    const size_t n = size_t(org.shape(0));
    const PerRay near = per_ray(tnear, n, "tnear"), far = per_ray(tfar, n, "tfar");
    py::array_t<bool> blocked(n);
    static_assert(sizeof(bool) == sizeof(uint8_t));
    const RayBatch batch{org.data(), dir.data(), near.data, near.stride, far.data, far.stride, n};
    {
      py::gil_scoped_release release;
      std::shared_lock lock(mutex_);
      require_committed();
      scene_.occluded(batch, reinterpret_cast<uint8_t*>(blocked.mutable_data()), check_threads(threads));
    }
    return blocked;
  }

  py::dict bvh_stats(int64_t mesh) {
    std::shared_lock lock(mutex_);
    require_committed();
    const Bvh* bvh = &scene_.top_level();
    if (mesh >= 0) {
      if (size_t(mesh) >= scene_.mesh_count()) throw py::value_error("unknown mesh id " + std::to_string(mesh));
      bvh = &scene_.mesh(uint32_t(mesh)).bvh();
    }
    py::dict d;
    d["nodes"] = bvh->nodes.size();
    d["leaves"] = bvh->leaf_count();
    d["depth"] = bvh->depth();
    d["sah_cost"] = bvh->sah_cost();
    return d;
  }

  size_t mesh_count() { std::shared_lock l(mutex_); return scene_.mesh_count(); }
  size_t instance_count() { std::shared_lock l(mutex_); return scene_.instance_count(); }
  size_t triangle_count() { std::shared_lock l(mutex_); return scene_.stored_triangle_count(); }
  size_t memory_bytes() { std::shared_lock l(mutex_); return scene_.memory_bytes(); }
  bool committed() { std::shared_lock l(mutex_); return scene_.committed(); }
  double build_ms() { std::shared_lock l(mutex_); return scene_.commit_stats().build_ms; }

 private:
  std::pair<FloatArray, FloatArray> rays(py::handle origins, py::handle directions) {
    FloatArray org = as_points(origins, "origins"), dir = as_points(directions, "directions");
    if (org.shape(0) != dir.shape(0))
      throw py::value_error("origins and directions must hold the same number of rays, got " +
                            std::to_string(org.shape(0)) + " and " + std::to_string(dir.shape(0)));
    return {org, dir};
  }

  void require_committed() const {
    if (!scene_.committed())
      throw std::logic_error(scene_.instance_count() == 0 && scene_.mesh_count() == 0
                                 ? "query before commit(): add meshes, then call commit()"
                                 : "the scene changed since the last commit(): call commit() before queries");
  }

  // Shading attributes from their Python forms: per corner (M, 3, k) or per vertex (N, k).
  static MeshShading to_shading(size_t vertex_count, const std::vector<Triangle>& tris, py::handle normals, py::handle uvs,
                                py::handle material_ids) {
    MeshShading sh;
    const size_t m = tris.size();
    auto corners = [&](py::handle obj, int k, const char* name) {
      const py::array raw = try_array(obj);
      FloatArray a = raw && is_numeric(raw) ? FloatArray::ensure(raw) : FloatArray();
      if (!a) throw py::type_error(std::string(name) + " must be an array of numbers");
      std::vector<float> out(m * 3 * size_t(k));
      if (a.ndim() == 3 && size_t(a.shape(0)) == m && a.shape(1) == 3 && a.shape(2) == k) {
        std::memcpy(out.data(), a.data(), out.size() * sizeof(float));
      } else if (a.ndim() == 2 && size_t(a.shape(0)) == vertex_count && a.shape(1) == k) {
        for (size_t t = 0; t < m; ++t)
          for (int c = 0; c < 3; ++c)
            std::memcpy(&out[(3 * t + size_t(c)) * size_t(k)], a.data() + size_t(tris[t][c]) * size_t(k), size_t(k) * sizeof(float));
      } else {
        throw py::value_error(std::string(name) + " must have shape (" + std::to_string(m) + ", 3, " + std::to_string(k) +
                              ") per corner or (" + std::to_string(vertex_count) + ", " + std::to_string(k) +
                              ") per vertex, got " + shape_of(a));
      }
      for (float x : out)
        if (!std::isfinite(x)) throw py::value_error(std::string(name) + " holds a non-finite value");
      return out;
    };
    if (!normals.is_none()) {
      const auto n = corners(normals, 3, "normals");
      sh.corner_normals.resize(3 * m);
      std::memcpy(sh.corner_normals.data(), n.data(), n.size() * sizeof(float));
    }
    if (!uvs.is_none()) {
      const auto u = corners(uvs, 2, "uvs");
      sh.corner_uvs.resize(3 * m);
      std::memcpy(sh.corner_uvs.data(), u.data(), u.size() * sizeof(float));
    }
    if (!material_ids.is_none()) {
      if (py::isinstance<py::int_>(material_ids)) {
        const int64_t id = material_ids.cast<int64_t>();
        if (id < 0 || id > INT32_MAX) throw py::value_error("material_ids must be >= 0");
        sh.material_ids.assign(m, int32_t(id));
      } else {
        const py::array a = try_array(material_ids);
        if (!a || (a.dtype().kind() != 'i' && a.dtype().kind() != 'u'))
          throw py::type_error("material_ids must be an integer or an integer array of shape (M,)");
        if (a.ndim() != 1 || size_t(a.shape(0)) != m)
          throw py::value_error("material_ids must have shape (" + std::to_string(m) + ",), got " + shape_of(a));
        auto ids = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
        sh.material_ids.resize(m);
        for (size_t t = 0; t < m; ++t) {
          if (ids.data()[t] < 0 || ids.data()[t] > INT32_MAX) throw py::value_error("material_ids must be >= 0");
          sh.material_ids[t] = int32_t(ids.data()[t]);
        }
      }
    }
    return sh;
  }

  // Every material id a mesh uses must name a material (no materials at all: all default grey).
  static void check_material_ids(const RenderScene& rs) {
    for (size_t mesh = 0; mesh < rs.shading.size(); ++mesh)
      for (int32_t id : rs.shading[mesh].material_ids)
        if (size_t(id) >= rs.materials.size() && !(rs.materials.empty() && id == 0))
          throw py::value_error("mesh " + std::to_string(mesh) + " uses material id " + std::to_string(id) +
                                " but the scene has " + std::to_string(rs.materials.size()) + " materials");
  }

  // "auto" light sampling: every light at every hit up to this many lights, one chosen light beyond.
  static constexpr size_t kAllLightsUpTo = 4;

  Scene scene_;
  RenderScene render_;
  py::dict last_render_;
  std::shared_mutex mutex_;
};

}  // namespace

PYBIND11_MODULE(toyrt, m) {
  m.doc() = "TOYRT's native core: watertight triangles, SAH BVH, two-level scenes, batch ray queries.";
  m.attr("__version__") = "0.1.0";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const std::logic_error& e) {
      // std::invalid_argument is bad input; other logic errors are calls in the wrong order.
      if (dynamic_cast<const std::invalid_argument*>(&e))
        PyErr_SetString(PyExc_ValueError, e.what());
      else
        PyErr_SetString(PyExc_RuntimeError, e.what());
    } catch (const std::bad_alloc&) {
      PyErr_SetString(PyExc_MemoryError, "toyrt: out of memory");
    } catch (const RenderTooLarge& e) {
      PyErr_SetString(PyExc_MemoryError, e.what());  // refused before allocating
    }
  });

  py::class_<PyScene>(m, "Scene", "A two-level scene: meshes stored once, placed by instances.")
      .def(py::init<>())
      .def("add_mesh", &PyScene::add_mesh, py::arg("vertices"), py::arg("triangles"), py::arg("transform") = py::none(),
           py::arg("normals") = py::none(), py::arg("uvs") = py::none(), py::arg("material_ids") = py::none(),
           "Adds a mesh and one instance of it; returns the mesh id.\n"
           "vertices: (N, 3) numbers (stored as float32), finite. triangles: (M, 3) integer vertex\n"
           "indices. transform: None (identity) or a (4, 4) row-major affine world matrix.\n"
           "Degenerate (zero-area) triangles are kept but can never be hit.\n"
           "For rendering: normals (M, 3, 3) per corner or (N, 3) per vertex (smooth shading; None: flat),\n"
           "uvs (M, 3, 2) or (N, 2), material_ids: one int or (M,) ints into the scene's materials.")
      .def("add_material", &PyScene::add_material, py::arg("kind") = "diffuse",
           py::arg("color") = py::make_tuple(0.8, 0.8, 0.8), py::arg("texture") = -1, py::arg("ior") = 1.45f,
           "Adds a material; returns its id. kind: 'diffuse' (Lambert, linear RGB colour or a texture id),\n"
           "'refraction' (perfect refraction, Blender's Refraction BSDF, with its ior) or 'glass' (Fresnel\n"
           "reflection and refraction, Blender's Glass BSDF).")
      .def("add_texture", &PyScene::add_texture, py::arg("pixels"), py::arg("srgb") = true,
           "Adds an image; returns its id. pixels: (height, width, 3 or 4), float 0..1 or uint8, rows from\n"
           "the bottom (Blender's Image.pixels order); srgb: decode from sRGB to linear, as Blender does.")
      .def("add_point_light", &PyScene::add_point_light, py::arg("position"), py::arg("power"),
           py::arg("color") = py::make_tuple(1.0, 1.0, 1.0), py::arg("radius") = 0.0f, py::arg("visible_camera") = true,
           py::arg("visible_specular") = true,
           "Adds a point light in Blender's units: power in watts, linear colour, radius in metres (0: hard shadows).\n"
           "visible_camera / visible_specular: whether camera rays / rays through glass see the sphere itself.")
      .def("add_area_light", &PyScene::add_area_light, py::arg("matrix"), py::arg("shape") = "SQUARE",
           py::arg("size") = 1.0f, py::arg("size_y") = py::none(), py::arg("power") = 10.0f,
           py::arg("color") = py::make_tuple(1.0, 1.0, 1.0), py::arg("visible_camera") = true,
           py::arg("visible_specular") = true,
           "Adds an area light in Blender's units: the light object's (4, 4) world matrix (it emits along its\n"
           "local -Z, one-sided), shape 'RECTANGLE', 'SQUARE', 'DISK' or 'ELLIPSE', size (and size_y) in metres,\n"
           "power in watts (radiance = power / (4 area), as Cycles). visible_camera / visible_specular: whether\n"
           "camera rays / rays through glass see the light's surface (Cycles' defaults: both).")
      .def_property("background", &PyScene::background, &PyScene::set_background,
                    "Radiance (linear RGB) of rays that leave the scene: the world colour.")
      .def_property("background_lighting", &PyScene::background_lighting, &PyScene::set_background_lighting,
                    "Whether the background also lights diffuse surfaces, as Cycles' world does (default True).")
      .def("render", &PyScene::render, py::arg("camera"), py::arg("samples") = 16, py::arg("seed") = 0,
           py::arg("max_specular_depth") = 8, py::arg("area_light_sampling") = "solid_angle",
           py::arg("light_sampling") = "auto", py::arg("threads") = 0, py::arg("tile_size") = 32,
           py::arg("on_tile") = py::none(), py::arg("should_cancel") = py::none(), py::arg("first_sample") = 0,
           py::arg("split_depth") = IntegratorSettings{}.split_depth,
           "Renders the committed scene; returns (height, width, 4) float32 linear RGBA, rows from the top, of\n"
           "the camera's pixel window (the border region, if set).\n"
           "camera: a dict of Blender's camera and render settings: type ('PERSP', 'ORTHO'), lens, sensor_width,\n"
           "sensor_height, sensor_fit ('AUTO', 'HORIZONTAL', 'VERTICAL'), shift_x, shift_y, clip_start, clip_end,\n"
           "ortho_scale, resolution_x, resolution_y, resolution_percentage, pixel_aspect_x, pixel_aspect_y,\n"
           "use_border, border_min_x/y, border_max_x/y, matrix_world (4, 4).\n"
           "area_light_sampling: 'solid_angle' (spherical rectangles) or 'area'. light_sampling: 'all' (every\n"
           "light at every hit), 'one' (one light chosen by expected contribution) or 'auto' ('all' up to 4\n"
           "lights). on_tile(x, y, width, height, pixels) is called on this thread as tiles finish;\n"
           "should_cancel() is polled every 10 ms and stops the render when true (so does Ctrl-C).\n"
           "Results are the same for any thread count and tile size.\n"
           "first_sample: render samples [first_sample, first_sample + samples) of the same sequence, the\n"
           "mean of that pass: passes weighted by their sample counts average to one render of them all\n"
           "(progressive rendering). A window too large for the memory available raises MemoryError\n"
           "before anything is allocated.\n"
           "split_depth: glass (Fresnel) surfaces among the first split_depth path vertices trace both reflection\n"
           "and refraction, weighted by F and 1 - F; deeper ones choose one. 0: never split.")
      .def_property_readonly("last_render", &PyScene::last_render,
                             "What the last render did: cancelled, cancel_latency_ms, tiles_done, tiles_total, render_ms,\n"
                             "samples, light_sampling.")
      .def("set_material", &PyScene::set_material, py::arg("material"), py::arg("kind") = "diffuse",
           py::arg("color") = py::make_tuple(0.8, 0.8, 0.8), py::arg("texture") = -1, py::arg("ior") = 1.45f,
           "Replaces material `material` in place (same arguments as add_material); meshes keep their ids.")
      .def("set_texture", &PyScene::set_texture, py::arg("texture"), py::arg("pixels"), py::arg("srgb") = true,
           "Replaces texture `texture` in place (same arguments as add_texture).")
      .def("clear_lights", &PyScene::clear_lights, "Removes every light (to send them again after an edit).")
      .def("replace_mesh", &PyScene::replace_mesh, py::arg("mesh"), py::arg("vertices"), py::arg("triangles"),
           py::arg("normals") = py::none(), py::arg("uvs") = py::none(), py::arg("material_ids") = py::none(),
           "Replaces mesh `mesh`'s geometry and shading (arguments as add_mesh, without a transform); its\n"
           "instances stay, the next commit rebuilds its BVH. Empty arrays free a mesh no longer used.")
      .def("set_instance_transform", &PyScene::set_instance_transform, py::arg("instance"), py::arg("transform"),
           "Moves instance `instance` ((4, 4) row-major affine world matrix); the next commit rebuilds only\n"
           "the top level.")
      .def("clear_instances", &PyScene::clear_instances,
           "Removes every instance (meshes stay, with their BVHs), to place them again.")
      .def("add_instance", &PyScene::add_instance, py::arg("mesh"), py::arg("transform"),
           "Places mesh `mesh` again with a (4, 4) row-major affine world matrix; returns the instance id.")
      .def("commit", &PyScene::commit, py::arg("builder") = "auto", py::arg("threads") = 0,
           py::arg("expected_rays") = py::none(), py::arg("should_cancel") = py::none(),
           "Builds the BVHs of new meshes and the top level; returns True, or False when cancelled.\n"
           "should_cancel(): polled every 10 ms while building; when it returns true the build stops\n"
           "within a few milliseconds and the scene stays uncommitted (meshes already built keep their BVH,\n"
           "so the next commit builds only the rest).\n"
           "builder: 'sah' (binned SAH on the CPU: the faster trees), 'lbvh' (Karras' linear BVH as OpenCL\n"
           "kernels: the faster builds; falls back to 'sah' with a RuntimeWarning when no OpenCL device or\n"
           "kernel build is available), or 'auto' (per mesh, whichever makes build + tracing cheaper for\n"
           "`expected_rays` rays; without that estimate, 'sah'). threads: 0 for all cores.")
      .def_property_readonly("last_commit", &PyScene::last_commit,
           "What the last commit did: build_ms, lbvh_compile_ms (OpenCL compilation, first LBVH build of\n"
           "the process only), meshes_built, sah_meshes, lbvh_meshes, warning.")
      .def("intersect", &PyScene::intersect, py::arg("origins"), py::arg("directions"), py::arg("tnear") = 0.0f,
           py::arg("tfar") = std::numeric_limits<float>::infinity(), py::arg("threads") = 0,
           "Nearest hits of rays org + t * dir with tnear <= t < tfar (world units of t: the direction's\n"
           "length). origins, directions: (N, 3); tnear, tfar: numbers or (N,) arrays.\n"
           "Returns a dict of (N,) arrays: t (float32, inf on a miss), prim (int32 triangle index in its\n"
           "mesh, -1 on a miss), instance (int32), u, v (float32; p = (1-u-v) p0 + u p1 + v p2).\n"
           "Rays with a zero or non-finite direction, a non-finite origin, or tnear > tfar miss.")
      .def("occluded", &PyScene::occluded, py::arg("origins"), py::arg("directions"), py::arg("tnear") = 0.0f,
           py::arg("tfar") = std::numeric_limits<float>::infinity(), py::arg("threads") = 0,
           "Whether anything lies on each ray with tnear <= t < tfar; a (N,) bool array. Stops at the first hit.")
      .def("bvh_stats", &PyScene::bvh_stats, py::arg("mesh") = -1,
           "Node count, leaf count, depth and SAH cost of a mesh's BVH, or of the top level for mesh=-1.")
      .def_property_readonly("mesh_count", &PyScene::mesh_count)
      .def_property_readonly("instance_count", &PyScene::instance_count)
      .def_property_readonly("triangle_count", &PyScene::triangle_count, "Triangles stored, each mesh counted once.")
      .def_property_readonly("memory_bytes", &PyScene::memory_bytes)
      .def_property_readonly("committed", &PyScene::committed)
      .def_property_readonly("build_ms", &PyScene::build_ms, "Wall time of the last commit in milliseconds.");

  m.def(
      "camera_window",
      [](const py::dict& camera) {
        const Camera c = Camera::make(to_camera(camera));
        py::dict d;
        d["width"] = c.width;
        d["height"] = c.height;
        d["x0"] = c.window.x0;
        d["y0"] = c.window.y0;
        d["x1"] = c.window.x1;
        d["y1"] = c.window.y1;
        return d;
      },
      py::arg("camera"),
      "The image size (resolution times percentage) and the pixel window render() fills (the border,\n"
      "or the whole image), rows counted from the top: dict of width, height, x0, y0, x1, y1.");

  m.def(
      "offset_ray_origin",
      [](py::handle points, py::handle normals) {
        FloatArray p = as_points(points, "points"), n = as_points(normals, "normals");
        if (p.shape(0) != n.shape(0)) throw py::value_error("points and normals must have the same length");
        const size_t count = size_t(p.shape(0));
        py::array_t<float> out({py::ssize_t(count), py::ssize_t(3)});
        const Vec3* pp = reinterpret_cast<const Vec3*>(p.data());
        const Vec3* nn = reinterpret_cast<const Vec3*>(n.data());
        Vec3* o = reinterpret_cast<Vec3*>(out.mutable_data());
        for (size_t i = 0; i < count; ++i) o[i] = offset_ray_origin(pp[i], nn[i]);
        return out;
      },
      py::arg("points"), py::arg("normals"),
      "Ray origins moved off the surface along the normals (Waechter and Binder 2019), so rays\n"
      "leaving the surface do not hit it again: (N, 3) float32.");
}
