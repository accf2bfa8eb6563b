#include "scene/scene.h"

#include <algorithm>

#include "accel/traverse.h"
#include "accel/wide_traverse.h"
#include "core/parallel.h"
#include "scene/instance_bounds.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <glm/gtc/matrix_inverse.hpp>

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <future>
#include <stdexcept>
#include <thread>

namespace toyrt {

void Scene::check_mesh_id(int64_t mesh) const {
  if (mesh < 0 || size_t(mesh) >= meshes_.size())
    throw std::invalid_argument("unknown mesh id " + std::to_string(mesh) + " (the scene has " +
                                std::to_string(meshes_.size()) + " meshes)");
}

uint32_t Scene::add_mesh(std::vector<Vec3> vertices, std::vector<Triangle> triangles, MeshShading shading) {
  const int32_t max_material = shading.check(triangles.size());
  auto mesh = std::make_unique<Mesh>(std::move(vertices), std::move(triangles));  // validates
  meshes_.push_back(std::move(mesh));
  shading_.push_back(std::move(shading));
  max_material_id_.push_back(max_material);
  committed_ = false;
  return uint32_t(meshes_.size() - 1);
}

Scene::CheckedInverse Scene::checked_inverse(const Mat4& to_world) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(to_world[c][r])) throw std::invalid_argument("instance transform is not finite");
  if (to_world[0][3] != 0.0f || to_world[1][3] != 0.0f || to_world[2][3] != 0.0f || to_world[3][3] != 1.0f)
    throw std::invalid_argument("instance transform must be affine: its last row must be 0 0 0 1");
  const double det = glm::determinant(glm::dmat3(glm::mat3(to_world)));
  // Inverted in double and rounded once: glm's float inverse forms the determinant and cofactors
  // in float, which overflow or underflow for scales a double holds (a uniform scale of 1e13 gave
  // an inverse of zeros), and rounds each entry several times.
  const Mat4 to_object(glm::affineInverse(glm::dmat4(to_world)));
  bool finite_inverse = true;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) finite_inverse &= bool(std::isfinite(to_object[c][r]));
  if (det == 0.0 || !finite_inverse)
    throw std::invalid_argument("instance transform is singular (zero scale): it cannot be inverted");
  // A determinant of rounded products can be non-zero for rows that are exactly dependent; what
  // matters is whether the float inverse carries rays into object space with a bounded error
  // (instance_bounds.h).
  const TransformError error = transform_error(to_world, to_object);
  if (!error.invertible()) {
    char what[96];
    std::snprintf(what, sizeof what, "%.3g (|to_world * to_object - I| + rounding %.3g)", error.inverse + error.spread,
                  error.spread);
    throw std::invalid_argument(std::string("instance transform is nearly singular: rays carried into its object "
                                            "space in single precision would be off by ") +
                                what + "; apply the transform to the vertices instead");
  }
  return {to_object, error};
}

uint32_t Scene::add_instance(int64_t mesh, const Mat4& to_world, bool visible_shadow, int receiver_set, int blocker_set,
                             uint8_t visibility, uint64_t light_receivers) {
  check_mesh_id(mesh);
  if (receiver_set < 0 || receiver_set >= kLightSets || blocker_set < 0 || blocker_set >= kLightSets)
    throw std::invalid_argument("light-linking set must be in [0, 64): receiver_set " + std::to_string(receiver_set) +
                                ", blocker_set " + std::to_string(blocker_set));
  const CheckedInverse inverse = checked_inverse(to_world);
  Instance inst;
  inst.mesh = uint32_t(mesh);
  inst.to_world = to_world;
  inst.to_object = inverse.to_object;
  inst.identity = to_world == Mat4(1.0f);
  inst.visible_shadow = visible_shadow;
  inst.receiver_set = uint8_t(receiver_set);
  inst.blocker_set = uint8_t(blocker_set);
  inst.visibility = visibility & kVisibleAll;
  inst.light_receivers = light_receivers;
  instances_.push_back(inst);
  transform_errors_.push_back(inverse.error);
  committed_ = false;
  return uint32_t(instances_.size() - 1);
}

void Scene::replace_mesh(int64_t mesh, std::vector<Vec3> vertices, std::vector<Triangle> triangles,
                         MeshShading shading) {
  check_mesh_id(mesh);
  // Checked and built before the swap, so a refused mesh leaves the old one in place.
  const int32_t max_material = shading.check(triangles.size());
  auto replacement = std::make_unique<Mesh>(std::move(vertices), std::move(triangles));
  // The single-mesh path's pointer follows, as an instance's mesh index does (never dangling,
  // even for a ray traced before the next commit).
  if (single_mesh_ == meshes_[size_t(mesh)].get()) single_mesh_ = replacement.get();
  meshes_[size_t(mesh)] = std::move(replacement);
  shading_[size_t(mesh)] = std::move(shading);
  max_material_id_[size_t(mesh)] = max_material;
  committed_ = false;
}

void Scene::set_instance_transform(int64_t instance, const Mat4& to_world) {
  if (instance < 0 || size_t(instance) >= instances_.size())
    throw std::invalid_argument("unknown instance id " + std::to_string(instance) + " (the scene has " +
                                std::to_string(instances_.size()) + " instances)");
  const CheckedInverse inverse = checked_inverse(to_world);
  Instance& inst = instances_[size_t(instance)];
  inst.to_world = to_world;
  inst.to_object = inverse.to_object;
  transform_errors_[size_t(instance)] = inverse.error;
  inst.identity = to_world == Mat4(1.0f);
  committed_ = false;
}

void Scene::clear_instances() {
  instances_.clear();  // keeps the capacity: a re-sync adds about as many again
  transform_errors_.clear();
  committed_ = false;
}

namespace {

// Whether a ray can be traced: finite origin and direction, a direction other than 0, and
// tnear <= tfar (false for a NaN in either). The ray's eight floats (origin, tnear, direction,
// tfar) are checked as one vector: every ray pays this, and one test per component was about 35
// instructions a ray.
bool is_traceable(const Ray& ray) {
  static_assert(kWidth == 8, "one lane for each of the ray's origin, tnear, direction and tfar floats");
  // Made from the fields, not copied from the ray's 32 bytes: a ray that RayBatch::at has just
  // written sits in the store queue as six smaller stores, which one 32-byte load cannot take
  // from there, so it waited for them to reach the cache (this and the batch loops' inlined
  // call: a batch's camera rays at 10K triangles 6-9 % faster, docs/trace-speed.md,
  // thirty-eighth session). Where the ray is in memory already, GCC still makes this one load.
  // (Not through simd::load either: a ray is 16-byte aligned at best, which clang's vector types
  // do not accept; found by tests/fuzz.)
  const simd::vfloat v = {ray.org.x, ray.org.y, ray.org.z, ray.tnear, ray.dir.x, ray.dir.y, ray.dir.z, ray.tfar};
  const uint32_t finite = simd::mask_of((v - v) == 0.0f);  // inf - inf and NaN - NaN are NaN
  const uint32_t nonzero = simd::mask_of(v != 0.0f);
  constexpr uint32_t kOrigin = 0x07, kDirection = 0x70;
  return (finite & (kOrigin | kDirection)) == (kOrigin | kDirection) && (nonzero & kDirection) != 0 &&
         ray.tnear <= ray.tfar;
}

void check_texture_id(const Material& m, size_t textures) {
  const int32_t texture = texture_of(m);
  if (texture < -1 || texture >= int64_t(textures))
    throw std::invalid_argument("unknown texture id " + std::to_string(texture) + " (the scene has " +
                                std::to_string(textures) + " textures)");
}
}  // namespace

uint32_t Scene::add_material(const Material& material, const MaterialEmission& emission,
                             const MaterialTransparency& transparency, const MaterialNormalMap& normal_map) {
  check_texture_id(material, textures_.size());
  emission.check(textures_.size());
  transparency.check(textures_.size());
  normal_map.check(textures_.size());
  materials_.push_back(material);
  emission_.push_back(emission);
  transparency_.push_back(transparency);
  normal_maps_.push_back(normal_map);
  mixes_.emplace_back();
  any_transparency_ = any_transparency_ || transparency.transparent();
  any_normal_map_ = any_normal_map_ || normal_map.active();
  any_bump_footprint_ = any_bump_footprint_ || (normal_map.active() && normal_map.bump && normal_map.bump_footprint);
  if (emission.emits()) {
    any_emission_ = true;
    committed_ = false;
  }
  return uint32_t(materials_.size() - 1);
}

void Scene::set_material(int64_t material, const Material& replacement, const MaterialEmission& emission,
                         const MaterialTransparency& transparency, const MaterialNormalMap& normal_map) {
  if (material < 0 || size_t(material) >= materials_.size())
    throw std::invalid_argument("unknown material id " + std::to_string(material));
  check_texture_id(replacement, textures_.size());
  emission.check(textures_.size());
  transparency.check(textures_.size());
  normal_map.check(textures_.size());
  materials_[size_t(material)] = replacement;
  transparency_[size_t(material)] = transparency;
  normal_maps_[size_t(material)] = normal_map;
  if (mixes_[size_t(material)].active) {
    mixes_[size_t(material)] = MaterialMix{};
    any_mix_ = std::any_of(mixes_.begin(), mixes_.end(), [](const MaterialMix& m) { return m.active; });
  }
  any_normal_map_ =
      std::any_of(normal_maps_.begin(), normal_maps_.end(), [](const MaterialNormalMap& n) { return n.active(); });
  any_bump_footprint_ = std::any_of(normal_maps_.begin(), normal_maps_.end(), [](const MaterialNormalMap& n) {
    return n.active() && n.bump && n.bump_footprint;
  });
  any_transparency_ = std::any_of(transparency_.begin(), transparency_.end(),
                                  [](const MaterialTransparency& t) { return t.transparent(); });
  if (!(emission_[size_t(material)] == emission)) {
    emission_[size_t(material)] = emission;
    any_emission_ =
        std::any_of(emission_.begin(), emission_.end(), [](const MaterialEmission& e) { return e.emits(); });
    committed_ = false;  // the emissive triangles are gathered again
  }
}

void Scene::set_mix(int64_t material, const MaterialMix& mix) {
  if (material < 0 || size_t(material) >= materials_.size())
    throw std::invalid_argument("unknown material id " + std::to_string(material));
  check_mix(material, mix);
  mixes_[size_t(material)] = mix;
  any_mix_ = std::any_of(mixes_.begin(), mixes_.end(), [](const MaterialMix& m) { return m.active; });
}

void Scene::check_mix(int64_t material, const MaterialMix& mix) const {
  mix.check(material, materials_.size(), textures_.size());
  // No cycles: nothing this mix reaches through other mixes may lead back to it (the render
  // would draw forever; pick_mixed stops at a depth bound anyway).
  std::vector<int32_t> todo{mix.first, mix.second};
  for (size_t steps = 0; !todo.empty(); ++steps) {
    const int32_t id = todo.back();
    todo.pop_back();
    if (id == material || steps > 4 * materials_.size())
      throw std::invalid_argument("mix " + std::to_string(material) + " would contain itself");
    if (id >= 0 && mixes_[size_t(id)].active) {
      todo.push_back(mixes_[size_t(id)].first);
      todo.push_back(mixes_[size_t(id)].second);
    }
  }
}

uint32_t Scene::add_texture(Texture texture) {
  textures_.push_back(std::move(texture));
  return uint32_t(textures_.size() - 1);
}

void Scene::set_texture(int64_t texture, Texture replacement) {
  if (texture < 0 || size_t(texture) >= textures_.size())
    throw std::invalid_argument("unknown texture id " + std::to_string(texture));
  textures_[size_t(texture)] = std::move(replacement);
  // Emissive triangles weigh textured ones by their pixels (Scene::gather_emitters).
  if (std::any_of(emission_.begin(), emission_.end(),
                  [&](const MaterialEmission& e) { return e.texture == texture && e.emits(); }))
    committed_ = false;
  // The environment's sampling grid was made from the old pixels.
  const Environment& env = world_.environment;
  if (env.texture == texture) set_environment(texture, env.strength, env.to_map);
}

uint32_t Scene::add_light(const Light& light, LightVisibility visibility) {
  world_.lights.push_back(light);
  world_.light_visibility.push_back(visibility);
  light_tree_current_ = false;
  // Kept only once some light does not light every receiver, so unlinked scenes check nothing.
  const uint64_t reach = visibility.diffuse ? visibility.receiver_sets : 0;
  if (reach != kAllLightSets || !light_reach_.empty()) {
    light_reach_.resize(world_.lights.size() - 1, kAllLightSets);  // the full masks of the lights before
    light_reach_.push_back(reach);
  }
  return uint32_t(world_.lights.size() - 1);
}

void Scene::clear_lights() {
  world_.lights.clear();
  world_.light_visibility.clear();
  light_reach_.clear();
  light_tree_current_ = false;
}

void Scene::set_background(const Vec3& radiance) {
  if (!is_finite(radiance) || glm::any(glm::lessThan(radiance, Vec3(0.0f))))
    throw std::invalid_argument("background must be finite and >= 0");
  world_.background = radiance;
}

void Scene::set_environment(int64_t texture, const Vec3& strength, const glm::mat3& to_map) {
  if (texture < 0) {
    world_.environment = Environment{};
    return;
  }
  if (size_t(texture) >= textures_.size()) throw std::invalid_argument("unknown texture id " + std::to_string(texture));
  world_.environment = make_environment(int32_t(texture), textures_[size_t(texture)], strength, to_map);
}

void Scene::check_committed() const {
  if (!committed_)
    throw std::logic_error(instances_.empty() && meshes_.empty()
                               ? "query before commit(): add meshes, then call commit()"
                               : "the scene changed since the last commit(): call commit() before queries");
}

void Scene::check_renderable() const {
  check_committed();
  const size_t count = materials_.size();
  for (size_t mesh = 0; mesh < meshes_.size(); ++mesh) {
    const int32_t id = max_material_id_[mesh];
    if (id >= 0 && size_t(id) >= count && !(count == 0 && id == 0))
      throw std::invalid_argument("mesh " + std::to_string(mesh) + " uses material id " + std::to_string(id) +
                                  " but the scene has " + std::to_string(count) + " materials");
  }
}

bool Scene::commit(const CommitOptions& options, const CancelPoll& should_cancel) {
  check_threads(options.threads);
  if (options.expected_rays && !(std::isfinite(*options.expected_rays) && *options.expected_rays >= 0.0))
    throw std::invalid_argument("expected_rays must be a finite number >= 0 (or None when unknown)");
  if (!should_cancel) {
    build(options, nullptr);
    return true;
  }
  // The build runs on its own thread while this one polls should_cancel every 10 ms; a true
  // answer, or an exception from it, sets the flag the builders poll. The worker is joined
  // before anything else happens, exceptions included.
  std::atomic<bool> cancel{false};
  std::packaged_task<void()> task([&] { build(options, &cancel); });
  std::future<void> done = task.get_future();
  std::thread worker(std::move(task));
  std::exception_ptr poll_error;
  while (done.wait_for(std::chrono::milliseconds(10)) != std::future_status::ready) {
    if (cancel.load() || poll_error) continue;
    try {
      if (should_cancel()) cancel.store(true);
    } catch (...) {
      poll_error = std::current_exception();
      cancel.store(true);
    }
  }
  worker.join();
  bool cancelled = false;
  try {
    done.get();
  } catch (const BuildCancelled&) {
    cancelled = true;
  }
  if (poll_error) std::rethrow_exception(poll_error);
  return !cancelled;
}

void Scene::build(const CommitOptions& options, const std::atomic<bool>* cancel) {
  const auto start = std::chrono::steady_clock::now();
  stats_ = {};
  instances_.shrink_to_fit();  // many instances are added one by one: drop the growth slack
  committed_ = false;          // until this commit completes (it may be cancelled)
  BuildConfig config;
  static_cast<BuilderSettings&>(config) = options;  // every builder's settings, whatever builders there are
  config.sah.cancel = cancel;
  config.expected_rays = options.expected_rays.value_or(-1.0);
  auto check_cancel = [&] {
    if (cancel && cancel->load(std::memory_order_relaxed)) throw BuildCancelled();
  };
  run_with_threads(options.threads, [&] {
    // Meshes first (each build is parallel inside), then the top level over their boxes.
    for (auto& mesh : meshes_) {
      if (mesh->built()) continue;
      check_cancel();
      BuildStats built;
      mesh->build(options.builder, config, &built);
      stats_.lbvh_compile_ms += built.lbvh_compile_ms;
      if (stats_.warning.empty()) stats_.warning = built.warning;  // one message per commit
      ++(built.used == BuilderKind::Lbvh ? stats_.lbvh_meshes : stats_.sah_meshes);
      ++stats_.meshes_built;
    }
    std::vector<uint32_t> placed;
    std::vector<BBox> boxes;
    origin_pad_factor_ = 0.0f;
    for (uint32_t i = 0; i < instances_.size(); ++i) {
      Instance& inst = instances_[i];
      const BBox& b = meshes_[inst.mesh]->bounds();
      inst.world_bounds = BBox{};
      if (meshes_[inst.mesh]->wide_bvh().empty()) continue;  // nothing to hit
      if (inst.identity) {
        inst.world_bounds = b;  // the walk's ray is the world ray: the mesh box is exact
      } else {
        const TransformError& error = transform_errors_[i];
        inst.world_bounds = instance_world_bounds(b, inst.to_world, error);
        origin_pad_factor_ = std::max(origin_pad_factor_, origin_pad_factor(error));
      }
      placed.push_back(i);
      boxes.push_back(inst.world_bounds);
    }
    check_cancel();
    BuildConfig top_config = config;
    top_config.sah.max_leaf = 1;  // an instance test is a whole traversal: never group them
    top_ = build_bvh(BuilderKind::Sah, boxes.data(), boxes.size(), top_config);
    for (uint32_t& id : top_.prim_ids) id = placed[id];
    single_mesh_ = instances_.size() == 1 && instances_[0].identity ? meshes_[instances_[0].mesh].get() : nullptr;
    all_cast_shadows_ =
        std::all_of(instances_.begin(), instances_.end(), [](const Instance& i) { return i.visible_shadow; });
    all_visible_ = std::all_of(instances_.begin(), instances_.end(),
                               [](const Instance& i) { return i.visibility == kVisibleAll; });
    // The lights' structures on the commit's threads too: the lamp BVH's builder makes tasks from
    // 512 lamps (BinnedSahConfig::task_threshold), which a one-thread commit must not spread.
    const auto gather_start = std::chrono::steady_clock::now();
    gather_emitters();
    stats_.emissive_triangles = emitters_.triangles.size();
    stats_.emitter_tree_nodes = emitters_.tree.node_count();
    stats_.emitters_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - gather_start).count();
    if (!light_tree_current_) {
      // Only when the lights changed: a viewport edit of a mesh does not rebuild it. A scene of
      // few lights keeps no tree (the linear walk is cheaper there: kLightTreeFrom).
      const auto tree_start = std::chrono::steady_clock::now();
      light_tree_ = world_.lights.size() > kLightTreeFrom ? LightTree(world_.lights) : LightTree{};
      if (light_tree_.node_count() > 0) light_tree_.set_receiver_sets(light_reach_);
      lamp_bvh_ = world_.lights.size() >= kLampBvhFrom ? build_lamp_bvh(world_.lights) : LampBvh{};
      light_tree_current_ = true;
      stats_.light_tree_ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tree_start).count();
    }
  });
  stats_.light_tree_nodes = light_tree_.node_count();
  committed_ = true;
  stats_.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

namespace {

// An instance's mesh traced by a ray carried into its object space (org, dir): the triangle the
// ray leaves skipped where the ray names it in instance `id`, the instance named on a hit.
// identity: org and dir are the world ray's, whose finite components Scene::trace has checked.
template <bool AnyHit>
[[gnu::always_inline]] inline bool trace_mesh(const Mesh& mesh, uint32_t id, const Vec3& org, const Vec3& dir,
                                              bool identity, const Ray& ray, float& t_max, Hit& hit) {
  const int32_t skip = ray.self.instance == int32_t(id) ? ray.self.prim : kInvalidId;
  if constexpr (AnyHit) {
    return mesh.occluded(org, dir, ray.tnear, t_max, identity, skip);
  } else {
    if (!mesh.intersect(org, dir, ray.tnear, t_max, hit.u, hit.v, hit.prim, identity, skip)) return false;
    hit.instance = int32_t(id);
    return true;
  }
}

}  // namespace

template <bool AnyHit, bool ShadowCastersOnly, bool Visibility>
[[gnu::always_inline]] inline bool Scene::trace_instance(uint32_t id, const Ray& ray, float& t_max, Hit& hit,
                                                         uint64_t blockers, uint8_t seen_by) const {
  const Instance& inst = instances_[id];
  if constexpr (ShadowCastersOnly) {
    if (!inst.visible_shadow || !in_light_sets(blockers, inst.blocker_set)) return false;
  }
  if constexpr (Visibility) {
    if (!(inst.visibility & seen_by)) return false;
  }
  const Mesh& mesh = *meshes_[inst.mesh];
  if (inst.identity) return trace_mesh<AnyHit>(mesh, id, ray.org, ray.dir, true, ray, t_max, hit);
  const Vec3 org(inst.to_object * glm::vec4(ray.org, 1.0f)), dir(glm::mat3(inst.to_object) * ray.dir);
  return trace_mesh<AnyHit>(mesh, id, org, dir, false, ray, t_max, hit);
}

template <bool AnyHit, bool ShadowCastersOnly, bool Visibility>
bool Scene::trace(const Ray& ray, Hit& hit, uint64_t blockers, uint8_t seen_by) const {
  if (!is_traceable(ray)) return false;
  if (!single_mesh_) return trace_instances<AnyHit, ShadowCastersOnly, Visibility>(ray, hit, blockers, seen_by);
  // One untransformed instance (a single mesh): no top level. Kept apart from the top-level walk,
  // whose stack and registers made this path's every call set up a 1 KB frame (a diffuse ray at
  // 10K triangles: 1,052 -> 1,031 instructions, docs/trace-speed.md).
  float tfar = ray.tfar;
  // Nor an instance record to read, but in the light-linking and visibility variants, which test
  // its flags: the mesh kept at commit, two dependent loads fewer a ray (10K triangles: camera
  // rays 1 %, diffuse 2 %, shadow rays 4 % faster, docs/trace-speed.md, thirty-eighth session).
  const bool found = !ShadowCastersOnly && !Visibility
                         ? trace_mesh<AnyHit>(*single_mesh_, 0, ray.org, ray.dir, true, ray, tfar, hit)
                         : trace_instance<AnyHit, ShadowCastersOnly, Visibility>(0, ray, tfar, hit, blockers, seen_by);
  if (found) hit.t = tfar;
  return found;
}

template <bool AnyHit, bool ShadowCastersOnly, bool Visibility>
[[gnu::noinline]] bool Scene::trace_instances(const Ray& ray, Hit& hit, uint64_t blockers, uint8_t seen_by) const {
  float tfar = ray.tfar;
  const RayBoxData box_ray = make_ray_box_data(ray.org, ray.dir, instance_box_pad(ray.org));
  const bool found =
      traverse<AnyHit>(top_, box_ray, ray.tnear, tfar, [&](uint32_t first, uint32_t count, float& t_max) {
        bool any = false;
        for (uint32_t k = first; k < first + count; ++k) {
          if (trace_instance<AnyHit, ShadowCastersOnly, Visibility>(top_.prim_ids[k], ray, t_max, hit, blockers,
                                                                    seen_by)) {
            any = true;
            if constexpr (AnyHit) return true;
          }
        }
        return any;
      });
  if (found) hit.t = tfar;
  return found;
}

Hit Scene::intersect(const Ray& ray) const {
  Hit hit;
  if (!trace<false>(ray, hit)) hit = Hit{};
  return hit;
}

bool Scene::occluded(const Ray& ray) const {
  Hit unused;
  return trace<true>(ray, unused);
}

bool Scene::occluded_by_shadow_casters(const Ray& ray, uint64_t blockers) const {
  Hit unused;
  return trace<true, true>(ray, unused, blockers);
}

Hit Scene::intersect_visible(const Ray& ray, uint8_t seen_by) const {
  Hit hit;
  if (!trace<false, false, true>(ray, hit, kAllLightSets, seen_by)) hit = Hit{};
  return hit;
}

bool Scene::occluded_visible(const Ray& ray, uint8_t seen_by) const {
  Hit unused;
  return trace<true, false, true>(ray, unused, kAllLightSets, seen_by);
}

Hit Scene::intersect_shadow_casters(const Ray& ray, uint64_t blockers) const {
  Hit hit;
  const bool all = all_cast_shadows_ && blockers == kAllLightSets;
  if (!(all ? trace<false>(ray, hit) : trace<false, true>(ray, hit, blockers))) hit = Hit{};
  return hit;
}

namespace {

// Rays per task: enough to amortise scheduling, few enough to balance incoherent batches.
constexpr size_t kRayGrain = 256;

}  // namespace

void Scene::intersect(const RayBatch& rays, const HitBatch& hits, int threads) const {
  check_committed();
  check_threads(threads);
  run_with_threads(threads, [&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.count, kRayGrain), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) {
        // intersect(ray)'s body, inlined here: a call and a returned Hit fewer a ray.
        Hit h;
        if (!trace<false>(rays.at(i), h)) h = Hit{};
        hits.t[i] = h.t;
        hits.u[i] = h.u;
        hits.v[i] = h.v;
        hits.prim[i] = h.prim;
        hits.instance[i] = h.instance;
      }
    });
  });
}

void Scene::occluded(const RayBatch& rays, uint8_t* blocked, int threads) const {
  check_committed();
  check_threads(threads);
  run_with_threads(threads, [&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.count, kRayGrain), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) {
        Hit unused;  // occluded(ray)'s body, inlined as in intersect's batch above
        blocked[i] = trace<true>(rays.at(i), unused) ? 1 : 0;
      }
    });
  });
}

size_t Scene::stored_triangle_count() const {
  size_t n = 0;
  for (const auto& m : meshes_) n += m->triangles().size();
  return n;
}

size_t Scene::instanced_triangle_count() const {
  size_t n = 0;
  for (const Instance& inst : instances_) n += meshes_[inst.mesh]->triangles().size();
  return n;
}

size_t Scene::memory_bytes() const {
  size_t bytes = instances_.capacity() * sizeof(Instance) + top_.nodes.capacity() * sizeof(Node) +
                 top_.prim_ids.capacity() * sizeof(uint32_t);
  for (const MeshShading& sh : shading_)
    bytes += sh.corner_normals.capacity() * sizeof(Vec3) + sh.corner_uvs.capacity() * sizeof(Vec2) +
             sh.corner_tangents.capacity() * sizeof(glm::vec4) + sh.material_ids.capacity() * sizeof(int32_t);
  for (const auto& m : meshes_) bytes += m->memory_bytes();
  // Shading and lighting data the render reads: textures (the environment's image among them),
  // the environment's sampling grid, the emissive triangles and their CDF, materials and lamps.
  for (const Texture& t : textures_) bytes += t.texels.capacity() * sizeof(float);
  const Distribution2D& grid = world_.environment.sampling;
  bytes += (grid.conditional.capacity() + grid.marginal.capacity() + grid.density.capacity()) * sizeof(float);
  bytes += emitters_.memory_bytes();  // with their tree
  bytes += materials_.capacity() * sizeof(Material) + emission_.capacity() * sizeof(MaterialEmission) +
           normal_maps_.capacity() * sizeof(MaterialNormalMap) + mixes_.capacity() * sizeof(MaterialMix) +
           transparency_.capacity() * sizeof(MaterialTransparency) + world_.lights.capacity() * sizeof(Light);
  return bytes + light_tree_.memory_bytes() + lamp_bvh_.memory_bytes();
}

}  // namespace toyrt
