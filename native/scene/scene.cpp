#include "scene/scene.h"

#include "accel/traverse.h"
#include "core/parallel.h"
#include "opencl/device.h"

#include <glm/gtc/matrix_inverse.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <stdexcept>

namespace toyrt {

BuilderKind parse_builder(const std::string& name) {
  if (name == "auto") return BuilderKind::Auto;
  if (name == "sah") return BuilderKind::Sah;
  if (name == "lbvh") return BuilderKind::Lbvh;
  throw std::invalid_argument("unknown builder '" + name + "': expected 'auto', 'sah' or 'lbvh'");
}

uint32_t Scene::add_mesh(std::vector<Vec3> vertices, std::vector<Triangle> triangles) {
  meshes_.push_back(std::make_unique<Mesh>(std::move(vertices), std::move(triangles)));
  committed_ = false;
  return uint32_t(meshes_.size() - 1);
}

Mat4 Scene::checked_inverse(const Mat4& to_world) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(to_world[c][r])) throw std::invalid_argument("instance transform is not finite");
  if (to_world[0][3] != 0.0f || to_world[1][3] != 0.0f || to_world[2][3] != 0.0f || to_world[3][3] != 1.0f)
    throw std::invalid_argument("instance transform must be affine: its last row must be 0 0 0 1");
  const double det = glm::determinant(glm::dmat3(glm::mat3(to_world)));
  const Mat4 to_object = glm::affineInverse(to_world);
  bool finite_inverse = true;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) finite_inverse &= bool(std::isfinite(to_object[c][r]));
  if (det == 0.0 || !finite_inverse)
    throw std::invalid_argument("instance transform is singular (zero scale): it cannot be inverted");
  return to_object;
}

uint32_t Scene::add_instance(uint32_t mesh, const Mat4& to_world) {
  if (mesh >= meshes_.size())
    throw std::invalid_argument("unknown mesh id " + std::to_string(mesh) + " (the scene has " +
                                std::to_string(meshes_.size()) + " meshes)");
  const Mat4 to_object = checked_inverse(to_world);
  Instance inst;
  inst.mesh = mesh;
  inst.to_world = to_world;
  inst.to_object = to_object;
  inst.identity = to_world == Mat4(1.0f);
  instances_.push_back(inst);
  committed_ = false;
  return uint32_t(instances_.size() - 1);
}

void Scene::replace_mesh(uint32_t mesh, std::vector<Vec3> vertices, std::vector<Triangle> triangles) {
  if (mesh >= meshes_.size())
    throw std::invalid_argument("unknown mesh id " + std::to_string(mesh) + " (the scene has " +
                                std::to_string(meshes_.size()) + " meshes)");
  // Built before the swap, so a refused mesh leaves the old one in place.
  auto replacement = std::make_unique<Mesh>(std::move(vertices), std::move(triangles));
  meshes_[mesh] = std::move(replacement);
  committed_ = false;
}

void Scene::set_instance_transform(uint32_t instance, const Mat4& to_world) {
  if (instance >= instances_.size())
    throw std::invalid_argument("unknown instance id " + std::to_string(instance) + " (the scene has " +
                                std::to_string(instances_.size()) + " instances)");
  const Mat4 to_object = checked_inverse(to_world);
  Instance& inst = instances_[instance];
  inst.to_world = to_world;
  inst.to_object = to_object;
  inst.identity = to_world == Mat4(1.0f);
  committed_ = false;
}

void Scene::clear_instances() {
  instances_.clear();  // keeps the capacity: a re-sync adds about as many again
  committed_ = false;
}

void Scene::commit(const CommitOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  stats_ = {};
  instances_.shrink_to_fit();  // many instances are added one by one: drop the growth slack
  committed_ = false;  // until this commit completes (it may be cancelled)
  BinnedSahConfig sah = options.sah;
  sah.cancel = options.cancel;
  auto check_cancel = [&] {
    if (options.cancel && options.cancel->load(std::memory_order_relaxed)) throw BuildCancelled();
  };
  run_with_threads(options.threads, [&] {
    // Meshes first (each build is parallel inside), then the top level over their boxes.
    for (auto& mesh : meshes_) {
      if (mesh->built()) continue;
      check_cancel();
      BuilderKind kind = options.builder;
      if (kind == BuilderKind::Auto) kind = options.cost_model.choose(mesh->triangles().size(), options.expected_rays);
      if (kind == BuilderKind::Lbvh) {
        try {
          LbvhStats lbvh_stats;
          mesh->build_lbvh(options.lbvh, &lbvh_stats);
          stats_.lbvh_compile_ms += lbvh_stats.compile_ms;
          ++stats_.lbvh_meshes;
        } catch (const opencl::OpenClError& e) {
          if (stats_.warning.empty())
            stats_.warning = std::string("LBVH builder unavailable, using the SAH builder instead: ") + e.what();
          kind = BuilderKind::Sah;
        }
      }
      if (kind == BuilderKind::Sah) {
        mesh->build(sah);
        ++stats_.sah_meshes;
      }
      ++stats_.meshes_built;
    }
    std::vector<uint32_t> placed;
    std::vector<BBox> boxes;
    std::vector<Vec3> centers;
    for (uint32_t i = 0; i < instances_.size(); ++i) {
      Instance& inst = instances_[i];
      const BBox& b = meshes_[inst.mesh]->bounds();
      inst.world_bounds = BBox{};
      if (meshes_[inst.mesh]->bvh().empty()) continue;  // nothing to hit
      for (int corner = 0; corner < 8; ++corner) {
        const Vec3 p((corner & 1) ? b.hi.x : b.lo.x, (corner & 2) ? b.hi.y : b.lo.y, (corner & 4) ? b.hi.z : b.lo.z);
        inst.world_bounds.extend(Vec3(inst.to_world * glm::vec4(p, 1.0f)));
      }
      if (!inst.identity) {
        // The transformed corners are rounded; widen by a few ulps so the box stays conservative.
        const Vec3 pad = (glm::abs(inst.world_bounds.lo) + glm::abs(inst.world_bounds.hi)) * (4.0f * gamma(4));
        inst.world_bounds.lo -= pad;
        inst.world_bounds.hi += pad;
      }
      placed.push_back(i);
      boxes.push_back(inst.world_bounds);
      centers.push_back(inst.world_bounds.center());
    }
    check_cancel();
    BinnedSahConfig top_config = sah;
    top_config.max_leaf = 1;  // an instance test is a whole traversal: never group them
    top_ = build_binned_sah(boxes.data(), centers.data(), boxes.size(), top_config);
    for (uint32_t& id : top_.prim_ids) id = placed[id];
  });
  single_identity_ = instances_.size() == 1 && instances_[0].identity;
  committed_ = true;
  stats_.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

template <bool AnyHit>
bool Scene::trace(const Ray& ray, Hit& hit) const {
  if (!is_finite(ray.org) || !is_finite(ray.dir) || ray.dir == Vec3(0.0f) || std::isnan(ray.tnear) ||
      std::isnan(ray.tfar) || !(ray.tnear <= ray.tfar))
    return false;
  float tfar = ray.tfar;
  auto trace_instance = [&](uint32_t id, float& t_max) {
    const Instance& inst = instances_[id];
    const Mesh& mesh = *meshes_[inst.mesh];
    Vec3 org = ray.org, dir = ray.dir;
    if (!inst.identity) {
      org = Vec3(inst.to_object * glm::vec4(org, 1.0f));
      dir = glm::mat3(inst.to_object) * dir;
    }
    if constexpr (AnyHit) {
      return mesh.occluded(org, dir, ray.tnear, t_max);
    } else {
      if (!mesh.intersect(org, dir, ray.tnear, t_max, hit.u, hit.v, hit.prim)) return false;
      hit.instance = int32_t(id);
      return true;
    }
  };
  bool found;
  if (single_identity_) {
    found = trace_instance(0, tfar);
    if (found) hit.t = tfar;
    return found;
  }
  const RayBoxData box_ray = make_ray_box_data(ray.org, ray.dir);
  found = traverse<AnyHit>(top_, box_ray, ray.tnear, tfar, [&](uint32_t first, uint32_t count, float& t_max) {
    bool any = false;
    for (uint32_t k = first; k < first + count; ++k) {
      if (trace_instance(top_.prim_ids[k], t_max)) {
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

namespace {

Ray ray_at(const RayBatch& b, size_t i) {
  Ray r;
  r.org = Vec3(b.origins[3 * i], b.origins[3 * i + 1], b.origins[3 * i + 2]);
  r.dir = Vec3(b.directions[3 * i], b.directions[3 * i + 1], b.directions[3 * i + 2]);
  r.tnear = b.tnear ? b.tnear[i * b.tnear_stride] : 0.0f;
  r.tfar = b.tfar ? b.tfar[i * b.tfar_stride] : kInfinity;
  return r;
}

// Rays per task: enough to amortise scheduling, few enough to balance incoherent batches.
constexpr size_t kRayGrain = 256;

}  // namespace

void Scene::intersect(const RayBatch& rays, const HitBatch& hits, int threads) const {
  if (!committed_) throw std::logic_error("the scene changed since the last commit(): call commit() before queries");
  run_with_threads(threads, [&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.count, kRayGrain), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) {
        const Hit h = intersect(ray_at(rays, i));
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
  if (!committed_) throw std::logic_error("the scene changed since the last commit(): call commit() before queries");
  run_with_threads(threads, [&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.count, kRayGrain), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) blocked[i] = occluded(ray_at(rays, i)) ? 1 : 0;
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
  for (const auto& m : meshes_) bytes += m->memory_bytes();
  return bytes;
}

}  // namespace toyrt
