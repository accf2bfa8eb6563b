// The render passes' per-pixel rules (render/aovs.h), each against Cycles' definition: what
// comes from the first sample only, what is averaged, Cycles' mist falloffs, and that a render
// pays only for the passes it asks for.
#include "render/aovs.h"
#include "camera/camera.h"

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include <stdexcept>

namespace toyrt {
namespace {

// A perspective camera at (0, 0, 5) looking down -Z.
Camera camera_above() {
  CameraParams p;
  p.resolution_x = p.resolution_y = 1;
  p.matrix_world = glm::translate(Mat4(1.0f), Vec3(0.0f, 0.0f, 5.0f));
  return Camera::make(p);
}

AovRequest all_passes() {
  AovRequest r;
  r.mask = (1u << kAovCount) - 1u;
  r.object_index = {7.0f, 9.0f};
  r.material_index = {3.0f};
  return r;
}

FirstHit hit_at(Vec3 p, Vec3 n, Vec3 albedo, int32_t instance = 1, int32_t material = 0) {
  FirstHit h;
  h.found = true;
  h.p = p;
  h.normal = n;
  h.diffuse = albedo;
  h.instance = instance;
  h.material = material;
  return h;
}

// Reads pass `aov` of the one pixel of `b`.
Vec3 value(const AovBuffers& b, Aov aov) {
  const std::vector<float>& d = b.data[size_t(aov)];
  return aov_channels(aov) == 1 ? Vec3(d[0]) : Vec3(d[0], d[1], d[2]);
}

TEST(AovPixel, DepthPositionAndIndicesComeFromTheFirstSampleOnly) {
  const Camera cam = camera_above();
  const AovRequest r = all_passes();
  AovBuffers b;
  b.allocate(r, 1, 1);
  AovPixel px(r, cam);
  px.add(hit_at(Vec3(0.3f, 0.0f, 1.0f), Vec3(0, 0, 1), Vec3(0.5f)), true);         // 4 m below: planar z
  px.add(hit_at(Vec3(0.0f, 0.0f, 0.0f), Vec3(0, 0, 1), Vec3(0.5f), 0, 0), false);  // another object behind
  px.store(b, 0, 0.5f);
  EXPECT_FLOAT_EQ(value(b, Aov::Depth).x, 4.0f);  // planar, not the 4.011 m distance
  EXPECT_EQ(value(b, Aov::Position), Vec3(0.3f, 0.0f, 1.0f));
  EXPECT_FLOAT_EQ(value(b, Aov::ObjectIndex).x, 9.0f);  // instance 1's
  EXPECT_FLOAT_EQ(value(b, Aov::MaterialIndex).x, 3.0f);
}

TEST(AovPixel, AFirstSampleThatMissesLeavesDepth1e10AndIndexZeroEvenIfLaterOnesHit) {
  const Camera cam = camera_above();
  const AovRequest r = all_passes();
  AovBuffers b;
  b.allocate(r, 1, 1);
  AovPixel px(r, cam);
  px.add(FirstHit{}, true);
  px.add(hit_at(Vec3(0.0f), Vec3(0, 0, 1), Vec3(0.5f)), false);
  px.store(b, 0, 0.5f);
  EXPECT_EQ(value(b, Aov::Depth).x, 1e10f);
  EXPECT_EQ(value(b, Aov::ObjectIndex).x, 0.0f);
  EXPECT_EQ(value(b, Aov::Position), Vec3(0.0f));
}

TEST(AovPixel, NormalAlbedoAndMistAreAveragedWithMissesCountingAsNothingHit) {
  const Camera cam = camera_above();
  AovRequest r = all_passes();
  r.mist = MistSettings{1.0f, 8.0f, 1.0f};  // linear over [1, 9] m
  AovBuffers b;
  b.allocate(r, 1, 1);
  AovPixel px(r, cam);
  px.add(hit_at(Vec3(0.0f), Vec3(0, 0, 1), Vec3(0.8f, 0.4f, 0.2f)), true);  // 5 m: mist 0.5
  px.add(FirstHit{}, false);                                                // a miss: mist 1
  px.store(b, 0, 0.5f);
  EXPECT_EQ(value(b, Aov::Normal), Vec3(0.0f, 0.0f, 0.5f));
  EXPECT_EQ(value(b, Aov::DiffuseColor), Vec3(0.4f, 0.2f, 0.1f));
  EXPECT_FLOAT_EQ(value(b, Aov::Mist).x, 1.0f - 0.5f * (1.0f - 0.5f));
}

TEST(AovPixel, EmissionAndEnvironmentCountOnMissesAndGlossyColorIsAveraged) {
  const Camera cam = camera_above();
  const AovRequest r = all_passes();
  AovBuffers b;
  b.allocate(r, 1, 1);
  AovPixel px(r, cam);
  FirstHit miss;  // a lamp in front of the world, then nothing
  miss.emission = Vec3(4.0f, 2.0f, 0.0f);
  miss.environment = Vec3(0.2f, 0.4f, 0.6f);
  px.add(miss, true);
  FirstHit hit = hit_at(Vec3(0.0f), Vec3(0, 0, 1), Vec3(0.0f));
  hit.glossy = Vec3(0.8f, 0.6f, 0.4f);
  px.add(hit, false);
  px.store(b, 0, 0.5f);
  EXPECT_EQ(value(b, Aov::Emission), Vec3(2.0f, 1.0f, 0.0f));
  EXPECT_EQ(value(b, Aov::Environment), Vec3(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(value(b, Aov::GlossyColor), Vec3(0.4f, 0.3f, 0.2f));
  EXPECT_EQ(value(b, Aov::Depth).x, 1e10f);  // the first sample missed
}

TEST(AovPixel, MistFollowsCyclesFalloffExponents) {
  const Camera cam = camera_above();
  for (const auto& [falloff, expected] : {std::pair{2.0f, 0.25f}, {1.0f, 0.5f}, {0.5f, 0.70710678f}, {3.0f, 0.125f}}) {
    AovRequest r;
    r.mask = 1u << uint32_t(Aov::Mist);
    r.mist = MistSettings{1.0f, 8.0f, falloff};
    AovBuffers b;
    b.allocate(r, 1, 1);
    AovPixel px(r, cam);
    px.add(hit_at(Vec3(0.0f), Vec3(0, 0, 1), Vec3(0.5f)), true);
    px.store(b, 0, 1.0f);
    EXPECT_NEAR(value(b, Aov::Mist).x, expected, 1e-6f) << "falloff " << falloff;
  }
}

TEST(AovBuffers, OnlyThePassesAskedForAreAllocated) {
  AovRequest r;
  r.mask = (1u << uint32_t(Aov::Depth)) | (1u << uint32_t(Aov::Normal));
  AovBuffers b;
  b.allocate(r, 4, 3);
  for (size_t k = 0; k < kAovCount; ++k) {
    const Aov aov = Aov(k);
    EXPECT_EQ(b.data[k].size(), r.has(aov) ? size_t(12 * aov_channels(aov)) : 0u) << aov_name(aov);
  }
  EXPECT_EQ(b.data[size_t(Aov::Depth)][0], 1e10f);  // an unrendered pixel reads as nothing hit
  EXPECT_FALSE(AovRequest{}.any());
}

TEST(Aov, NamesParseBackAndAnUnknownOneIsRefused) {
  for (size_t k = 0; k < kAovCount; ++k) EXPECT_EQ(parse_aov(aov_name(Aov(k))), Aov(k));
  EXPECT_THROW(parse_aov("vector"), std::invalid_argument);
  for (size_t k = 0; k < kCryptoKindCount; ++k)
    EXPECT_EQ(parse_crypto_kind(crypto_kind_name(CryptoKind(k))), CryptoKind(k));
  EXPECT_THROW(parse_crypto_kind("light"), std::invalid_argument);
}

// Cryptomatte (render/cryptomatte.h): instances 0, 1, 2 with ids 1.5, 2.5, 3.5; asset ids group
// instances 0 and 1 under 7.5; material ids 0, 1 as 4.5, 5.5.
CryptomatteRequest crypto_request(int depth) {
  CryptomatteRequest r;
  r.depth = depth;
  r.ids[size_t(CryptoKind::Object)] = {1.5f, 2.5f, 3.5f};
  r.ids[size_t(CryptoKind::Material)] = {4.5f, 5.5f};
  r.ids[size_t(CryptoKind::Asset)] = {7.5f, 7.5f, 8.5f};
  return r;
}

TEST(CryptomattePixel, IdsAreRankedByTheirShareOfSamplesAndMissesCountAsNoId) {
  const CryptomatteRequest r = crypto_request(4);
  std::array<std::vector<float>, kCryptoKindCount> out;
  for (auto& o : out) o.assign(size_t(r.channels()), -1.0f);
  std::vector<CryptomattePixel::Entry> scratch;
  CryptomattePixel px(r, scratch);
  // 8 samples: instance 1 (material 0) three times, instance 2 (material 1) twice, instance 0
  // (material 1) twice, one miss.
  for (auto [instance, material] : {std::pair{0, 1}, {1, 0}, {2, 1}, {-1, -1}, {1, 0}, {2, 1}, {1, 0}, {0, 1}})
    px.add(instance, material);
  px.store(out, 0, 1.0f / 8.0f);
  // Equal shares keep the order in which the ids first came (instance 0 before 2), as Cycles.
  EXPECT_EQ(out[size_t(CryptoKind::Object)], (std::vector<float>{2.5f, 0.375f, 1.5f, 0.25f, 3.5f, 0.25f, 0.0f, 0.0f}));
  EXPECT_EQ(out[size_t(CryptoKind::Material)], (std::vector<float>{5.5f, 0.5f, 4.5f, 0.375f, 0, 0, 0, 0}));
  // The asset sums its instances: 0 and 1 are 5 of the 8 samples.
  EXPECT_EQ(out[size_t(CryptoKind::Asset)], (std::vector<float>{7.5f, 0.625f, 8.5f, 0.25f, 0, 0, 0, 0}));
}

TEST(CryptomattePixel, MoreIdsThanTheDepthKeepTheTopOnesExactly) {
  CryptomatteRequest r;
  r.depth = 2;
  for (int k = 0; k < 6; ++k) r.ids[size_t(CryptoKind::Object)].push_back(1.0f + float(k));
  std::array<std::vector<float>, kCryptoKindCount> out;
  out[0].assign(4, -1.0f);
  std::vector<CryptomattePixel::Entry> scratch;
  CryptomattePixel px(r, scratch);
  // Instance k is hit k + 1 times: the two most covered are 5 and 4, whatever the others add up to.
  for (int k = 0; k < 6; ++k)
    for (int n = 0; n <= k; ++n) px.add(k, 0);
  px.store(out, 0, 1.0f / 21.0f);
  EXPECT_EQ(out[0][0], 6.0f);
  EXPECT_FLOAT_EQ(out[0][1], 6.0f / 21.0f);
  EXPECT_EQ(out[0][2], 5.0f);
  EXPECT_FLOAT_EQ(out[0][3], 5.0f / 21.0f);
}

TEST(CryptomatteRequest, DepthOutsideBlendersRangeIsRefused) {
  EXPECT_NO_THROW(crypto_request(kCryptomatteMaxDepth).check());
  EXPECT_THROW(crypto_request(kCryptomatteMaxDepth + 1).check(), std::invalid_argument);
  EXPECT_THROW(crypto_request(0).check(), std::invalid_argument);
  EXPECT_THROW(crypto_request(-1).check(), std::invalid_argument);
  EXPECT_FALSE(CryptomatteRequest{}.any());
  AovRequest passes;
  passes.cryptomatte = crypto_request(1);
  EXPECT_TRUE(passes.any());  // a Cryptomatte pass alone takes the passes' path of the render loop
}

}  // namespace
}  // namespace toyrt
