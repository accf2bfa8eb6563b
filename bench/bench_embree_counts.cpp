// Embree 3 counting crossings directly, the way ray libraries built on it count them (Open3D's
// RaycastingScene.count_intersections): one rtcIntersect1 per ray whose intersection filter
// records each hit it is offered and rejects it, so the traversal goes on to the next one. Run by
// bench/queries_bench.py (`make bench`) on the aligned sets it exports, whose answers are known
// (docs/queries.md): every ray crosses the closed mesh exactly once; each point is inside or not.
//
// Usage: bench_embree_counts SETS_FILE. Reads, per set: u32 name length, the name, u32 vertex
// count, float32 xyz per vertex, u32 triangle count, u32 indices, u32 ray count, float32 origins
// then directions, u32 point count, float32 points, u8 inside per point. Prints a first line
// "version<TAB>Embree's version number (30xxyy)", then one line per set, scene flag and counting
// rule (below): "set<TAB>flags, rule<TAB>rays<TAB>wrong counts<TAB>points<TAB>wrong occupancies".
#include <embree3/rtcore.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

struct QuerySet {
  std::string name;
  std::vector<float> vertices;    // xyz per vertex
  std::vector<uint32_t> indices;  // three per triangle
  std::vector<float> origins, directions;
  std::vector<float> points;
  std::vector<uint8_t> inside;
};

template <class T>
void read_array(std::ifstream& in, std::vector<T>& out, size_t count) {
  out.resize(count);
  in.read(reinterpret_cast<char*>(out.data()), std::streamsize(count * sizeof(T)));
}

uint32_t read_u32(std::ifstream& in) {
  uint32_t v = 0;
  in.read(reinterpret_cast<char*>(&v), sizeof v);
  return v;
}

std::vector<QuerySet> read_sets(const char* path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(std::string("cannot open ") + path);
  std::vector<QuerySet> sets;
  for (;;) {
    const uint32_t name_length = read_u32(in);
    if (!in) break;
    QuerySet s;
    s.name.resize(name_length);
    in.read(s.name.data(), name_length);
    read_array(in, s.vertices, 3 * size_t(read_u32(in)));
    read_array(in, s.indices, 3 * size_t(read_u32(in)));
    const size_t rays = read_u32(in);
    read_array(in, s.origins, 3 * rays);
    read_array(in, s.directions, 3 * rays);
    const size_t points = read_u32(in);
    read_array(in, s.points, 3 * points);
    read_array(in, s.inside, points);
    if (!in) throw std::runtime_error("truncated sets file");
    sets.push_back(std::move(s));
  }
  return sets;
}

// The hits one ray was offered, in the order Embree offered them.
struct Offered {
  uint32_t prim;
  float t;
};

// The context the filter sees: Embree hands back the pointer it was given, so the record of the
// hits travels with it.
struct CountingContext {
  RTCIntersectContext base;
  std::vector<Offered>* hits;
};

void record_and_reject(const RTCFilterFunctionNArguments* args) {
  const auto* context = reinterpret_cast<const CountingContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    context->hits->push_back({RTCHitN_primID(args->hit, args->N, i), RTCRayN_tfar(args->ray, args->N, i)});
    args->valid[i] = 0;  // rejected: the traversal looks for the next hit
  }
}

// Two ways to turn the offered hits into a count. `distinct`: each primitive once (Embree may
// offer a hit again after a rejection), so what remains are the geometric misses and double
// counts. `merged`: as Open3D counts, a hit whose primitive or distance equals that of the last
// hit counted is not counted again, which merges the two triangles of an edge when Embree gives
// them one t (and can merge two separate crossings that round to one t).
struct Counts {
  unsigned distinct, merged;
};

Counts count_crossings(RTCScene scene, const float* org, const float* dir) {
  std::vector<Offered> hits;
  CountingContext context;
  rtcInitIntersectContext(&context.base);
  context.base.filter = record_and_reject;
  context.hits = &hits;
  RTCRayHit rh{};
  rh.ray.org_x = org[0];
  rh.ray.org_y = org[1];
  rh.ray.org_z = org[2];
  rh.ray.dir_x = dir[0];
  rh.ray.dir_y = dir[1];
  rh.ray.dir_z = dir[2];
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = std::numeric_limits<float>::infinity();
  rh.ray.mask = 0xFFFFFFFFu;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene, &context.base, &rh);
  std::set<uint32_t> prims;
  Counts c{0, 0};
  const Offered* last = nullptr;
  for (const Offered& h : hits) {
    prims.insert(h.prim);
    if (!last || (h.prim != last->prim && h.t != last->t)) {
      ++c.merged;
      last = &h;
    }
  }
  c.distinct = unsigned(prims.size());
  return c;
}

RTCScene make_scene(RTCDevice device, const QuerySet& s, RTCSceneFlags flags) {
  RTCScene scene = rtcNewScene(device);
  rtcSetSceneFlags(scene, RTCSceneFlags(flags | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION));
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  const size_t nv = s.vertices.size() / 3, nt = s.indices.size() / 3;
  auto* vb = static_cast<float*>(
      rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
  auto* ib = static_cast<uint32_t*>(
      rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), nt));
  std::copy(s.vertices.begin(), s.vertices.end(), vb);
  std::copy(s.indices.begin(), s.indices.end(), ib);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(scene);
  return scene;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s SETS_FILE\n", argv[0]);
    return 2;
  }
  try {
    const std::vector<QuerySet> sets = read_sets(argv[1]);
    RTCDevice device = rtcNewDevice("");
    if (!device) throw std::runtime_error("Embree: cannot create a device");
    std::printf("version\t%ld\n", long(rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION)));
    const struct {
      RTCSceneFlags flags;
      const char* name;
    } modes[] = {{RTC_SCENE_FLAG_NONE, "default"}, {RTC_SCENE_FLAG_ROBUST, "robust"}};
    for (const QuerySet& s : sets) {
      for (const auto& mode : modes) {
        RTCScene scene = make_scene(device, s, mode.flags);
        const size_t rays = s.origins.size() / 3, points = s.inside.size();
        size_t wrong_distinct = 0, wrong_merged = 0, inside_distinct = 0, inside_merged = 0;
        for (size_t i = 0; i < rays; ++i) {
          const Counts c = count_crossings(scene, &s.origins[3 * i], &s.directions[3 * i]);
          wrong_distinct += c.distinct != 1;
          wrong_merged += c.merged != 1;
        }
        // Occupancy as the parity of one ray along +x (what TOYRT's compute_occupancy decides).
        const float plus_x[3] = {1.0f, 0.0f, 0.0f};
        for (size_t i = 0; i < points; ++i) {
          const Counts c = count_crossings(scene, &s.points[3 * i], plus_x);
          inside_distinct += (c.distinct % 2 == 1) != (s.inside[i] != 0);
          inside_merged += (c.merged % 2 == 1) != (s.inside[i] != 0);
        }
        std::printf("%s\t%s, distinct\t%zu\t%zu\t%zu\t%zu\n", s.name.c_str(), mode.name, rays, wrong_distinct, points,
                    inside_distinct);
        std::printf("%s\t%s, merged\t%zu\t%zu\t%zu\t%zu\n", s.name.c_str(), mode.name, rays, wrong_merged, points,
                    inside_merged);
        rtcReleaseScene(scene);
      }
    }
    rtcReleaseDevice(device);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_embree_counts: %s\n", e.what());
    return 1;
  }
  return 0;
}
