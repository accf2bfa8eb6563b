#include "core/params.h"

#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>

namespace toyrt {
namespace {

std::string show(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

const char* kind_of(const Params::Value& v) {
  switch (v.index()) {
    case 0:
      return "a number";
    case 1:
      return "a bool";
    case 2:
      return "text";
    case 3:
      return "3 numbers";
    default:
      return "a (4, 4) matrix";
  }
}

}  // namespace

Params& Params::set(std::string_view name, Value value) {
  const int i = find(name);
  if (i >= 0) {
    values_[size_t(i)].second = std::move(value);
  } else {
    values_.emplace_back(std::string(name), std::move(value));
  }
  return *this;
}

int Params::find(std::string_view name) const {
  for (size_t i = 0; i < values_.size(); ++i)
    if (values_[i].first == name) return int(i);
  return -1;
}

const Params::Value* Params::get(std::string_view name) const {
  const int i = find(name);
  if (i < 0) return nullptr;
  read_.resize(values_.size(), false);
  read_[size_t(i)] = true;
  return &values_[size_t(i)].second;
}

void Params::fail(std::string_view name, const std::string& requirement, const std::string& got) const {
  throw std::invalid_argument(subject_ + ": " + std::string(name) + " must be " + requirement + ", got " + got);
}

template <class T>
const T* Params::typed(std::string_view name, const char* expected) const {
  const Value* v = get(name);
  if (!v) return nullptr;
  const T* x = std::get_if<T>(v);
  if (!x) fail(name, expected, kind_of(*v));
  return x;
}

double Params::number(std::string_view name, double fallback) const {
  const double* x = typed<double>(name, "a number");
  if (!x) return fallback;
  if (!std::isfinite(*x)) fail(name, "a finite number", show(*x));
  return *x;
}

double Params::non_negative(std::string_view name, double fallback) const {
  const double* x = typed<double>(name, "a number");
  if (!x) return fallback;
  if (!(std::isfinite(*x) && *x >= 0.0)) fail(name, "finite and >= 0", show(*x));
  return *x;
}

double Params::positive(std::string_view name, double fallback) const {
  const double* x = typed<double>(name, "a number");
  if (!x) return fallback;
  if (!(std::isfinite(*x) && *x > 0.0)) fail(name, "positive and finite", show(*x));
  return *x;
}

int64_t Params::integer(std::string_view name, int64_t fallback) const {
  const double* x = typed<double>(name, "a whole number");
  if (!x) return fallback;
  if (!(*x >= double(INT32_MIN) && *x <= double(INT32_MAX)) || *x != std::floor(*x))
    fail(name, "a whole number in int32's range", show(*x));
  return int64_t(*x);
}

Vec3 Params::color(std::string_view name, const Vec3& fallback) const {
  const Vec3* x = typed<Vec3>(name, "3 numbers (linear RGB)");
  if (!x) return fallback;
  if (!is_finite(*x) || glm::any(glm::lessThan(*x, Vec3(0.0f))))
    fail(name, "finite and >= 0", "(" + show(x->x) + ", " + show(x->y) + ", " + show(x->z) + ")");
  return *x;
}

Vec3 Params::point(std::string_view name, const Vec3& fallback) const {
  const Vec3* x = typed<Vec3>(name, "3 numbers");
  if (!x) return fallback;
  if (!is_finite(*x)) fail(name, "finite", "(" + show(x->x) + ", " + show(x->y) + ", " + show(x->z) + ")");
  return *x;
}

Mat4 Params::matrix(std::string_view name, const Mat4& fallback) const {
  const Mat4* x = typed<Mat4>(name, "a (4, 4) matrix");
  if (!x) return fallback;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite((*x)[c][r])) fail(name, "finite", "a non-finite value");
  return *x;
}

std::string Params::text(std::string_view name, std::string_view fallback) const {
  const std::string* x = typed<std::string>(name, "text");
  return x ? *x : std::string(fallback);
}

bool Params::flag(std::string_view name, bool fallback) const {
  const bool* x = typed<bool>(name, "True or False");
  return x ? *x : fallback;
}

void Params::allow_unread(std::string_view name) {
  const int i = find(name);
  if (i < 0) return;
  read_.resize(values_.size(), false);
  read_[size_t(i)] = true;
}

void Params::check_all_read() const {
  read_.resize(values_.size(), false);
  for (size_t i = 0; i < values_.size(); ++i)
    if (!read_[i]) throw UnknownArgument("unknown argument '" + values_[i].first + "' for a " + subject_);
}

}  // namespace toyrt
