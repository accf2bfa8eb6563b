#include "sampling/distribution_2d.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace toyrt {
namespace {

// Normalises the running sums in cdf[0 .. n] to end at 1; an all-zero row becomes uniform.
// Returns the total. Sums in double: a row of 32768 cells must not lose its small ones.
double make_cdf(const float* weights, int n, float* cdf) {
  double total = 0.0;
  cdf[0] = 0.0f;
  for (int i = 0; i < n; ++i) total += weights[i];
  if (total > 0.0) {
    double run = 0.0;
    for (int i = 0; i < n; ++i) {
      run += weights[i];
      cdf[i + 1] = float(run / total);
    }
  } else {
    for (int i = 0; i < n; ++i) cdf[i + 1] = float(double(i + 1) / n);
  }
  cdf[n] = 1.0f;
  return total;
}

// The cell i with cdf[i] <= u < cdf[i + 1], skipping empty cells, and u's position within it.
int find_cell(const float* cdf, int n, float u, float& offset) {
  const float* it = std::upper_bound(cdf + 1, cdf + n + 1, u);
  int i = std::clamp(int(it - cdf) - 1, 0, n - 1);
  while (i < n - 1 && cdf[i + 1] <= cdf[i]) ++i;  // only reachable by rounding at u ~ 1
  const float width = cdf[i + 1] - cdf[i];
  offset = width > 0.0f ? std::clamp((u - cdf[i]) / width, 0.0f, 0.99999994f) : 0.5f;
  return i;
}

}  // namespace

Distribution2D Distribution2D::build(const std::vector<float>& weights, int width, int height) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("distribution: sizes must be positive");
  if (weights.size() != size_t(width) * size_t(height))
    throw std::invalid_argument("distribution: weights do not match its size");
  for (float w : weights)
    if (!std::isfinite(w) || w < 0.0f) throw std::invalid_argument("distribution: weights must be finite and >= 0");
  Distribution2D d;
  d.width = width;
  d.height = height;
  d.conditional.resize(size_t(height) * size_t(width + 1));
  std::vector<float> rows(static_cast<size_t>(height));
  double total = 0.0;
  for (int y = 0; y < height; ++y) {
    rows[size_t(y)] =
        float(make_cdf(&weights[size_t(y) * size_t(width)], width, &d.conditional[size_t(y) * (width + 1)]));
    total += rows[size_t(y)];
  }
  d.marginal.resize(size_t(height) + 1);
  make_cdf(rows.data(), height, d.marginal.data());
  d.density.resize(weights.size());
  const double mean = total / (double(width) * height);
  for (size_t i = 0; i < weights.size(); ++i) d.density[i] = mean > 0.0 ? float(weights[i] / mean) : 1.0f;
  return d;
}

Vec2 Distribution2D::sample(const Vec2& u, float& pdf) const {
  float dy = 0.0f, dx = 0.0f;
  const int y = find_cell(marginal.data(), height, u.y, dy);
  const int x = find_cell(&conditional[size_t(y) * (width + 1)], width, u.x, dx);
  pdf = density[size_t(y) * width + x];
  return Vec2((x + dx) / float(width), (y + dy) / float(height));
}

float Distribution2D::pdf(const Vec2& uv) const {
  const int x = std::clamp(int(uv.x * float(width)), 0, width - 1);
  const int y = std::clamp(int(uv.y * float(height)), 0, height - 1);
  return density[size_t(y) * width + x];
}

}  // namespace toyrt
