// Stability benchmark: where methods fail, counted. Writes one JSON object (docs/results.md,
// section 3, is drawn from it by bench/report.py):
//   leaks       rays from inside closed meshes aimed exactly at vertices and edges, which must all
//               hit: misses of TOYRT's watertight test (through its BVH), of a plain float
//               Moller-Trumbore test (written here: the non-watertight baseline) and of Embree 3
//               (default and robust mode), at the origin, moved far away and scaled down;
//   acne        shadow rays from hit points towards a light the surface faces (so nothing may
//               block them) that hit their own surface: from the raw hit point, with a fixed
//               epsilon tnear, and from offset_ray_origin(), across scales and distances;
//   estimators  relative standard deviation of one-sample irradiance estimates of a square area
//               light, area against solid-angle sampling, as the point approaches the light and
//               as the light is seen at grazing angles;
//   lbvh_room   tree quality (SAH cost, trace speed) of LBVH (30- and 63-bit Morton codes)
//               against binned SAH on a small detailed object in a huge room;
//   tir         glass (Fresnel dielectric) from inside: the fraction of samples transmitted
//               against 1 - F from Fresnel's equations in double, across the critical angle.
//
//   bench_stability [--out FILE.json] [--quick] [--smoke]
// --smoke runs the leak count of one case and exits non-zero unless the watertight test has no
// leak where Moller-Trumbore has some (ctest runs it, so this program cannot rot unnoticed).
#include "accel/binned_sah_builder.h"
#include "accel/lbvh_builder.h"
#include "bench_util.h"
#include "embree_oracle.h"
#include "geometry/offset_ray.h"
#include "lights/area_light.h"
#include "materials/refraction.h"
#include "scene/scene.h"
#include "test_scenes.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

using namespace toyrt;
using namespace toyrt::testing;
using namespace toyrt::bench;

namespace {

// The textbook Moller-Trumbore test in float (Moller and Trumbore 1997), with only an exact-zero
// determinant rejected (the original's epsilon would also reject every triangle at tiny scales).
// Each triangle decides its edges from its own edge vectors, so two triangles sharing an edge can
// both round a ray through it to "outside": the leaks counted below.
bool moller_trumbore(const Ray& r, const Vec3& p0, const Vec3& p1, const Vec3& p2, float& t) {
  const Vec3 e1 = p1 - p0, e2 = p2 - p0;
  const Vec3 pv = glm::cross(r.dir, e2);
  const float det = glm::dot(e1, pv);
  if (det == 0.0f) return false;
  const float inv = 1.0f / det;
  const Vec3 tv = r.org - p0;
  const float u = glm::dot(tv, pv) * inv;
  if (u < 0.0f || u > 1.0f) return false;
  const Vec3 qv = glm::cross(tv, e1);
  const float v = glm::dot(r.dir, qv) * inv;
  if (v < 0.0f || u + v > 1.0f) return false;
  t = glm::dot(e2, qv) * inv;
  return t >= r.tnear && t < r.tfar;
}

bool mt_hits_any(const MeshData& m, const Ray& r) {
  float t;
  for (const Triangle& tri : m.triangles)
    if (moller_trumbore(r, m.vertices[tri[0]], m.vertices[tri[1]], m.vertices[tri[2]], t)) return true;
  return false;
}

template <class F>
size_t count_parallel(size_t n, F&& f) {
  std::atomic<size_t> count{0};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 64), [&](const tbb::blocked_range<size_t>& r) {
    size_t local = 0;
    for (size_t i = r.begin(); i != r.end(); ++i) local += f(i) ? 1 : 0;
    count += local;
  });
  return count.load();
}

struct LeakCase {
  std::string mesh, placement;
  size_t rays = 0, watertight = 0, moller_trumbore = 0, embree = 0, embree_robust = 0;
};

LeakCase leaks(const std::string& name, const MeshData& base, const std::string& placement, float scale,
               const Vec3& offset, int per_edge) {
  const MeshData m = transformed(base, scale, offset);
  const Vec3 inside = bounds_of(m).center();
  const std::vector<Ray> rays = rays_at_vertices_and_edges(m, inside, per_edge, 6);
  const auto toyrt = scene_of(m);
  const EmbreeScene embree(m.vertices, m.triangles), robust(m.vertices, m.triangles, true);
  LeakCase c{name, placement, rays.size()};
  c.watertight = count_parallel(rays.size(), [&](size_t i) { return !toyrt->intersect(rays[i]).found(); });
  c.moller_trumbore = count_parallel(rays.size(), [&](size_t i) { return !mt_hits_any(m, rays[i]); });
  c.embree = count_parallel(rays.size(), [&](size_t i) { return !embree.intersect(rays[i]).found(); });
  c.embree_robust = count_parallel(rays.size(), [&](size_t i) { return !robust.intersect(rays[i]).found(); });
  return c;
}

struct AcneCase {
  std::string surface;
  float scale, distance;
  size_t rays = 0, raw = 0, epsilon = 0, offset = 0;
};

// Shadow rays from the hit points of camera rays on a convex surface, towards a light on the side
// the hit triangle faces: nothing can block them, so every blocked one hit its own surface.
AcneCase acne(const std::string& name, const MeshData& base, float scale, float distance, int res) {
  // The surface far from the origin along a diagonal, so every coordinate grows.
  const MeshData m = transformed(base, scale, Vec3(distance, distance * 0.7f, distance * 0.4f));
  const BBox box = bounds_of(m);
  const auto scene = scene_of(m);
  const std::vector<Ray> cams = primary_rays(box, res, res);
  const Vec3 light = light_for(box);
  AcneCase c{name, scale, distance};
  std::vector<std::array<Ray, 3>> shadow;
  for (const Ray& r : cams) {
    const Hit h = scene->intersect(r);
    if (!h.found()) continue;
    const Vec3 p = hit_point(m, h);
    Vec3 n = glm::normalize(geometric_normal(m, h.prim));
    if (glm::dot(n, r.dir) > 0.0f) n = -n;  // the side the camera ray came from
    const Vec3 to_light = light - p;
    if (glm::dot(n, to_light) <= 0.0f) continue;  // the surface faces away: in its own shadow
    std::array<Ray, 3> s;
    for (Ray& q : s) {
      q.org = p;
      q.dir = to_light;
      q.tfar = 1.0f;
    }
    // A fixed epsilon in world units, the usual fix that scenes of another scale break.
    s[1].tnear = 1e-4f;
    s[2].org = offset_ray_origin(p, n);
    s[2].dir = light - s[2].org;
    shadow.push_back(s);
  }
  c.rays = shadow.size();
  c.raw = count_parallel(shadow.size(), [&](size_t i) { return scene->occluded(shadow[i][0]); });
  c.epsilon = count_parallel(shadow.size(), [&](size_t i) { return scene->occluded(shadow[i][1]); });
  c.offset = count_parallel(shadow.size(), [&](size_t i) { return scene->occluded(shadow[i][2]); });
  return c;
}

struct EstimatorCase {
  std::string sweep;
  double parameter = 0.0, exact = 0.0;
  double area_mean = 0.0, area_rel_std = 0.0, solid_mean = 0.0, solid_rel_std = 0.0;
};

// One-sample irradiance estimates E = L cos / pdf at p (normal n) from a 1 m x 1 m light at the
// origin emitting down (-Z); mean and relative standard deviation over `n` independent samples.
std::pair<double, double> estimate(AreaSampling sampling, const Vec3& p, const Vec3& n, int count) {
  const AreaLight light = AreaLight::make(AreaShape::Square, 1.0f, 1.0f, Mat4(1.0f), 4.0f, Vec3(1.0f));
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < count; ++i) {
    const LightSample s = sample(light, p, Vec2(unit(rng), unit(rng)), sampling);
    double e = 0.0;
    if (s.valid()) e = double(s.radiance.x) * std::max(0.0f, glm::dot(n, s.wi)) / double(s.pdf);
    sum += e;
    sum2 += e * e;
  }
  const double mean = sum / count, var = std::max(0.0, sum2 / count - mean * mean);
  return {mean, mean > 0.0 ? std::sqrt(var) / mean : 0.0};
}

EstimatorCase estimators(const std::string& sweep, double parameter, const Vec3& p, const Vec3& n, int count) {
  EstimatorCase c{sweep, parameter};
  std::tie(c.area_mean, c.area_rel_std) = estimate(AreaSampling::Area, p, n, count);
  std::tie(c.solid_mean, c.solid_rel_std) = estimate(AreaSampling::SolidAngle, p, n, count);
  return c;
}

// Fresnel reflectance of unpolarised light in double, written out independently of
// native/materials/fresnel.h: eta = n_t / n_i, 1 beyond the critical angle.
double fresnel_exact(double cos_i, double eta) {
  const double sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0) return 1.0;
  const double cos_t = std::sqrt(1.0 - sin2_t);
  const double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const double rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Args> args = parse_args(argc, argv, "[--out FILE.json] [--quick] [--smoke]");
  if (!args) return 2;
  const std::string& out_path = args->out;
  const bool quick = args->quick, smoke = args->smoke;

  if (smoke) {
    // A fan of 64 triangles around each apex of a double cone: rays at the apexes and edges.
    const LeakCase c = leaks("bicone_fan", bicone_fan(64), "origin", 1.0f, Vec3(0.0f), 8);
    std::printf("smoke: %zu rays, watertight leaks %zu, Moller-Trumbore leaks %zu, Embree leaks %zu\n", c.rays,
                c.watertight, c.moller_trumbore, c.embree);
    const bool ok = c.rays > 0 && c.watertight == 0 && c.moller_trumbore > 0;
    std::printf("%s\n", ok ? "1 passed, 0 failed" : "0 passed, 1 failed");
    return ok ? 0 : 1;
  }

  std::ostringstream js;
  js << "{\n";

  // ---- leaks ----
  struct Placement {
    const char* name;
    float scale;
    Vec3 offset;
  };
  std::vector<Placement> placements = {{"origin", 1.0f, Vec3(0.0f)},
                                       {"offset 1e3", 1.0f, Vec3(1e3f, -7e2f, 4e2f)},
                                       {"offset 1e4", 1.0f, Vec3(1e4f, -7e3f, 4e3f)},
                                       {"offset 1e5", 1.0f, Vec3(1e5f, -7e4f, 4e4f)},
                                       {"offset 1e6", 1.0f, Vec3(1e6f, -7e5f, 4e5f)},
                                       {"scale 1e-3", 1e-3f, Vec3(0.0f)},
                                       {"scale 1e-6", 1e-6f, Vec3(0.0f)}};
  const int per_edge = quick ? 4 : 16;
  const MeshData sphere = uv_sphere(24, 48), fan = bicone_fan(256);
  js << " \"leaks\": [\n";
  bool first = true;
  for (const auto& [mesh_name, mesh] :
       {std::pair<std::string, const MeshData*>{"uv_sphere", &sphere}, {"bicone_fan", &fan}})
    for (const Placement& p : placements) {
      const LeakCase c = leaks(mesh_name, *mesh, p.name, p.scale, p.offset, per_edge);
      std::fprintf(stderr, "leaks %s %s: %zu rays, watertight %zu, MT %zu, Embree %zu / robust %zu\n", c.mesh.c_str(),
                   c.placement.c_str(), c.rays, c.watertight, c.moller_trumbore, c.embree, c.embree_robust);
      js << (first ? "" : ",\n") << "  {\"mesh\": \"" << c.mesh << "\", \"placement\": \"" << c.placement
         << "\", \"rays\": " << c.rays << ", \"watertight\": " << c.watertight
         << ", \"moller_trumbore\": " << c.moller_trumbore << ", \"embree\": " << c.embree
         << ", \"embree_robust\": " << c.embree_robust << "}";
      first = false;
    }
  js << "\n ],\n";

  // ---- acne ----
  const int res = quick ? 96 : 256;
  const MeshData ball = uv_sphere(32, 64);
  MeshData sheet;  // a tilted 16 x 16 grid of quads: a plane made of triangles
  for (int y = 0; y <= 16; ++y)
    for (int x = 0; x <= 16; ++x)
      sheet.vertices.push_back(Vec3(x / 16.0f - 0.5f, y / 16.0f - 0.5f, 0.3f * (x / 16.0f - 0.5f)));
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      const uint32_t a = y * 17 + x;
      sheet.triangles.push_back(Triangle(a, a + 1, a + 18));
      sheet.triangles.push_back(Triangle(a, a + 18, a + 17));
    }
  js << " \"acne\": [\n";
  first = true;
  for (const auto& [surface, mesh] : {std::pair<std::string, const MeshData*>{"sphere", &ball}, {"plane", &sheet}})
    for (float scale : {1e-3f, 1.0f, 1e3f})
      for (float distance : {0.0f, 1e2f, 1e4f, 1e5f}) {
        const AcneCase c = acne(surface, *mesh, scale, distance, res);
        std::fprintf(stderr, "acne %s scale %g distance %g: %zu rays, raw %zu, eps %zu, offset %zu\n", surface.c_str(),
                     scale, distance, c.rays, c.raw, c.epsilon, c.offset);
        js << (first ? "" : ",\n") << "  {\"surface\": \"" << c.surface << "\", \"scale\": " << c.scale
           << ", \"distance\": " << c.distance << ", \"rays\": " << c.rays << ", \"raw\": " << c.raw
           << ", \"epsilon\": " << c.epsilon << ", \"offset\": " << c.offset << "}";
        first = false;
      }
  js << "\n ],\n";

  // ---- area-light estimators ----
  const int count = quick ? 20000 : 200000;
  std::vector<EstimatorCase> est;
  // Straight below the light's centre, facing it, coming closer.
  for (double h : {4.0, 2.0, 1.0, 0.5, 0.2, 0.1, 0.05, 0.02, 0.01, 0.005})
    est.push_back(estimators("distance", h, Vec3(0.0f, 0.0f, -float(h)), Vec3(0, 0, 1), count));
  // 0.1 m below the light's plane, moving sideways: the light is seen at ever more grazing angles.
  for (double x : {0.0, 0.5, 1.0, 2.0, 4.0, 8.0})
    est.push_back(estimators("sideways", x, Vec3(float(x), 0.0f, -0.1f), Vec3(0, 0, 1), count));
  js << " \"estimators\": [\n";
  for (size_t i = 0; i < est.size(); ++i) {
    const EstimatorCase& c = est[i];
    js << (i ? ",\n" : "") << "  {\"sweep\": \"" << c.sweep << "\", \"parameter\": " << c.parameter
       << ", \"area_mean\": " << c.area_mean << ", \"area_rel_std\": " << c.area_rel_std
       << ", \"solid_mean\": " << c.solid_mean << ", \"solid_rel_std\": " << c.solid_rel_std << "}";
  }
  js << "\n ],\n";

  // ---- LBVH on a badly distributed scene ----
  {
    const int rings = quick ? 100 : 300;
    MeshData room = transformed(uv_sphere(rings, 2 * rings, 1.0f, 0.1f), 1.0f, Vec3(0.0f));  // ~1 m, detailed
    const size_t object_tris = room.triangles.size();
    // A 2 km room (12 triangles) around it, the object near one corner of its floor.
    const float s = 1000.0f;
    const uint32_t b = uint32_t(room.vertices.size());
    for (int k = 0; k < 8; ++k)
      room.vertices.push_back(Vec3((k & 1) ? s : -s, (k & 2) ? s : -s, (k & 4) ? s : -2.0f) +
                              Vec3(s * 0.9f, s * 0.9f, 0.0f));
    const int faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
    for (const auto& f : faces) {
      room.triangles.push_back(Triangle(b + f[0], b + f[1], b + f[2]));
      room.triangles.push_back(Triangle(b + f[0], b + f[2], b + f[3]));
    }
    const PrimitiveBounds prims = triangle_bounds(room);
    const Bvh sah = build_binned_sah(prims.boxes.data(), prims.boxes.size());
    const Bvh l30 = build_lbvh(prims.boxes.data(), prims.boxes.size(), {});
    const Bvh l63 = build_lbvh(prims.boxes.data(), prims.boxes.size(), LbvhConfig{MortonBits::k63});
    // Rays at the object (camera outside its box, inside the room), then diffuse bounces from the hits.
    MeshData object_only;
    object_only.vertices.assign(room.vertices.begin(), room.vertices.begin() + b);
    object_only.triangles.assign(room.triangles.begin(), room.triangles.begin() + object_tris);
    std::vector<Ray> rays = primary_rays(bounds_of(object_only), quick ? 192 : 384, quick ? 192 : 384);
    {
      const EmbreeScene e(room.vertices, room.triangles);
      std::vector<Hit> hits;
      for (const Ray& r : rays) hits.push_back(e.intersect(r));
      const std::vector<Ray> d = diffuse_rays(room, rays, hits, 3);
      rays.insert(rays.end(), d.begin(), d.end());
    }
    auto speed = [&](BuilderKind kind, MortonBits bits) {
      const auto scene = scene_of(room, kind, bits);
      const double ms = best_ms(3, [&] { for_each_ray(rays, [&](const Ray& ray) { scene->intersect(ray); }); });
      return rays.size() / ms / 1e3;
    };
    const double v_sah = speed(BuilderKind::Sah, MortonBits::k30), v30 = speed(BuilderKind::Lbvh, MortonBits::k30),
                 v63 = speed(BuilderKind::Lbvh, MortonBits::k63);
    std::fprintf(stderr, "room: SAH cost %.1f / %.1f / %.1f, Mrays/s %.2f / %.2f / %.2f\n", sah.sah_cost(),
                 l30.sah_cost(), l63.sah_cost(), v_sah, v30, v63);
    js << " \"lbvh_room\": {\"triangles\": " << room.triangles.size() << ", \"object_triangles\": " << object_tris
       << ", \"room_size_m\": " << 2 * s << ", \"rays\": " << rays.size()
       << ", \"sah_cost\": {\"sah\": " << sah.sah_cost() << ", \"lbvh30\": " << l30.sah_cost()
       << ", \"lbvh63\": " << l63.sah_cost() << "}, \"mrays\": {\"sah\": " << v_sah << ", \"lbvh30\": " << v30
       << ", \"lbvh63\": " << v63 << "}},\n";
  }

  // ---- total internal reflection: glass seen from inside ----
  {
    const float ior = 1.5f;
    const FresnelDielectric glass = FresnelDielectric::make(ior);
    const PerfectRefraction refr = PerfectRefraction::make(ior);
    const Vec3 ng(0, 0, 1);  // outward: wo below it is inside the glass
    const int n = quick ? 20000 : 200000;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    js << " \"tir\": {\"ior\": " << ior << ", \"critical_deg\": " << std::asin(1.0 / ior) * 180.0 / M_PI
       << ", \"samples\": " << n << ", \"angles\": [\n";
    for (int deg = 0; deg <= 88; deg += 2) {
      const double th = deg * M_PI / 180.0;
      const Vec3 wo(float(std::sin(th)), 0.0f, -float(std::cos(th)));
      size_t transmitted = 0;
      for (int i = 0; i < n; ++i) transmitted += sample(glass, wo, ng, ng, unit(rng)).reflected ? 0 : 1;
      const SpecularSample pr = sample(refr, wo, ng, ng);
      const double expected = 1.0 - fresnel_exact(std::cos(th), 1.0 / ior);  // eta = n_t / n_i = 1 / 1.5
      js << (deg ? ",\n" : "") << "  {\"deg\": " << deg << ", \"transmitted\": " << double(transmitted) / n
         << ", \"expected\": " << expected
         << ", \"refraction_tir\": " << (pr.total_internal_reflection ? "true" : "false") << "}";
    }
    js << "\n ]}\n";
  }
  js << "}\n";
  if (!out_path.empty())
    std::ofstream(out_path) << js.str();
  else
    std::cout << js.str();
  return 0;
}
