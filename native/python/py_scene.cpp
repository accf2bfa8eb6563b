#include "python/py_scene.h"

#include "python/convert.h"

#include <mutex>
#include <utility>
#include <vector>

namespace toyrt::binding {

uint32_t PyScene::add_mesh(py::handle vertices, py::handle triangles, py::handle transform, py::handle normals,
                           py::handle uvs, py::handle material_ids, bool instance, py::handle tangents) {
  std::vector<Vec3> verts = to_vec3s(as_points(vertices, "vertices"));
  std::vector<Triangle> tris = to_triangles(triangles);
  if (!instance && !transform.is_none())
    throw py::value_error("transform places the mesh's instance: pass None with instance=False");
  const Mat4 m = transform.is_none() ? Mat4(1.0f) : to_matrix(transform, "transform");
  MeshShading shading = to_shading(verts.size(), tris, normals, uvs, material_ids, tangents);
  return write([&] {
    if (instance) Scene::checked_inverse(m);  // before the mesh is added: a refused call changes nothing
    const uint32_t id = scene_.add_mesh(std::move(verts), std::move(tris), std::move(shading));
    if (instance) scene_.add_instance(id, m);
    return id;
  });
}

void PyScene::replace_mesh(int64_t mesh, py::handle vertices, py::handle triangles, py::handle normals, py::handle uvs,
                           py::handle material_ids, py::handle tangents) {
  std::vector<Vec3> verts = to_vec3s(as_points(vertices, "vertices"));
  std::vector<Triangle> tris = to_triangles(triangles);
  MeshShading shading = to_shading(verts.size(), tris, normals, uvs, material_ids, tangents);
  write([&] { scene_.replace_mesh(mesh, std::move(verts), std::move(tris), std::move(shading)); });
}

uint32_t PyScene::add_instance(int64_t mesh, py::handle transform, bool visible_shadow, int receiver_set,
                               int blocker_set, bool visible_camera, bool visible_diffuse, bool visible_glossy,
                               bool visible_transmission, uint64_t light_receivers) {
  const Mat4 m = to_matrix(transform, "transform");
  const uint8_t visibility =
      uint8_t((visible_camera ? kVisibleCamera : 0) | (visible_diffuse ? kVisibleDiffuse : 0) |
              (visible_glossy ? kVisibleGlossy : 0) | (visible_transmission ? kVisibleTransmission : 0));
  return write([&] {
    return scene_.add_instance(mesh, m, visible_shadow, receiver_set, blocker_set, visibility, light_receivers);
  });
}

void PyScene::set_instance_transform(int64_t instance, py::handle transform) {
  const Mat4 m = to_matrix(transform, "transform");
  write([&] { scene_.set_instance_transform(instance, m); });
}

void PyScene::clear_instances() {
  write([&] { scene_.clear_instances(); });
}

namespace {

// The emission every material kind accepts (materials/emission.h), read before the kind reads
// its own parameters: emission (linear RGB radiance, colour x strength), emission_texture (-1:
// none; else the colour's image, emission its strength) and emission_sampling
// (Blender 4.x's names: 'NONE', 'AUTO', 'FRONT', 'BACK', 'FRONT_AND_BACK'; AUTO samples both).
MaterialEmission emission_of(const Params& params) {
  MaterialEmission e;
  e.radiance = params.color("emission", e.radiance);
  e.texture = int32_t(params.integer("emission_texture", e.texture));
  const std::string sampling = params.text("emission_sampling", "AUTO");
  if (sampling == "NONE")
    e.sampled = false;
  else if (sampling == "FRONT")
    e.sides = EmitterSides::Front;
  else if (sampling == "BACK")
    e.sides = EmitterSides::Back;
  else if (sampling != "AUTO" && sampling != "FRONT_AND_BACK")
    throw std::invalid_argument("emission_sampling must be 'NONE', 'AUTO', 'FRONT', 'BACK' or 'FRONT_AND_BACK', got '" +
                                sampling + "'");
  return e;
}

// The transparency every material kind accepts (materials/transparency.h): opacity (1: opaque;
// the constant, clamped to [0, 1] where read), opacity_texture (-1: none), opacity_channel
// ('alpha' or 'gray'), opacity_invert (False) and transparent_color ((1, 1, 1)).
MaterialTransparency transparency_of(const Params& params) {
  MaterialTransparency t;
  t.opacity = float(params.number("opacity", t.opacity));
  t.texture = int32_t(params.integer("opacity_texture", t.texture));
  const std::string channel = params.text("opacity_channel", "alpha");
  if (channel == "gray")
    t.channel = OpacityChannel::Gray;
  else if (channel != "alpha")
    throw std::invalid_argument("opacity_channel must be 'alpha' or 'gray', got '" + channel + "'");
  t.invert = params.flag("opacity_invert", t.invert);
  t.color = params.color("transparent_color", t.color);
  return t;
}

}  // namespace

uint32_t PyScene::add_material(const std::string& kind, const Params& params) {
  const MaterialEmission emission = emission_of(params);
  const MaterialTransparency transparency = transparency_of(params);
  const MaterialNormalMap normal_map = MaterialNormalMap::from_params(params);
  // A Mix or Add Shader (materials/material_mix.h): its own slot holds a black diffuse, never
  // shaded, beside the mix that names the two materials it stands for.
  const bool mix = kind == "mix";
  const MaterialMix mixed = mix ? MaterialMix::from_params(params) : MaterialMix{};
  const Material material = mix ? Material(Lambert{Vec3(0.0f)}) : make_material(kind, params);
  if (mix) params.check_all_read();
  return write([&] {
    if (mix) scene_.check_mix(int64_t(scene_.materials().size()), mixed);  // before anything changes
    const uint32_t id = scene_.add_material(material, emission, transparency, normal_map);
    if (mix) scene_.set_mix(id, mixed);
    return id;
  });
}

void PyScene::set_material(int64_t id, const std::string& kind, const Params& params) {
  const MaterialEmission emission = emission_of(params);
  const MaterialTransparency transparency = transparency_of(params);
  const MaterialNormalMap normal_map = MaterialNormalMap::from_params(params);
  const bool mix = kind == "mix";
  const MaterialMix mixed = mix ? MaterialMix::from_params(params) : MaterialMix{};
  const Material material = mix ? Material(Lambert{Vec3(0.0f)}) : make_material(kind, params);
  if (mix) params.check_all_read();
  write([&] {
    if (mix) scene_.check_mix(id, mixed);  // before anything changes
    scene_.set_material(id, material, emission, transparency, normal_map);
    if (mix) scene_.set_mix(id, mixed);
  });
}

uint32_t PyScene::add_texture(py::handle pixels, bool srgb) {
  Texture t = to_texture(pixels, srgb);
  return write([&] { return scene_.add_texture(std::move(t)); });
}

void PyScene::set_texture(int64_t id, py::handle pixels, bool srgb) {
  Texture t = to_texture(pixels, srgb);
  write([&] { scene_.set_texture(id, std::move(t)); });
}

uint32_t PyScene::add_light(const std::string& type, const Params& params, LightVisibility visibility) {
  const Light light = make_light(type, params);
  return write([&] { return scene_.add_light(light, visibility); });
}

void PyScene::clear_lights() {
  write([&] { scene_.clear_lights(); });
}

void PyScene::set_background(py::handle color) {
  const Vec3 c = to_vec3(color, "background");
  write([&] { scene_.set_background(c); });
}

py::tuple PyScene::background() {
  const Vec3 b = read([&] { return scene_.world().background; });
  return py::make_tuple(b.x, b.y, b.z);
}

void PyScene::set_background_lighting(bool on) {
  write([&] { scene_.set_background_lighting(on); });
}

void PyScene::set_environment(int64_t texture, py::handle strength, py::handle matrix) {
  const Vec3 k = to_vec3(strength, "strength");
  // A (3, 3) rotation/scale, or a (4, 4) matrix whose upper-left 3x3 is used; None: identity.
  glm::mat3 m(1.0f);
  if (!matrix.is_none()) {
    const auto a = contiguous<double>(matrix, "matrix");
    if (a.ndim() != 2 || a.shape(0) != a.shape(1) || (a.shape(0) != 3 && a.shape(0) != 4))
      throw py::value_error("matrix must be None, a (3, 3) or a (4, 4) array");
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) m[c][r] = float(a.at(r, c));  // row-major in, GLM columns
    for (int c = 0; c < 3; ++c)
      if (!is_finite(m[c])) throw py::value_error("matrix must be finite");
  }
  write([&] { scene_.set_environment(texture, k, m); });
}

bool PyScene::background_lighting() {
  return read([&] { return scene_.world().background_lights_surfaces; });
}

void PyScene::set_background_visible_camera(bool on) {
  write([&] { scene_.set_background_visible_camera(on); });
}

bool PyScene::background_visible_camera() {
  return read([&] { return scene_.world().background_visible_camera; });
}

void PyScene::set_background_visible_glossy(bool on) {
  write([&] { scene_.set_background_visible_glossy(on); });
}

bool PyScene::background_visible_glossy() {
  return read([&] { return scene_.world().background_visible_glossy; });
}

void PyScene::set_background_visible_transmission(bool on) {
  write([&] { scene_.set_background_visible_transmission(on); });
}

bool PyScene::background_visible_transmission() {
  return read([&] { return scene_.world().background_visible_transmission; });
}

bool PyScene::commit(const std::string& builder, int threads, py::handle expected_rays, py::object should_cancel) {
  CommitOptions options;
  options.builder = parse_builder(builder);
  options.threads = threads;
  if (!expected_rays.is_none()) {
    if (!py::isinstance<py::int_>(expected_rays) && !py::isinstance<py::float_>(expected_rays))
      throw py::type_error("expected_rays must be a number (or None when unknown)");
    options.expected_rays = expected_rays.cast<double>();
  }
  // Polled by the core on this thread (which released the GIL) every 10 ms: take the GIL for
  // Python, as Blender's test_break needs.
  CancelPoll poll;
  if (!should_cancel.is_none()) {
    poll = [&] {
      py::gil_scoped_acquire gil;
      return should_cancel().cast<bool>();
    };
  }
  bool done;
  std::string warning;
  {
    py::gil_scoped_release release;
    std::unique_lock lock(mutex_);
    done = scene_.commit(options, poll);
    warning = scene_.commit_stats().warning;
  }
  // One clear warning when the LBVH could not run and the SAH builder stood in.
  if (!warning.empty() && PyErr_WarnEx(PyExc_RuntimeWarning, warning.c_str(), 1) != 0) throw py::error_already_set();
  return done;
}

py::dict PyScene::last_commit() {
  const CommitStats st = read([&] { return scene_.commit_stats(); });
  py::dict d;
  d["build_ms"] = st.build_ms;
  d["lbvh_compile_ms"] = st.lbvh_compile_ms;
  d["meshes_built"] = st.meshes_built;
  d["sah_meshes"] = st.sah_meshes;
  d["lbvh_meshes"] = st.lbvh_meshes;
  d["emissive_triangles"] = st.emissive_triangles;
  d["emitters_ms"] = st.emitters_ms;
  d["emitter_tree_nodes"] = st.emitter_tree_nodes;
  d["light_tree_nodes"] = st.light_tree_nodes;
  d["light_tree_ms"] = st.light_tree_ms;
  d["warning"] = st.warning;
  return d;
}

namespace {
struct Rays {
  FloatArray org, dir;
  std::vector<py::ssize_t> leading;  // the rays' shape without the trailing 3
};
Rays rays(py::handle origins, py::handle directions) {
  Rays r;
  std::vector<py::ssize_t> dir_leading;
  r.org = as_point_grid(origins, "origins", r.leading);
  r.dir = as_point_grid(directions, "directions", dir_leading);
  if (r.org.shape(0) != r.dir.shape(0) || r.leading != dir_leading)
    throw py::value_error("origins and directions must hold the same number of rays, got " +
                          std::to_string(r.org.shape(0)) + " and " + std::to_string(r.dir.shape(0)));
  return r;
}
}  // namespace

py::dict PyScene::intersect(py::handle origins, py::handle directions, py::handle tnear, py::handle tfar, int threads,
                            bool normals, bool mesh_ids) {
  const Rays r = rays(origins, directions);
  const FloatArray &org = r.org, &dir = r.dir;
  const size_t n = size_t(org.shape(0));
  const PerRay near = per_ray(tnear, n, "tnear"), far = per_ray(tfar, n, "tfar");
  py::array_t<float> t(n), u(n), v(n);
  py::array_t<int32_t> prim(n), instance(n);
  const RayBatch batch{org.data(), dir.data(), near.data, near.stride, far.data, far.stride, n};
  const HitBatch hits{t.mutable_data(), u.mutable_data(), v.mutable_data(), prim.mutable_data(),
                      instance.mutable_data()};
  // Opt-in fields, filled from the hits under the same lock: the plain query stays as fast.
  py::array_t<float> normal(normals ? std::vector<py::ssize_t>{py::ssize_t(n), 3} : std::vector<py::ssize_t>{0, 3});
  py::array_t<int32_t> mesh(mesh_ids ? n : 0);
  float* normal_out = normal.mutable_data();
  int32_t* mesh_out = mesh.mutable_data();
  {
    py::gil_scoped_release release;
    std::shared_lock lock(mutex_);
    scene_.intersect(batch, hits, threads);
    if (normals || mesh_ids) hit_extras(hits, n, normals ? normal_out : nullptr, mesh_ids ? mesh_out : nullptr);
  }
  py::dict out;
  out["t"] = shaped(t, r.leading);
  out["prim"] = shaped(prim, r.leading);
  out["instance"] = shaped(instance, r.leading);
  out["u"] = shaped(u, r.leading);
  out["v"] = shaped(v, r.leading);
  if (normals) out["normal"] = shaped(normal, r.leading);
  if (mesh_ids) out["mesh"] = shaped(mesh, r.leading);
  return out;
}

py::array PyScene::occluded(py::handle origins, py::handle directions, py::handle tnear, py::handle tfar, int threads) {
  const Rays r = rays(origins, directions);
  const size_t n = size_t(r.org.shape(0));
  const PerRay near = per_ray(tnear, n, "tnear"), far = per_ray(tfar, n, "tfar");
  py::array_t<bool> blocked(n);
  static_assert(sizeof(bool) == sizeof(uint8_t));
  const RayBatch batch{r.org.data(), r.dir.data(), near.data, near.stride, far.data, far.stride, n};
  {
    py::gil_scoped_release release;
    std::shared_lock lock(mutex_);
    scene_.occluded(batch, reinterpret_cast<uint8_t*>(blocked.mutable_data()), threads);
  }
  return shaped(blocked, r.leading);
}

size_t PyScene::mesh_count() {
  return read([&] { return scene_.mesh_count(); });
}
size_t PyScene::instance_count() {
  return read([&] { return scene_.instance_count(); });
}
size_t PyScene::triangle_count() {
  return read([&] { return scene_.stored_triangle_count(); });
}
size_t PyScene::memory_bytes() {
  return read([&] { return scene_.memory_bytes(); });
}
bool PyScene::committed() {
  return read([&] { return scene_.committed(); });
}
double PyScene::build_ms() {
  return read([&] { return scene_.commit_stats().build_ms; });
}

}  // namespace toyrt::binding
