// Parameters as data: a type's Blender-facing settings as names -> values, so a new light or
// material reads its own settings (its from_params) and the binding passes any keyword along
// without knowing the type. The typed getters take the default (which lives in the type's own
// header, as a struct member default) and validate, throwing std::invalid_argument that names
// the subject and the argument ("POINT light: power must be finite and >= 0, got -1").
// check_all_read() refuses an argument no getter asked for, so a typo is an error, not a silent
// default ("unknown argument 'powr' for a POINT light").
#pragma once

#include "core/math.h"

#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace toyrt {

// An argument no getter asked for (a typo, or a parameter of another type). Python raises
// TypeError for an unexpected keyword; the binding translates this one the same way.
struct UnknownArgument : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

class Params {
 public:
  using Value = std::variant<double, bool, std::string, Vec3, Mat4>;

  Params() = default;
  explicit Params(std::vector<std::pair<std::string, Value>> values) : values_(std::move(values)) {}

  // Adds or replaces a value.
  Params& set(std::string_view name, Value value);
  bool has(std::string_view name) const { return find(name) >= 0; }
  size_t size() const { return values_.size(); }

  // What the values describe, for messages ("POINT light", "glass material").
  void set_subject(std::string subject) { subject_ = std::move(subject); }
  const std::string& subject() const { return subject_; }

  // Typed getters: the value, or `fallback` when absent. Each marks the name as read.
  double number(std::string_view name, double fallback) const;        // finite
  double non_negative(std::string_view name, double fallback) const;  // finite and >= 0
  double positive(std::string_view name, double fallback) const;      // finite and > 0
  int64_t integer(std::string_view name, int64_t fallback) const;     // a whole number in int32's range
  Vec3 color(std::string_view name, const Vec3& fallback) const;      // finite and >= 0 per channel
  Vec3 point(std::string_view name, const Vec3& fallback) const;      // finite
  Mat4 matrix(std::string_view name, const Mat4& fallback) const;     // finite
  std::string text(std::string_view name, std::string_view fallback) const;
  bool flag(std::string_view name, bool fallback) const;

  // An argument every caller sends whether or not the type uses it (the binding's documented
  // keywords): check_all_read() lets it pass unread.
  void allow_unread(std::string_view name);
  // Throws std::invalid_argument for the first argument no getter read: "unknown argument
  // 'powr' for a POINT light".
  void check_all_read() const;

 private:
  int find(std::string_view name) const;
  const Value* get(std::string_view name) const;
  [[noreturn]] void fail(std::string_view name, const std::string& requirement, const std::string& got) const;
  template <class T>
  const T* typed(std::string_view name, const char* expected) const;

  std::vector<std::pair<std::string, Value>> values_;
  mutable std::vector<bool> read_;  // parallel to values_: reading is logically const
  std::string subject_ = "argument";
};

}  // namespace toyrt
