#include "render/cryptomatte.h"

#include <algorithm>
#include <stdexcept>

namespace toyrt {

namespace {
constexpr std::array<const char*, kCryptoKindCount> kKindNames{{"object", "material", "asset"}};
}  // namespace

const char* crypto_kind_name(CryptoKind kind) { return kKindNames[size_t(kind)]; }

CryptoKind parse_crypto_kind(const std::string& name) {
  for (size_t k = 0; k < kCryptoKindCount; ++k)
    if (name == kKindNames[k]) return CryptoKind(k);
  throw std::invalid_argument("render: unknown Cryptomatte kind '" + name + "' (known: object, material, asset)");
}

bool CryptomatteRequest::any() const {
  for (size_t k = 0; k < kCryptoKindCount; ++k)
    if (has(CryptoKind(k))) return true;
  return false;
}

void CryptomatteRequest::check() const {
  if (depth < 0 || depth > kCryptomatteMaxDepth)
    throw std::invalid_argument("render: cryptomatte_depth must be in [0, " + std::to_string(kCryptomatteMaxDepth) +
                                "] (got " + std::to_string(depth) + ")");
  if (depth == 0)
    for (const std::vector<float>& table : ids)
      if (!table.empty()) throw std::invalid_argument("render: a Cryptomatte pass needs cryptomatte_depth >= 1");
}

CryptomattePixel::CryptomattePixel(const CryptomatteRequest& request, std::vector<Entry>& scratch)
    : request_(request), entries_(scratch) {
  entries_.clear();
}

void CryptomattePixel::count(CryptoKind kind, int32_t index) {
  const std::vector<float>& table = request_.ids[size_t(kind)];
  if (index < 0 || size_t(index) >= table.size() || table[size_t(index)] == 0.0f) return;  // no id: a miss
  const float id = table[size_t(index)];
  // A pixel sees few distinct ids: a linear search beats any map, and keeps arrival order.
  for (Entry& e : entries_)
    if (e.id == id && e.kind == uint8_t(kind)) {
      ++e.count;
      return;
    }
  entries_.push_back({id, 1u, uint8_t(kind)});
}

void CryptomattePixel::add(int32_t instance, int32_t material) {
  if (instance < 0) return;
  if (request_.has(CryptoKind::Object)) count(CryptoKind::Object, instance);
  if (request_.has(CryptoKind::Material)) count(CryptoKind::Material, material);
  if (request_.has(CryptoKind::Asset)) count(CryptoKind::Asset, instance);
}

void CryptomattePixel::store(std::array<std::vector<float>, kCryptoKindCount>& out, size_t pixel, float inv) {
  // Highest coverage first; equal counts keep their order of arrival, as in Cycles. An insertion
  // sort: the list is short, and std::stable_sort would allocate a buffer per pixel.
  for (size_t i = 1; i < entries_.size(); ++i)
    for (size_t j = i; j > 0 && entries_[j].count > entries_[j - 1].count; --j) std::swap(entries_[j], entries_[j - 1]);
  const size_t channels = size_t(request_.channels());
  for (size_t k = 0; k < kCryptoKindCount; ++k) {
    if (!request_.has(CryptoKind(k))) continue;
    float* dst = out[k].data() + pixel * channels;
    std::fill(dst, dst + channels, 0.0f);
    size_t written = 0;
    for (const Entry& e : entries_) {
      if (e.kind != uint8_t(k)) continue;
      if (written == channels) break;
      dst[written] = e.id;
      dst[written + 1] = float(e.count) * inv;
      written += 2;
    }
  }
}

}  // namespace toyrt
