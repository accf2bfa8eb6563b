// Cryptomatte passes (Psyop's Cryptomatte specification 1.2, as Cycles writes them): per pixel, the
// ids of the objects, materials or assets its camera rays first hit, ranked by coverage (the share
// of the pixel's samples whose first hit carries that id), the top `depth` (id, coverage) pairs
// written and zeros after. A sample that hits nothing carries no id, as in Cycles (whose
// background writes none), so coverage sums to 1 only on pixels covered by surfaces.
// The ids are given, not computed: the caller hashes names (MurmurHash3_32 reinterpreted as a
// float, addon/render_toyrt/cryptomatte.py) into a table per instance or per material id; 0.0 is
// the specification's "no id" and an id of 0.0 or an index outside its table counts as a miss.
// Counting is exact (every distinct id of the pixel is kept, not only `depth` slots as in Cycles,
// whose last slot absorbs the rest); ties keep the order of first arrival, as Cycles' stable sort.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace toyrt {

enum class CryptoKind : uint8_t { Object, Material, Asset, Count };
inline constexpr size_t kCryptoKindCount = size_t(CryptoKind::Count);
// Blender's pass_cryptomatte_depth goes up to 16, which Cycles writes as 8 RGBA layers: 16 pairs.
inline constexpr int kCryptomatteMaxDepth = 16;

// The name render(cryptomatte={...}) takes: "object", "material", "asset".
const char* crypto_kind_name(CryptoKind kind);
// Throws std::invalid_argument for a name that is none of crypto_kind_name's.
CryptoKind parse_crypto_kind(const std::string& name);

struct CryptomatteRequest {
  int depth = 0;  // (id, coverage) pairs per pixel and kind; 0: no Cryptomatte pass
  // Per kind asked for, the id of each instance (object, asset) or material id (material); an
  // empty table: that kind is not asked for.
  std::array<std::vector<float>, kCryptoKindCount> ids;
  bool has(CryptoKind kind) const { return depth > 0 && !ids[size_t(kind)].empty(); }
  bool any() const;
  // Float channels per pixel of one kind: depth pairs.
  int channels() const { return 2 * depth; }
  // Throws std::invalid_argument for a depth outside [0, kCryptomatteMaxDepth], or a kind asked
  // for with depth 0.
  void check() const;
};

// One pixel's ids and sample counts per kind, in a scratch list the caller keeps per tile (no
// allocation per pixel once it has grown to the largest pixel's count of distinct ids).
class CryptomattePixel {
 public:
  struct Entry {
    float id;
    uint32_t count;
    uint8_t kind;
  };
  CryptomattePixel(const CryptomatteRequest& request, std::vector<Entry>& scratch);
  // One sample's first hit (instance -1: a miss).
  void add(int32_t instance, int32_t material);
  // Writes the ranked pairs of each kind asked for into out[kind] at `pixel` (channels() floats).
  void store(std::array<std::vector<float>, kCryptoKindCount>& out, size_t pixel, float inv_samples);

 private:
  void count(CryptoKind kind, int32_t index);
  const CryptomatteRequest& request_;
  std::vector<Entry>& entries_;
};

}  // namespace toyrt
