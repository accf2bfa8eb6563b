#include "render/aovs.h"

#include "camera/camera.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace toyrt {

namespace {
struct AovInfo {
  const char* name;
  int channels;
  bool from_first_sample;  // Cycles writes it at sample 0 only; the others are averaged
};
constexpr std::array<AovInfo, kAovCount> kAovs{{{"depth", 1, true},
                                                {"mist", 1, false},
                                                {"position", 3, true},
                                                {"normal", 3, false},
                                                {"diffuse_color", 3, false},
                                                {"glossy_color", 3, false},
                                                {"emission", 3, false},
                                                {"environment", 3, false},
                                                {"object_index", 1, true},
                                                {"material_index", 1, true}}};

// Cycles' mist (kernel/film/data_passes.h): the distance from the camera (perspective) or along
// its axis (orthographic) mapped to [0, 1] over [start, start + depth], then the falloff power.
float mist_at(const MistSettings& m, const Camera& camera, const Vec3& p) {
  const float distance = camera.type == CameraType::Orthographic
                             ? std::fabs(glm::dot(p - camera.position, camera.axis_z))
                             : glm::length(p - camera.position);
  const float x = m.depth > 0.0f ? std::clamp((distance - m.start) / m.depth, 0.0f, 1.0f) : 1.0f;
  if (m.falloff == 1.0f) return x;
  if (m.falloff == 2.0f) return x * x;
  if (m.falloff == 0.5f) return std::sqrt(x);
  return std::pow(x, m.falloff);
}

float index_at(const std::vector<float>& table, int32_t id) {
  return id >= 0 && size_t(id) < table.size() ? table[size_t(id)] : 0.0f;
}
}  // namespace

const char* aov_name(Aov aov) { return kAovs[size_t(aov)].name; }
int aov_channels(Aov aov) { return kAovs[size_t(aov)].channels; }
bool aov_from_first_sample(Aov aov) { return kAovs[size_t(aov)].from_first_sample; }

Aov parse_aov(const std::string& name) {
  for (size_t k = 0; k < kAovCount; ++k)
    if (name == kAovs[k].name) return Aov(k);
  std::string known;
  for (const AovInfo& a : kAovs) known += std::string(known.empty() ? "" : ", ") + a.name;
  throw std::invalid_argument("render: unknown pass '" + name + "' (known: " + known + ")");
}

void AovBuffers::allocate(const AovRequest& request, int w, int h) {
  width = w;
  height = h;
  for (size_t k = 0; k < kAovCount; ++k) {
    const Aov aov = Aov(k);
    // Depth reads 1e10 and mist 1 where nothing is hit; a pixel never rendered (cancel) keeps that.
    const float fill = aov == Aov::Depth ? 1e10f : aov == Aov::Mist ? 1.0f : 0.0f;
    if (request.has(aov)) data[k].assign(size_t(w) * size_t(h) * size_t(aov_channels(aov)), fill);
  }
  for (size_t k = 0; k < kCryptoKindCount; ++k)
    if (request.cryptomatte.has(CryptoKind(k)))
      cryptomatte[k].assign(size_t(w) * size_t(h) * size_t(request.cryptomatte.channels()), 0.0f);
}

void AovPixel::add(const FirstHit& hit, bool first_sample) {
  // Lamps and the world a camera ray sees count whether or not it then hits a surface.
  emission_sum_ += hit.emission;
  environment_sum_ += hit.environment;
  if (!hit.found) return;  // a miss adds 0 to the other averages and leaves the first-sample values
  if (first_sample) {
    // Cycles' camera space looks down +z: the planar depth is along the view axis (-axis_z).
    depth_ = glm::dot(hit.p - camera_.position, -camera_.axis_z);
    position_ = hit.p;
    object_ = index_at(request_.object_index, hit.instance);
    material_ = index_at(request_.material_index, hit.material);
  }
  normal_sum_ += hit.normal;
  diffuse_sum_ += hit.diffuse;
  glossy_sum_ += hit.glossy;
  if (request_.has(Aov::Mist)) mist_sum_ += 1.0f - mist_at(request_.mist, camera_, hit.p);
}

void AovPixel::store(AovBuffers& b, size_t pixel, float inv) const {
  auto put = [&](Aov aov, const Vec3& v) {
    std::vector<float>& d = b.data[size_t(aov)];
    if (d.empty()) return;
    const int c = aov_channels(aov);
    for (int k = 0; k < c; ++k) d[pixel * size_t(c) + size_t(k)] = v[k];
  };
  put(Aov::Depth, Vec3(depth_));
  put(Aov::Mist, Vec3(1.0f - mist_sum_ * inv));
  put(Aov::Position, position_);
  put(Aov::Normal, normal_sum_ * inv);
  put(Aov::DiffuseColor, diffuse_sum_ * inv);
  put(Aov::GlossyColor, glossy_sum_ * inv);
  put(Aov::Emission, emission_sum_ * inv);
  put(Aov::Environment, environment_sum_ * inv);
  put(Aov::ObjectIndex, Vec3(object_));
  put(Aov::MaterialIndex, Vec3(material_));
}

}  // namespace toyrt
