// The whole scene the core renders: the two-level geometry (meshes stored once, each with its
// own BVH, and instances placing them, gathered by a top-level BVH over the instances' world
// boxes), each mesh's shading attributes, the materials and textures, and the world (lights,
// background). It owns the policy too: every edit validates its input (std::invalid_argument
// names the bad value), commit() chooses builders and honours a cancel poll. Queries come one
// ray at a time (the integrator's) or as batches spread over threads.
//
// Thread safety: queries and renders of a committed scene are read-only and may run
// concurrently; edits and commit must not overlap with anything else (the Python binding holds
// a lock to guarantee that).
#pragma once

#include "accel/builder.h"
#include "core/cancel_poll.h"
#include "core/ray.h"
#include "geometry/mesh.h"
#include "lights/lamp_bvh.h"
#include "lights/light_selector.h"
#include "lights/mesh_emitters.h"
#include "materials/emission.h"
#include "materials/material.h"
#include "materials/material_mix.h"
#include "materials/normal_map.h"
#include "materials/texture.h"
#include "materials/transparency.h"
#include "scene/instance.h"
#include "scene/instance_bounds.h"
#include "scene/mesh_shading.h"
#include "scene/world.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace toyrt {

// The builders' own settings (sah, lbvh, cost_model) come from BuilderSettings (accel/builder.h).
struct CommitOptions : BuilderSettings {
  BuilderKind builder = BuilderKind::Auto;
  int threads = 0;  // 0: all cores
  // Rays the caller expects to trace (pixels x samples x rays per sample), for "auto"; unset:
  // unknown, and "auto" keeps the SAH builder. Must be finite and >= 0 when set.
  std::optional<double> expected_rays;
};

struct CommitStats {
  double build_ms = 0.0;         // wall time of the last commit
  double lbvh_compile_ms = 0.0;  // OpenCL kernel compilation inside it (first LBVH build of the process)
  size_t meshes_built = 0;       // meshes whose BVH the last commit (re)built
  size_t sah_meshes = 0, lbvh_meshes = 0;
  size_t emissive_triangles = 0;  // sampled as lights (world space, each instance's counted)
  double emitters_ms = 0.0;       // gathering them (and their light tree), part of build_ms
  size_t emitter_tree_nodes = 0;  // 0: no tree over them (fewer than kEmitterTreeFrom)
  size_t light_tree_nodes = 0;    // 0: no tree (kLightTreeFrom lights or fewer)
  double light_tree_ms = 0.0;     // building it (only when the lights changed), part of build_ms
  // Set when an LBVH build could not run (no OpenCL device, kernel build failure) and the SAH
  // builder stood in: one message per commit.
  std::string warning;
};

// A batch of rays as flat arrays: origins and directions are (count, 3) row-major; tnear and tfar
// are read at index i * stride, so a stride of 0 broadcasts one value to every ray.
struct RayBatch {
  const float* origins = nullptr;
  const float* directions = nullptr;
  const float* tnear = nullptr;
  size_t tnear_stride = 0;
  const float* tfar = nullptr;
  size_t tfar_stride = 0;
  size_t count = 0;
  // The triangle each ray leaves (Ray::self), one per ray; none where not given. intersect and
  // occluded read it; the geometric queries (queries/) do not.
  const TriangleRef* self = nullptr;

  // Ray i of the batch (tnear 0 and tfar infinite where their arrays are not given).
  Ray at(size_t i) const {
    Ray r;
    r.org = Vec3(origins[3 * i], origins[3 * i + 1], origins[3 * i + 2]);
    r.dir = Vec3(directions[3 * i], directions[3 * i + 1], directions[3 * i + 2]);
    r.tnear = tnear ? tnear[i * tnear_stride] : 0.0f;
    r.tfar = tfar ? tfar[i * tfar_stride] : kInfinity;
    if (self) r.self = self[i];
    return r;
  }
};

// Where a batch's hits go: one entry per ray in each array.
struct HitBatch {
  float* t = nullptr;
  float* u = nullptr;
  float* v = nullptr;
  int32_t* prim = nullptr;
  int32_t* instance = nullptr;
};

class Scene {
 public:
  // ---- geometry and shading. Ids are int64_t so that a caller's negative id is refused by
  // name ("unknown mesh id -1") instead of wrapping around.
  // Adds a mesh (no instance) and returns its id. Validation as in Mesh's constructor and
  // MeshShading::check; a refused mesh leaves the scene unchanged.
  uint32_t add_mesh(std::vector<Vec3> vertices, std::vector<Triangle> triangles, MeshShading shading = {});
  // Places mesh `mesh` with the affine object-to-world matrix `to_world`; returns the instance
  // id. Throws std::invalid_argument for an unknown mesh, a non-finite, non-affine (last row not
  // 0 0 0 1) or singular matrix.
  // `visible_shadow` false: the instance casts no shadow in a render (Instance::visible_shadow).
  // receiver_set / blocker_set: its light-linking sets (Instance; < kLightSets, else
  // std::invalid_argument). visibility: the path rays that see it (RayVisibility bits).
  // light_receivers: as an emitter, the receiver sets it lights (Instance::light_receivers).
  uint32_t add_instance(int64_t mesh, const Mat4& to_world, bool visible_shadow = true, int receiver_set = 0,
                        int blocker_set = 0, uint8_t visibility = kVisibleAll,
                        uint64_t light_receivers = kAllLightSets);
  // Edits for interactive updates (the viewport), each leaving the scene uncommitted; ids stay
  // valid. replace_mesh swaps a mesh's geometry and shading (its BVH is rebuilt by the next
  // commit, the instances placing it stay); set_instance_transform moves one instance (the next
  // commit rebuilds only the top level); clear_instances removes every instance (meshes stay).
  void replace_mesh(int64_t mesh, std::vector<Vec3> vertices, std::vector<Triangle> triangles,
                    MeshShading shading = {});
  void set_instance_transform(int64_t instance, const Mat4& to_world);
  void clear_instances();
  // The transform checks of add_instance alone; returns the inverse and its error bound.
  struct CheckedInverse {
    Mat4 to_object;
    TransformError error;
  };
  static CheckedInverse checked_inverse(const Mat4& to_world);

  // ---- materials, textures, world. Edits in place, so meshes keep their material ids; they
  // do not touch the geometry (no commit needed).
  // A Lambert texture id must name one of the scene's textures (or be -1).
  // `emission`: what the material emits beside its BSDF (materials/emission.h); a change of it
  // leaves the scene uncommitted, since commit() gathers the emissive triangles. `transparency`:
  // the part of the surface rays pass through (materials/transparency.h); its texture id is checked
  // as the material's. `normal_map`: the Normal Map node on its Normal input (materials/normal_map.h),
  // read where a mesh using it has tangents (MeshShading::corner_tangents) for tangent space.
  uint32_t add_material(const Material& material, const MaterialEmission& emission = {},
                        const MaterialTransparency& transparency = {}, const MaterialNormalMap& normal_map = {});
  void set_material(int64_t material, const Material& replacement, const MaterialEmission& emission = {},
                    const MaterialTransparency& transparency = {}, const MaterialNormalMap& normal_map = {});
  uint32_t add_texture(Texture texture);
  void set_texture(int64_t texture, Texture replacement);
  uint32_t add_light(const Light& light, LightVisibility visibility = {});
  void clear_lights();                        // lights are re-sent as a whole on an edit: they are few and cheap
  void set_background(const Vec3& radiance);  // finite and >= 0
  void set_background_lighting(bool on) { world_.background_lights_surfaces = on; }
  void set_background_visible_camera(bool on) { world_.background_visible_camera = on; }
  void set_background_visible_glossy(bool on) { world_.background_visible_glossy = on; }
  void set_background_visible_transmission(bool on) { world_.background_visible_transmission = on; }
  // The world's Environment Texture: texture `texture` (an equirectangular image) times strength,
  // looked up along to_map * direction (scene/environment.h); it replaces the background colour
  // for rays that leave the scene. texture -1 removes it. Throws std::invalid_argument for an
  // unknown texture, a bad strength or a singular mapping.
  void set_environment(int64_t texture, const Vec3& strength, const glm::mat3& to_map);

  // Builds what changed since the last commit: new meshes' BVHs (each with the builder
  // options.builder names, "auto" deciding per mesh) and the top level. With should_cancel, the
  // build runs on a worker thread while this one polls it every 10 ms (core/cancel_poll.h);
  // returns false when it answered true: the scene stays uncommitted, and meshes built before the
  // cancel keep their BVHs, so the next commit builds only the rest. Throws std::invalid_argument
  // for bad options, and what should_cancel throws once the worker has stopped.
  bool commit(const CommitOptions& options = {}, const CancelPoll& should_cancel = {});
  bool committed() const { return committed_; }
  const CommitStats& commit_stats() const { return stats_; }

  // Single-ray queries (the integrator's). Require a committed scene (not checked here; the
  // batch entry points and the binding check). A ray with a non-finite or zero direction, a
  // non-finite origin, or tnear > tfar finds nothing.
  Hit intersect(const Ray& ray) const;
  bool occluded(const Ray& ray) const;
  // The same for a path ray of the kinds `seen_by` (RayVisibility bits): instances hidden from
  // them are passed. Inline, so that a scene where every instance is seen by every ray calls the
  // plain queries (a flag test more).
  Hit intersect(const Ray& ray, uint8_t seen_by) const {
    return all_visible_ ? intersect(ray) : intersect_visible(ray, seen_by);
  }
  bool occluded(const Ray& ray, uint8_t seen_by) const {
    return all_visible_ ? occluded(ray) : occluded_visible(ray, seen_by);
  }
  // The render's shadow rays: occluded() by the instances that cast shadows. Inline, so that a
  // scene where every instance casts shadows calls occluded() as before (a flag test more).
  bool shadowed(const Ray& ray) const { return all_cast_shadows_ ? occluded(ray) : occluded_by_shadow_casters(ray); }
  // The shadow ray of a light whose blocker sets are `blockers` (light linking): occluded by the
  // casters in those sets; shadowed(ray) for a light that links no blockers.
  bool shadowed(const Ray& ray, uint64_t blockers) const {
    return blockers == kAllLightSets ? shadowed(ray) : occluded_by_shadow_casters(ray, blockers);
  }

  // Throws std::logic_error (naming commit()) unless the scene is committed.
  void check_committed() const;
  // What a render needs beyond check_committed: every material id a mesh uses names a material
  // (with no materials at all, id 0 is the default grey). Costs one check per mesh.
  void check_renderable() const;

  // Batch queries over `threads` threads (0: all cores). Throw std::logic_error before commit.
  void intersect(const RayBatch& rays, const HitBatch& hits, int threads = 0) const;
  void occluded(const RayBatch& rays, uint8_t* blocked, int threads = 0) const;

  size_t mesh_count() const { return meshes_.size(); }
  size_t instance_count() const { return instances_.size(); }
  const Mesh& mesh(uint32_t id) const { return *meshes_.at(id); }
  const Instance& instance(uint32_t id) const { return instances_.at(id); }
  const Bvh& top_level() const { return top_; }
  // The pad by which a walk of top_level() must widen its boxes for a ray from org: the instance
  // boxes are conservative for the rays the meshes see only with it (instance_bounds.h).
  float instance_box_pad(const Vec3& org) const {
    if (origin_pad_factor_ == 0.0f) return 0.0f;
    const Vec3 m = glm::abs(org);
    return origin_pad_factor_ * std::max(m.x, std::max(m.y, m.z));
  }
  const MeshShading& shading(uint32_t mesh) const { return shading_[mesh]; }  // one per mesh, always
  const std::vector<Material>& materials() const { return materials_; }       // empty: all default grey
  const std::vector<Texture>& textures() const { return textures_; }
  const std::vector<MaterialEmission>& emission() const { return emission_; }  // parallel to materials()
  bool any_emission() const { return any_emission_; }
  const std::vector<MaterialTransparency>& transparency() const { return transparency_; }  // parallel to materials()
  // Whether some material lets rays through: the render walks shadow rays through surfaces
  // (render/transparent_walk.h) only then; otherwise they stay occluded()'s any-hit query.
  bool any_transparency() const { return any_transparency_; }
  const std::vector<MaterialNormalMap>& normal_maps() const { return normal_maps_; }  // parallel to materials()
  // Whether some material has a normal map: only then does a hit look one up
  // (render/normal_mapping.h), so other scenes run the code they ran before.
  bool any_normal_map() const { return any_normal_map_; }
  // Some bump map differences over the ray's footprint (MaterialNormalMap::bump_footprint): only
  // then does the integrator carry ray cones (camera/ray_cone.h).
  bool any_bump_footprint() const { return any_bump_footprint_; }
  // Mix and Add Shaders of other materials (materials/material_mix.h): material `material`
  // becomes a mix of two materials added before it; set_material makes it a plain material
  // again. Throws std::invalid_argument for an unknown id or child.
  void set_mix(int64_t material, const MaterialMix& mix);
  // set_mix's checks alone (material may be the id the next add_material returns).
  void check_mix(int64_t material, const MaterialMix& mix) const;
  const std::vector<MaterialMix>& mixes() const { return mixes_; }  // parallel to materials()
  // Whether some material is a mix: only then does a hit look its slot up (pick_mixed).
  bool any_mix() const { return any_mix_; }
  // The nearest hit on an instance that casts shadows (the shadow walk's step), among those in the
  // blocker sets `blockers` (light linking).
  Hit intersect_shadow_casters(const Ray& ray, uint64_t blockers = kAllLightSets) const;
  const MeshEmitters& emitters() const { return emitters_; }  // the sampled emissive triangles, by commit()
  // What the emissive triangle of `key` (instance << 32 | triangle, MeshEmitters::keys) emits at
  // barycentrics b (along its second and third corners), its image read at the UV there; and
  // that UV ((0, 0) for a mesh without UVs).
  Vec3 emitted_at(uint64_t key, const Vec2& b) const;
  Vec2 emitter_uv(uint64_t key, const Vec2& b) const;
  // From how many sampled emissive triangles, spanning what share of the scene's diagonal, the
  // next commits pick them through a light tree (kEmitterTreeFrom, kEmitterTreeSpread; benchmarks
  // set them to compare the tree with the power CDF).
  void set_emitter_tree_from(size_t triangles, float spread = kEmitterTreeSpread) {
    emitter_tree_from_ = triangles;
    emitter_tree_spread_ = spread;
  }
  const World& world() const { return world_; }
  // The tree the render selects lights with: built by commit() over more than kLightTreeFrom
  // lights; null for fewer, and for lights edited since the last commit (they are selected
  // linearly until the next one: the same answers in distribution, only slower).
  const LightTree* light_tree() const {
    return light_tree_current_ && light_tree_.light_count() == world_.lights.size() && light_tree_.node_count() > 0
               ? &light_tree_
               : nullptr;
  }
  // Per light, the receiver sets whose diffuse surfaces it lights (its light-linking receiver
  // sets, none when it is hidden from diffuse rays), for the light selection; null when every
  // light lights every receiver (no linking: the selection checks nothing).
  // The BVH over the lamps' shapes for the rays that see lamps (lights/lamp_bvh.h): built at
  // commit from kLampBvhFrom lamps, else empty.
  const LampBvh& lamp_bvh() const { return lamp_bvh_; }
  const uint64_t* light_receiver_sets() const { return light_reach_.empty() ? nullptr : light_reach_.data(); }
  // Triangles stored (each mesh counted once) and placed (each instance counting its mesh).
  size_t stored_triangle_count() const;
  size_t instanced_triangle_count() const;
  size_t memory_bytes() const;

 private:
  template <bool AnyHit, bool ShadowCastersOnly = false, bool Visibility = false>
  bool trace(const Ray& ray, Hit& hit, uint64_t blockers = kAllLightSets, uint8_t seen_by = kVisibleAll) const;
  // trace()'s walk of the top level (more than one instance, or a transformed one).
  template <bool AnyHit, bool ShadowCastersOnly, bool Visibility>
  bool trace_instances(const Ray& ray, Hit& hit, uint64_t blockers, uint8_t seen_by) const;
  // One instance's part of trace(): its mesh traced in object space within [tnear, t_max).
  template <bool AnyHit, bool ShadowCastersOnly, bool Visibility>
  bool trace_instance(uint32_t id, const Ray& ray, float& t_max, Hit& hit, uint64_t blockers, uint8_t seen_by) const;
  Hit intersect_visible(const Ray& ray, uint8_t seen_by) const;
  bool occluded_visible(const Ray& ray, uint8_t seen_by) const;
  bool occluded_by_shadow_casters(const Ray& ray, uint64_t blockers = kAllLightSets) const;
  // commit()'s work; throws BuildCancelled when *cancel turns true.
  void build(const CommitOptions& options, const std::atomic<bool>* cancel);
  void check_mesh_id(int64_t mesh) const;
  void gather_emitters();  // scene_emitters.cpp: emitters_ from the instances and emission_

  std::vector<std::unique_ptr<Mesh>> meshes_;
  std::vector<MeshShading> shading_;      // parallel to meshes_
  std::vector<int32_t> max_material_id_;  // parallel to meshes_: MeshShading::check's answer
  std::vector<Material> materials_;
  std::vector<MaterialEmission> emission_;  // parallel to materials_
  bool any_emission_ = false;
  std::vector<MaterialTransparency> transparency_;  // parallel to materials_
  bool any_transparency_ = false;
  std::vector<MaterialNormalMap> normal_maps_;  // parallel to materials_
  bool any_normal_map_ = false;
  bool any_bump_footprint_ = false;
  std::vector<MaterialMix> mixes_;  // parallel to materials_
  bool any_mix_ = false;
  MeshEmitters emitters_;
  size_t emitter_tree_from_ = kEmitterTreeFrom;
  float emitter_tree_spread_ = kEmitterTreeSpread;
  std::vector<Texture> textures_;
  World world_;
  LightTree light_tree_;               // over world_.lights when light_tree_current_
  LampBvh lamp_bvh_;                   // over world_.lights when light_tree_current_
  bool light_tree_current_ = false;    // add_light and clear_lights reset it, commit() rebuilds
  std::vector<uint64_t> light_reach_;  // light_receiver_sets(), parallel to world_.lights, or empty
  std::vector<Instance> instances_;
  Bvh top_;  // over instances with a non-empty world box
  // The top-level walk widens every instance box by this times the ray origin's largest
  // coordinate: the rounding of rays sent into object space grows with it (instance_bounds.h).
  // Beside instances_, one each: how far rays carried by to_object may stray
  // (instance_bounds.h), made with the inverse at every transform change and read by each commit
  // for the instance's box. Not in Instance, whose array the top-level walk reads per ray.
  std::vector<TransformError> transform_errors_;
  float origin_pad_factor_ = 0.0f;
  // The mesh of the scene's one instance when it is untransformed (trace() skips the top level
  // and the instance record), else null.
  const Mesh* single_mesh_ = nullptr;
  bool all_cast_shadows_ = true;  // no instance with visible_shadow off: shadowed() is occluded()
  bool all_visible_ = true;       // every instance seen by every path ray: intersect(ray, kinds) is intersect(ray)
  bool committed_ = false;
  CommitStats stats_;
};

}  // namespace toyrt
