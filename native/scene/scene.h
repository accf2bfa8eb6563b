// The two-level scene: meshes stored once, each with its own BVH, and instances placing them,
// gathered by a top-level BVH over the instances' world boxes. Queries come one ray at a time
// or as batches spread over threads.
//
// Thread safety: queries on a committed scene are read-only and may run concurrently;
// add_mesh / add_instance / commit must not overlap with anything else (the Python binding
// holds a lock to guarantee that).
#pragma once

#include "core/ray.h"
#include "geometry/mesh.h"
#include "accel/builder_choice.h"
#include "accel/lbvh_builder.h"
#include "scene/instance.h"

#include <memory>
#include <string>
#include <vector>

namespace toyrt {

// Parses "auto", "sah", "lbvh"; throws std::invalid_argument on anything else.
BuilderKind parse_builder(const std::string& name);

struct CommitOptions {
  BuilderKind builder = BuilderKind::Auto;
  int threads = 0;  // 0: all cores
  // Rays the caller expects to trace (pixels x samples x rays per sample), for "auto"; < 0:
  // unknown, and "auto" keeps the SAH builder.
  double expected_rays = -1.0;
  BinnedSahConfig sah;
  LbvhConfig lbvh;
  BuilderCostModel cost_model;
  // Cancel flag (not owned; may be null): polled between meshes and inside every SAH build.
  // A cancelled commit throws BuildCancelled and leaves the scene uncommitted; meshes built
  // before the cancel keep their BVHs, so the next commit builds only the rest.
  const std::atomic<bool>* cancel = nullptr;
};

struct CommitStats {
  double build_ms = 0.0;         // wall time of the last commit
  double lbvh_compile_ms = 0.0;  // OpenCL kernel compilation inside it (first LBVH build of the process)
  size_t meshes_built = 0;       // meshes whose BVH the last commit (re)built
  size_t sah_meshes = 0, lbvh_meshes = 0;
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
  // Adds a mesh (no instance) and returns its id. Validation as in Mesh's constructor.
  uint32_t add_mesh(std::vector<Vec3> vertices, std::vector<Triangle> triangles);
  // Places mesh `mesh` with the affine object-to-world matrix `to_world`; returns the instance
  // id. Throws std::invalid_argument for an unknown mesh, a non-finite, non-affine (last row not
  // 0 0 0 1) or singular matrix.
  uint32_t add_instance(uint32_t mesh, const Mat4& to_world);
  // Edits for interactive updates (the viewport), each leaving the scene uncommitted; ids stay
  // valid. replace_mesh swaps a mesh's geometry (its BVH is rebuilt by the next commit, the
  // instances placing it stay); set_instance_transform moves one instance (the next commit
  // rebuilds only the top level); clear_instances removes every instance (meshes stay).
  void replace_mesh(uint32_t mesh, std::vector<Vec3> vertices, std::vector<Triangle> triangles);
  void set_instance_transform(uint32_t instance, const Mat4& to_world);
  void clear_instances();
  // The transform checks of add_instance alone; returns the inverse.
  static Mat4 checked_inverse(const Mat4& to_world);

  // Builds what changed since the last commit: new meshes' BVHs and the top level.
  void commit(const CommitOptions& options = {});
  bool committed() const { return committed_; }
  const CommitStats& commit_stats() const { return stats_; }

  // Single-ray queries (the integrator's). Require a committed scene (not checked here; the
  // batch entry points and the binding check). A ray with a non-finite or zero direction, a
  // non-finite origin, or tnear > tfar finds nothing.
  Hit intersect(const Ray& ray) const;
  bool occluded(const Ray& ray) const;

  // Batch queries over `threads` threads (0: all cores). Throw std::logic_error before commit.
  void intersect(const RayBatch& rays, const HitBatch& hits, int threads = 0) const;
  void occluded(const RayBatch& rays, uint8_t* blocked, int threads = 0) const;

  size_t mesh_count() const { return meshes_.size(); }
  size_t instance_count() const { return instances_.size(); }
  const Mesh& mesh(uint32_t id) const { return *meshes_.at(id); }
  const Instance& instance(uint32_t id) const { return instances_.at(id); }
  const Bvh& top_level() const { return top_; }
  // Triangles stored (each mesh counted once) and placed (each instance counting its mesh).
  size_t stored_triangle_count() const;
  size_t instanced_triangle_count() const;
  size_t memory_bytes() const;

 private:
  template <bool AnyHit>
  bool trace(const Ray& ray, Hit& hit) const;

  std::vector<std::unique_ptr<Mesh>> meshes_;
  std::vector<Instance> instances_;
  Bvh top_;                       // over instances with a non-empty world box
  bool single_identity_ = false;  // one untransformed instance: skip the top level
  bool committed_ = false;
  CommitStats stats_;
};

}  // namespace toyrt
