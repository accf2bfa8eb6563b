// libFuzzer target over the core's entry points: scenes built from fuzzed vertices, indices and
// instance matrices, committed and traced with fuzzed rays; both CPU builders over fuzzed boxes;
// the camera, light and texture constructors and their lookups. Built with ASan + UBSan, so any
// memory error or undefined behaviour is a crash, and the properties below are checked on top:
//   - add_mesh / add_instance refuse exactly the inputs the API documents as invalid;
//   - intersect and occluded agree, and a hit lies on [tnear, tfar) on a real triangle; the same
//     ray naming that triangle (Ray::self) never hits it, and its two queries agree too;
//   - on moderately sized inputs the scene finds a hit exactly when a brute-force loop over every
//     triangle of every instance does (the BVH's boxes are conservative);
//   - batch queries equal single-ray queries;
//   - every builder's tree passes Bvh::validate;
//   - a whole scene (shading, materials, lights, world) renders to finite, non-negative pixels.
// First input byte (from the end, FuzzedDataProvider's integer order) picks the part.
#include "accel/binned_sah_builder.h"
#include "accel/lbvh_builder.h"
#include "accel/wide_bvh.h"
#include "camera/camera.h"
#include "geometry/triangle.h"
#include "lights/area_light.h"
#include "lights/point_light.h"
#include "materials/texture.h"
#include "render/renderer.h"
#include "scene/scene.h"

#include <fuzzer/FuzzedDataProvider.h>

#include <cfloat>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace {

using namespace toyrt;

// A failed property aborts, so libFuzzer saves the input as a crash artifact.
#define FUZZ_CHECK(cond)                                                                  \
  do {                                                                                    \
    if (!(cond)) {                                                                        \
      std::fprintf(stderr, "fuzz check failed: %s (%s:%d)\n", #cond, __FILE__, __LINE__); \
      std::abort();                                                                       \
    }                                                                                     \
  } while (0)

// Floats that reach the interesting cases: a coarse grid (shared vertices and edges, rays along
// axes and through vertices), special values, small reals, and arbitrary bit patterns.
float fuzz_float(FuzzedDataProvider& in) {
  static const float special[] = {0.0f,    -0.0f,  NAN,   INFINITY, -INFINITY, FLT_MAX, -FLT_MAX,
                                  FLT_MIN, 1e-40f, 1e30f, -1e30f,   1e-30f,    1e6f};
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0:
      return float(in.ConsumeIntegralInRange<int>(-8, 8)) * 0.5f;
    case 1:
      return special[in.ConsumeIntegralInRange<size_t>(0, sizeof(special) / sizeof(float) - 1)];
    case 2:
      return in.ConsumeFloatingPointInRange<float>(-4.0f, 4.0f);
    default: {
      const uint32_t bits = in.ConsumeIntegral<uint32_t>();
      float f;
      std::memcpy(&f, &bits, sizeof f);
      return f;
    }
  }
}

Vec3 fuzz_vec3(FuzzedDataProvider& in) {
  const float x = fuzz_float(in), y = fuzz_float(in), z = fuzz_float(in);
  return {x, y, z};
}

Mat4 fuzz_matrix(FuzzedDataProvider& in) {
  Mat4 m(1.0f);
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0:
      break;  // identity
    case 1:   // scale and translation
      for (int a = 0; a < 3; ++a) m[a][a] = fuzz_float(in);
      m[3] = glm::vec4(fuzz_vec3(in), 1.0f);
      break;
    case 2:  // any affine matrix
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 3; ++r) m[c][r] = fuzz_float(in);
      break;
    default:  // anything, the last row included
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) m[c][r] = fuzz_float(in);
  }
  return m;
}

// Within this range the float box and triangle tests cannot overflow, so the scene and the
// brute-force loop must agree exactly; beyond it only "no crash" is asked.
bool moderate(float x) { return x == 0.0f || (std::fabs(x) >= 1e-3f && std::fabs(x) <= 1e3f); }
bool moderate(const Vec3& v) { return moderate(v.x) && moderate(v.y) && moderate(v.z); }

// The mesh's rule (geometry/mesh.cpp): zero area in double precision.
bool degenerate(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  if (p0 == p1 || p1 == p2 || p2 == p0) return true;
  const DVec3 n = glm::cross(DVec3(p1) - DVec3(p0), DVec3(p2) - DVec3(p0));
  return n.x == 0.0 && n.y == 0.0 && n.z == 0.0;
}

// The documented contract of Scene::intersect: these rays find nothing.
bool valid_ray(const Ray& r) {
  return is_finite(r.org) && is_finite(r.dir) && r.dir != Vec3(0.0f) && !std::isnan(r.tnear) && !std::isnan(r.tfar) &&
         r.tnear <= r.tfar;
}

// Every triangle of every instance, with the scene's own object-space ray (scene.cpp).
bool brute_force_hits(const Scene& scene, const Ray& ray) {
  if (!valid_ray(ray)) return false;
  for (uint32_t i = 0; i < scene.instance_count(); ++i) {
    const Instance& inst = scene.instance(i);
    const Mesh& mesh = scene.mesh(inst.mesh);
    Vec3 org = ray.org, dir = ray.dir;
    if (!inst.identity) {
      org = Vec3(inst.to_object * glm::vec4(org, 1.0f));
      dir = glm::mat3(inst.to_object) * dir;
    }
    const WatertightRay wr = make_watertight_ray(org, dir);
    for (const Triangle& t : mesh.triangles()) {
      const Vec3 &p0 = mesh.vertices()[t.x], &p1 = mesh.vertices()[t.y], &p2 = mesh.vertices()[t.z];
      if (degenerate(p0, p1, p2)) continue;
      float th, u, v;
      if (intersect_triangle(wr, p0, p1, p2, ray.tnear, ray.tfar, th, u, v)) return true;
    }
  }
  return false;
}

// What a failed check needs to be reproduced by hand (hex floats are exact).
void dump(const Scene& scene, const Ray& r, const Hit& h) {
  std::fprintf(stderr, "ray org (%a %a %a) dir (%a %a %a) [%a, %a): t %a prim %d instance %d\n", r.org.x, r.org.y,
               r.org.z, r.dir.x, r.dir.y, r.dir.z, r.tnear, r.tfar, h.t, h.prim, h.instance);
  for (uint32_t i = 0; i < scene.instance_count(); ++i) {
    const Instance& inst = scene.instance(i);
    std::fprintf(stderr, "instance %u: mesh %u, identity %d, to_world rows:", i, inst.mesh, int(inst.identity));
    for (int row = 0; row < 3; ++row)
      std::fprintf(stderr, " (%a %a %a %a)", inst.to_world[0][row], inst.to_world[1][row], inst.to_world[2][row],
                   inst.to_world[3][row]);
    std::fprintf(stderr, "\n");
  }
  for (uint32_t m = 0; m < scene.mesh_count(); ++m) {
    const Mesh& mesh = scene.mesh(m);
    for (const Triangle& t : mesh.triangles()) {
      std::fprintf(stderr, "mesh %u triangle:", m);
      for (int k = 0; k < 3; ++k) {
        const Vec3& p = mesh.vertices()[t[k]];
        std::fprintf(stderr, " (%a %a %a)", p.x, p.y, p.z);
      }
      std::fprintf(stderr, "\n");
    }
  }
}

void fuzz_scene(FuzzedDataProvider& in) {
  Scene scene;
  bool all_moderate = true;
  const int meshes = in.ConsumeIntegralInRange<int>(0, 3);
  for (int m = 0; m < meshes; ++m) {
    std::vector<Vec3> vertices(in.ConsumeIntegralInRange<size_t>(0, 12));
    bool valid = true;
    for (Vec3& v : vertices) {
      v = fuzz_vec3(in);
      valid &= is_finite(v);
      all_moderate &= moderate(v);
    }
    std::vector<Triangle> triangles(in.ConsumeIntegralInRange<size_t>(0, 12));
    for (Triangle& t : triangles)
      for (int k = 0; k < 3; ++k) {
        // vertices.size() + 1 reaches past the end: an index out of range.
        t[k] = in.ConsumeIntegralInRange<uint32_t>(0, uint32_t(vertices.size()) + 1);
        valid &= t[k] < vertices.size();
      }
    const size_t before = scene.mesh_count();
    try {
      const uint32_t id = scene.add_mesh(vertices, triangles);
      FUZZ_CHECK(valid && id == before);
    } catch (const std::invalid_argument&) {
      FUZZ_CHECK(!valid && scene.mesh_count() == before);
    }
  }
  const int instances = in.ConsumeIntegralInRange<int>(0, 4);
  for (int i = 0; i < instances; ++i) {
    const uint32_t mesh = in.ConsumeIntegralInRange<uint32_t>(0, uint32_t(scene.mesh_count()));  // may be unknown
    const Mat4 m = fuzz_matrix(in);
    try {
      scene.add_instance(mesh, m);
      FUZZ_CHECK(mesh < scene.mesh_count());
      for (int c = 0; c < 4; ++c) all_moderate &= moderate(Vec3(m[c]));
    } catch (const std::invalid_argument&) {
    }
  }
  CommitOptions options;
  // "lbvh" falls back to SAH when OpenCL is off (make fuzz sets TOYRT_OPENCL=off): that path too.
  options.builder = in.ConsumeBool() ? BuilderKind::Sah : BuilderKind::Lbvh;
  options.threads = 1;
  scene.commit(options);
  FUZZ_CHECK(scene.committed());

  const size_t count = in.ConsumeIntegralInRange<size_t>(0, 8);
  std::vector<float> org(3 * count), dir(3 * count), tnear(count), tfar(count);
  std::vector<Hit> single(count);
  std::vector<uint8_t> single_blocked(count);
  for (size_t k = 0; k < count; ++k) {
    Ray r;
    r.org = fuzz_vec3(in);
    r.dir = fuzz_vec3(in);
    r.tnear = in.ConsumeBool() ? 0.0f : fuzz_float(in);
    r.tfar = in.ConsumeBool() ? kInfinity : fuzz_float(in);
    // TOYRT_FUZZ_DUMP=1 prints every scene and ray before tracing it: how a saved input becomes
    // a readable test.
    static const bool dump_all = std::getenv("TOYRT_FUZZ_DUMP") != nullptr;
    if (dump_all) dump(scene, r, Hit{});
    const Hit h = scene.intersect(r);
    const bool blocked = scene.occluded(r);
    if (h.found() != blocked) dump(scene, r, h);
    FUZZ_CHECK(h.found() == blocked);
    if (h.found()) {
      FUZZ_CHECK(h.instance >= 0 && size_t(h.instance) < scene.instance_count());
      const Instance& inst = scene.instance(uint32_t(h.instance));
      const Mesh& mesh = scene.mesh(inst.mesh);
      FUZZ_CHECK(h.prim >= 0 && size_t(h.prim) < mesh.triangles().size());
      const Triangle& t = mesh.triangles()[size_t(h.prim)];
      FUZZ_CHECK(!degenerate(mesh.vertices()[t.x], mesh.vertices()[t.y], mesh.vertices()[t.z]));
      if (!(h.t >= r.tnear && h.t < r.tfar)) dump(scene, r, h);
      FUZZ_CHECK(h.t >= r.tnear && h.t < r.tfar);
    } else {
      FUZZ_CHECK(h.t == kInfinity && h.instance == kInvalidId);
    }
    // Ray::self: the same ray naming the triangle it hit never hits that one (it finds another,
    // or none), and its two queries still agree (the walks compiled for a named triangle).
    if (h.found()) {
      Ray named = r;
      named.self = TriangleRef{h.prim, h.instance};
      const Hit n = scene.intersect(named);
      FUZZ_CHECK(!(n.prim == h.prim && n.instance == h.instance));
      FUZZ_CHECK(n.found() == scene.occluded(named));
    }
    if (all_moderate && moderate(r.org) && moderate(r.dir) && moderate(r.tnear) &&
        (moderate(r.tfar) || r.tfar == kInfinity)) {
      const bool brute = brute_force_hits(scene, r);
      if (brute != h.found()) dump(scene, r, h);
      FUZZ_CHECK(h.found() == brute);
    }
    std::memcpy(&org[3 * k], &r.org, sizeof(Vec3));
    std::memcpy(&dir[3 * k], &r.dir, sizeof(Vec3));
    tnear[k] = r.tnear;
    tfar[k] = r.tfar;
    single[k] = h;
    single_blocked[k] = blocked;
  }
  // The batch entry points, per-ray tnear and tfar: the same answers bit for bit.
  const RayBatch batch{org.data(), dir.data(), tnear.data(), 1, tfar.data(), 1, count};
  std::vector<float> t(count), u(count), v(count);
  std::vector<int32_t> prim(count), instance(count);
  std::vector<uint8_t> blocked(count);
  scene.intersect(batch, HitBatch{t.data(), u.data(), v.data(), prim.data(), instance.data()}, 1);
  scene.occluded(batch, blocked.data(), 1);
  for (size_t k = 0; k < count; ++k) {
    FUZZ_CHECK(prim[k] == single[k].prim && instance[k] == single[k].instance && blocked[k] == single_blocked[k]);
    FUZZ_CHECK(std::memcmp(&t[k], &single[k].t, sizeof(float)) == 0);
  }
}

// Both CPU builders over fuzzed boxes (finite, possibly empty-volume, overlapping or equal).
void fuzz_builders(FuzzedDataProvider& in) {
  const size_t count = in.ConsumeIntegralInRange<size_t>(0, 64);
  std::vector<BBox> boxes(count);
  for (size_t i = 0; i < count; ++i) {
    Vec3 a = fuzz_vec3(in), b = fuzz_vec3(in);
    if (!is_finite(a)) a = Vec3(0.0f);
    if (!is_finite(b)) b = a;
    boxes[i].extend(a);
    boxes[i].extend(b);
  }
  BinnedSahConfig sah;
  sah.max_leaf = in.ConsumeIntegralInRange<uint32_t>(1, 8);
  sah.bins = in.ConsumeIntegralInRange<int>(2, 32);
  const Bvh tree = build_binned_sah(boxes.data(), count, sah);
  const std::string sah_problem = tree.validate(boxes.data(), count);
  if (!sah_problem.empty()) std::fprintf(stderr, "SAH: %s\n", sah_problem.c_str());
  FUZZ_CHECK(sah_problem.empty());
  LbvhConfig lbvh;
  lbvh.bits = in.ConsumeBool() ? MortonBits::k30 : MortonBits::k63;
  const Bvh linear = build_lbvh_reference(boxes.data(), count, lbvh);
  const std::string lbvh_problem = linear.validate(boxes.data(), count);
  if (!lbvh_problem.empty()) std::fprintf(stderr, "LBVH: %s\n", lbvh_problem.c_str());
  FUZZ_CHECK(lbvh_problem.empty());
  // Collapsing keeps every primitive exactly once.
  for (const Bvh* b : {&tree, &linear}) {
    const WideBvh wide = collapse(*b, 4);
    size_t leaves = wide.root_leaf_count;
    for (const WideNode& n : wide.nodes)
      for (int c = 0; c < kWidth; ++c) leaves += n.count[c];
    FUZZ_CHECK(leaves == count);
  }
}

// Constructors refuse bad settings with std::invalid_argument; what they accept must be usable.
// The whole scene rendered: fuzzed shading (refused exactly when MeshShading::check says so),
// materials of every kind with fuzzed settings, a light, the background; a 2 x 2 render must
// give finite, non-negative pixels or refuse a material id it does not have.
void fuzz_render(FuzzedDataProvider& in) {
  Scene scene;
  std::vector<Vec3> vertices(in.ConsumeIntegralInRange<size_t>(0, 6));
  for (Vec3& v : vertices) v = Vec3(fuzz_float(in) * 0.25f, fuzz_float(in) * 0.25f, fuzz_float(in) * 0.1f);
  std::vector<Triangle> triangles(in.ConsumeIntegralInRange<size_t>(0, 4));
  for (Triangle& t : triangles)
    for (int k = 0; k < 3; ++k)
      t[k] = in.ConsumeIntegralInRange<uint32_t>(0, uint32_t(std::max<size_t>(vertices.size(), 1) - 1));
  MeshShading sh;
  const size_t corners = 3 * triangles.size() + (in.ConsumeIntegralInRange<int>(0, 7) == 0 ? 1 : 0);  // rarely wrong
  if (in.ConsumeBool()) sh.corner_normals.resize(corners);
  for (Vec3& n : sh.corner_normals) n = fuzz_vec3(in);
  if (in.ConsumeBool()) sh.corner_uvs.resize(corners);
  for (Vec2& uv : sh.corner_uvs) uv = Vec2(fuzz_float(in), fuzz_float(in));
  if (in.ConsumeBool()) sh.material_ids.resize(triangles.size());
  for (int32_t& id : sh.material_ids) id = in.ConsumeIntegralInRange<int32_t>(-1, 4);
  bool shading_ok = true;
  try {
    (void)sh.check(triangles.size());
  } catch (const std::invalid_argument&) {
    shading_ok = false;
  }
  try {
    scene.add_instance(scene.add_mesh(vertices, triangles, sh), Mat4(1.0f));
    FUZZ_CHECK(shading_ok);
  } catch (const std::invalid_argument&) {
    FUZZ_CHECK(scene.mesh_count() == 0);  // refused shading or vertices: nothing added
  }
  if (in.ConsumeBool())
    scene.add_texture(Texture::from_floats(2, 1, 3, {0, 0.5f, 1, 1, 0.5f, 0}, ColorEncoding::Linear));
  for (int m = in.ConsumeIntegralInRange<int>(0, 4); m > 0; --m) {
    static const char* kinds[] = {"diffuse", "refraction", "glass", "metal"};
    try {
      // The binding's parameters: color, texture and ior for every kind (allowed unread), consumed
      // in the order clang evaluated the former make_material(kind, color, texture, ior) call.
      const char* kind = kinds[in.ConsumeIntegralInRange<int>(0, 3)];
      Params params;
      params.set("color", fuzz_vec3(in)).set("texture", double(in.ConsumeIntegralInRange<int64_t>(-2, 1)));
      params.set("ior", double(fuzz_float(in)));
      for (const char* shared : {"color", "texture", "ior"}) params.allow_unread(shared);
      scene.add_material(make_material(kind, params));
    } catch (const std::invalid_argument&) {
    }
  }
  try {
    scene.add_light(PointLight::make(fuzz_vec3(in), fuzz_float(in), Vec3(1.0f), fuzz_float(in)),
                    {in.ConsumeBool(), in.ConsumeBool()});
  } catch (const std::invalid_argument&) {
  }
  try {
    scene.set_background(fuzz_vec3(in));
  } catch (const std::invalid_argument&) {
  }
  scene.set_background_lighting(in.ConsumeBool());
  CommitOptions options;
  options.threads = 1;
  scene.commit(options);
  CameraParams p;
  p.type = CameraType::Orthographic;
  p.ortho_scale = 2.0f;
  p.resolution_x = p.resolution_y = 2;
  p.matrix_world[3] = glm::vec4(0.0f, 0.0f, 3.0f, 1.0f);
  RenderSettings settings;
  settings.samples = 1;
  settings.threads = 1;
  settings.integrator.max_specular_depth = in.ConsumeIntegralInRange<int>(0, 4);
  settings.integrator.split_depth = in.ConsumeIntegralInRange<int>(0, 2);
  settings.integrator.light_sampling = LightSampling(in.ConsumeIntegralInRange<int>(0, 2));
  try {
    const RenderResult r = render(scene, Camera::make(p), settings);
    for (float x : r.rgba) FUZZ_CHECK(std::isfinite(x) && x >= 0.0f);
  } catch (const std::invalid_argument& e) {
    FUZZ_CHECK(std::strstr(e.what(), "uses material id") != nullptr);  // the only refusal left
  }
}

void fuzz_transport(FuzzedDataProvider& in) {
  CameraParams p;
  p.type = in.ConsumeBool() ? CameraType::Perspective : CameraType::Orthographic;
  p.sensor_fit = SensorFit(in.ConsumeIntegralInRange<int>(0, 2));
  p.resolution_x = in.ConsumeIntegralInRange<int>(-2, 4096);
  p.resolution_y = in.ConsumeIntegralInRange<int>(-2, 4096);
  p.resolution_percentage = in.ConsumeIntegralInRange<int>(-1, 400);
  p.lens = fuzz_float(in);
  p.sensor_width = fuzz_float(in);
  p.sensor_height = fuzz_float(in);
  p.shift_x = fuzz_float(in);
  p.ortho_scale = fuzz_float(in);
  p.pixel_aspect_x = fuzz_float(in);
  p.clip_start = fuzz_float(in);
  p.clip_end = fuzz_float(in);
  p.use_border = in.ConsumeBool();
  p.border_min_x = fuzz_float(in);
  p.border_max_y = fuzz_float(in);
  p.matrix_world = fuzz_matrix(in);
  try {
    const Camera camera = Camera::make(p);
    FUZZ_CHECK(camera.window.width() >= 1 && camera.window.height() >= 1);
    FUZZ_CHECK(camera.window.x1 <= camera.width && camera.window.y1 <= camera.height);
    (void)camera.generate(in.ConsumeFloatingPointInRange<float>(0.0f, float(camera.width)),
                          in.ConsumeFloatingPointInRange<float>(0.0f, float(camera.height)));
  } catch (const std::invalid_argument&) {
  }

  const Vec3 shading_point = fuzz_vec3(in), normal = fuzz_vec3(in);
  const Vec2 u(in.ConsumeProbability<float>(), in.ConsumeProbability<float>());
  try {
    const PointLight light = PointLight::make(fuzz_vec3(in), fuzz_float(in), fuzz_vec3(in), fuzz_float(in));
    (void)sample(light, shading_point, u);
    (void)evaluate(light, shading_point, normal);
    (void)importance(light, shading_point, normal);
  } catch (const std::invalid_argument&) {
  }
  try {
    const AreaLight light = AreaLight::make(AreaShape(in.ConsumeIntegralInRange<int>(0, 3)), fuzz_float(in),
                                            fuzz_float(in), fuzz_matrix(in), fuzz_float(in), fuzz_vec3(in));
    const AreaSampling sampling = in.ConsumeBool() ? AreaSampling::Area : AreaSampling::SolidAngle;
    (void)sample(light, shading_point, u, sampling);
    (void)evaluate(light, shading_point, normal, sampling);
    (void)importance(light, shading_point, normal);
  } catch (const std::invalid_argument&) {
  }
  try {
    const int w = in.ConsumeIntegralInRange<int>(-1, 5), h = in.ConsumeIntegralInRange<int>(-1, 5);
    const int c = in.ConsumeIntegralInRange<int>(0, 5);
    std::vector<float> texels(in.ConsumeIntegralInRange<size_t>(0, 100));
    for (float& x : texels) x = fuzz_float(in);
    const Texture tex =
        Texture::from_floats(w, h, c, texels, in.ConsumeBool() ? ColorEncoding::Srgb : ColorEncoding::Linear);
    (void)tex.lookup(Vec2(fuzz_float(in), fuzz_float(in)));
  } catch (const std::invalid_argument&) {
  }
  fuzz_render(in);  // last, so the inputs above read the bytes they read before it existed
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  switch (in.ConsumeIntegralInRange<int>(0, 2)) {
    case 0:
      fuzz_scene(in);
      break;
    case 1:
      fuzz_builders(in);
      break;
    default:
      fuzz_transport(in);
      break;
  }
  return 0;
}
