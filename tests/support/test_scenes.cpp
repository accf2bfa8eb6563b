#include "test_scenes.h"

#include "geometry/offset_ray.h"

#include <cmath>
#include <random>
#include <set>
#include <utility>

namespace toyrt::testing {
namespace {
constexpr float kPi = 3.14159265358979f;
}

GridData square_grid(int side, float x, float z, float half) {
  GridData g;
  const float cell = 2.0f * half / float(side);
  for (int i = 0; i <= side; ++i)
    for (int j = 0; j <= side; ++j) {
      g.mesh.vertices.emplace_back(x - half + float(i) * cell, -half + float(j) * cell, z);
      g.uvs.emplace_back(float(i) / float(side), float(j) / float(side));
    }
  const auto at = [&](int i, int j) { return uint32_t(i * (side + 1) + j); };
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j) {
      g.mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      g.mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return g;
}

MeshData uv_sphere(int rings, int segments, float radius, float bumps) {
  MeshData m;
  auto r_at = [&](float theta, float phi) {
    return radius * (1.0f + bumps * std::sin(7.0f * theta) * std::sin(5.0f * phi));
  };
  m.vertices.push_back({0.0f, 0.0f, radius});  // north pole
  for (int i = 1; i < rings; ++i) {
    const float theta = kPi * float(i) / float(rings);
    for (int j = 0; j < segments; ++j) {
      const float phi = 2.0f * kPi * float(j) / float(segments);
      const float r = r_at(theta, phi);
      m.vertices.push_back(
          {r * std::sin(theta) * std::cos(phi), r * std::sin(theta) * std::sin(phi), r * std::cos(theta)});
    }
  }
  m.vertices.push_back({0.0f, 0.0f, -radius});  // south pole
  const uint32_t south = uint32_t(m.vertices.size() - 1);
  auto ring = [&](int i, int j) { return uint32_t(1 + (i - 1) * segments + (j % segments)); };
  for (int j = 0; j < segments; ++j) m.triangles.push_back({0u, ring(1, j), ring(1, j + 1)});
  for (int i = 1; i < rings - 1; ++i)
    for (int j = 0; j < segments; ++j) {
      m.triangles.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      m.triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
  for (int j = 0; j < segments; ++j) m.triangles.push_back({south, ring(rings - 1, j + 1), ring(rings - 1, j)});
  return m;
}

MeshData bicone_fan(int segments) {
  MeshData m;
  m.vertices.push_back({0.0f, 0.0f, 1.0f});
  m.vertices.push_back({0.0f, 0.0f, -1.0f});
  for (int j = 0; j < segments; ++j) {
    const float phi = 2.0f * kPi * float(j) / float(segments);
    m.vertices.push_back({std::cos(phi), std::sin(phi), 0.0f});
  }
  for (int j = 0; j < segments; ++j) {
    const uint32_t a = 2 + j, b = 2 + (j + 1) % segments;
    m.triangles.push_back({0u, a, b});
    m.triangles.push_back({1u, b, a});
  }
  return m;
}

MeshData triangle_soup(size_t count, float size, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), offset(-size, size);
  MeshData m;
  for (size_t i = 0; i < count; ++i) {
    const Vec3 c(unit(rng), unit(rng), unit(rng));
    const uint32_t base = uint32_t(m.vertices.size());
    for (int k = 0; k < 3; ++k) m.vertices.push_back(c + Vec3(offset(rng), offset(rng), offset(rng)));
    m.triangles.push_back({base, base + 1, base + 2});
  }
  return m;
}

MeshData slivers(size_t count, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), sym(-1.0f, 1.0f);
  MeshData m;
  for (size_t i = 0; i < count; ++i) {
    const Vec3 c(unit(rng), unit(rng), unit(rng));
    const Vec3 along = glm::normalize(Vec3(sym(rng), sym(rng), sym(rng)));
    const Vec3 across = glm::normalize(glm::cross(along, Vec3(sym(rng), sym(rng), sym(rng))));
    const uint32_t base = uint32_t(m.vertices.size());
    m.vertices.push_back(c - 0.5f * along);
    m.vertices.push_back(c + 0.5f * along);
    m.vertices.push_back(c + 1e-4f * across);
    m.triangles.push_back({base, base + 1, base + 2});
  }
  return m;
}

MeshData transformed(const MeshData& mesh, float scale, const Vec3& offset) {
  MeshData m = mesh;
  for (Vec3& v : m.vertices) v = v * scale + offset;
  return m;
}

BBox bounds_of(const MeshData& mesh) {
  BBox b;
  for (const Vec3& v : mesh.vertices) b.extend(v);
  return b;
}

MeshData in_closed_room(const MeshData& mesh, float margin) {
  const BBox b = bounds_of(mesh);
  const Vec3 lo = b.lo - margin * b.extent(), hi = b.hi + margin * b.extent();
  MeshData m = mesh;
  const uint32_t base = uint32_t(m.vertices.size());
  for (int i = 0; i < 8; ++i) m.vertices.push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
  // The six faces as corner quadruples (bit 0 = x, 1 = y, 2 = z), two triangles each.
  const uint32_t faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    m.triangles.push_back({base + f[0], base + f[1], base + f[2]});
    m.triangles.push_back({base + f[0], base + f[2], base + f[3]});
  }
  return m;
}

PrimitiveBounds triangle_bounds(const MeshData& mesh) {
  PrimitiveBounds p;
  for (const Triangle& t : mesh.triangles) {
    BBox b;
    b.extend(mesh.vertices[t.x]);
    b.extend(mesh.vertices[t.y]);
    b.extend(mesh.vertices[t.z]);
    p.boxes.push_back(b);
  }
  return p;
}

std::vector<Ray> primary_rays(const BBox& box, int width, int height) {
  const Vec3 center = box.center();
  const float radius = 0.5f * glm::length(box.extent());
  const Vec3 eye = center + radius * Vec3(0.6f, -2.2f, 0.9f);
  const Vec3 forward = glm::normalize(center - eye);
  const Vec3 right = glm::normalize(glm::cross(forward, Vec3(0.0f, 0.0f, 1.0f)));
  const Vec3 up = glm::cross(right, forward);
  const float half = 0.45f;  // tan of half the field of view: the object fills most of the image
  std::vector<Ray> rays;
  rays.reserve(size_t(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float sx = (2.0f * (x + 0.5f) / width - 1.0f) * half;
      const float sy = (1.0f - 2.0f * (y + 0.5f) / height) * half;
      Ray r;
      r.org = eye;
      r.dir = glm::normalize(forward + sx * right + sy * up);
      rays.push_back(r);
    }
  return rays;
}

Vec3 geometric_normal(const MeshData& mesh, int32_t prim) {
  const Triangle& t = mesh.triangles[size_t(prim)];
  return glm::cross(mesh.vertices[t.y] - mesh.vertices[t.x], mesh.vertices[t.z] - mesh.vertices[t.x]);
}

Vec3 hit_point(const MeshData& mesh, const Hit& hit) {
  const Triangle& t = mesh.triangles[size_t(hit.prim)];
  return (1.0f - hit.u - hit.v) * mesh.vertices[t.x] + hit.u * mesh.vertices[t.y] + hit.v * mesh.vertices[t.z];
}

namespace {
// Surface point and unit normal facing the incoming ray, moved off the surface.
std::pair<Vec3, Vec3> leave_surface(const MeshData& mesh, const Ray& in, const Hit& hit) {
  Vec3 n = glm::normalize(geometric_normal(mesh, hit.prim));
  if (glm::dot(n, in.dir) > 0.0f) n = -n;
  return {offset_ray_origin(hit_point(mesh, hit), n), n};
}
}  // namespace

std::vector<Ray> diffuse_rays(const MeshData& mesh, const std::vector<Ray>& incoming, const std::vector<Hit>& hits,
                              uint64_t seed, bool through) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<Ray> rays;
  for (size_t i = 0; i < hits.size(); ++i) {
    if (!hits[i].found()) continue;
    Ray in = incoming[i];
    if (through) in.dir = -in.dir;
    auto [p, n] = leave_surface(mesh, in, hits[i]);
    // Cosine-weighted hemisphere (Malley): a uniform disk sample lifted onto the hemisphere.
    const float r = std::sqrt(unit(rng)), phi = 2.0f * kPi * unit(rng);
    const Vec3 a = std::fabs(n.x) > 0.5f ? Vec3(0, 1, 0) : Vec3(1, 0, 0);
    const Vec3 t = glm::normalize(glm::cross(n, a)), b = glm::cross(n, t);
    Ray ray;
    ray.org = p;
    ray.dir = r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(std::max(0.0f, 1.0f - r * r)) * n;
    rays.push_back(ray);
  }
  return rays;
}

std::vector<Ray> shadow_rays(const MeshData& mesh, const std::vector<Ray>& incoming, const std::vector<Hit>& hits,
                             const Vec3& light) {
  std::vector<Ray> rays;
  for (size_t i = 0; i < hits.size(); ++i) {
    if (!hits[i].found()) continue;
    Ray ray;
    ray.org = leave_surface(mesh, incoming[i], hits[i]).first;
    ray.dir = light - ray.org;  // unnormalised: the light sits at t = 1
    ray.tfar = 1.0f;
    rays.push_back(ray);
  }
  return rays;
}

std::vector<Ray> leaving_their_triangles(const MeshData& mesh, std::vector<Ray> rays, const std::vector<Hit>& hits) {
  size_t k = 0;
  for (const Hit& hit : hits) {
    if (!hit.found()) continue;
    Ray& r = rays.at(k++);
    // The side the origin was moved to, and the side the ray goes to, of the triangle's plane.
    const Vec3 n = geometric_normal(mesh, hit.prim);
    const float origin_side = glm::dot(n, r.org - hit_point(mesh, hit)), going = glm::dot(n, r.dir);
    if ((origin_side > 0.0f && going > 0.0f) || (origin_side < 0.0f && going < 0.0f))
      r.self = TriangleRef{hit.prim, hit.instance};
  }
  return rays;
}

std::vector<Ray> rays_at_vertices_and_edges(const MeshData& mesh, const Vec3& inside, int per_edge, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<Ray> rays;
  auto aim = [&](const Vec3& target) {
    Ray r;
    r.org = inside;
    r.dir = target - inside;
    rays.push_back(r);
  };
  for (const Vec3& v : mesh.vertices) aim(v);
  std::set<std::pair<uint32_t, uint32_t>> edges;
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t[k], b = t[(k + 1) % 3];
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  for (auto [a, b] : edges) {
    const Vec3 pa = mesh.vertices[a], pb = mesh.vertices[b];
    aim(0.5f * (pa + pb));
    for (int k = 0; k < per_edge; ++k) {
      const float s = unit(rng);
      aim(pa + s * (pb - pa));
    }
  }
  return rays;
}

}  // namespace toyrt::testing
