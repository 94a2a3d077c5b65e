// Reading saved options strictly (DESIGN.md: options are saved whole and read back strictly): every key asked for
// must be present with the right type and range, and rejectUnknown() refuses any key nobody asked for. Errors are
// farfield::Error naming the source (a file and a path inside it) and the key.
#pragma once

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/core/checked_cast.h"
#include "farfield/core/error.h"

namespace farfield {

class StrictJson {
 public:
  // `what` names the kind of value in messages ("pipeline option", "placement option").
  StrictJson(const nlohmann::json& j, std::string where, std::string what = "option")
      : j_(j), where_(std::move(where)), what_(std::move(what)) {
    if (!j_.is_object()) throw Error(where_, what_ + "s must be a JSON object");
  }
  bool has(const char* key) const { return j_.contains(key); }
  const nlohmann::json& at(const char* key) {
    const auto it = j_.find(key);
    if (it == j_.end()) throw Error(where_, what_ + " \"" + key + "\" is missing");
    seen_.push_back(key);
    return *it;
  }
  template <typename T>
  void number(const char* key, T& out) {
    const nlohmann::json& v = at(key);
    if (!v.is_number()) throw Error(where_, what_ + " \"" + key + "\" must be a number");
    const double d = v.get<double>();
    if (!std::isfinite(d)) throw Error(where_, what_ + " \"" + key + "\" is not finite");
    if constexpr (std::is_integral_v<T>) {
      // fitsIn, not "d <= double(max)": double(INT64_MAX) is 2^63, one past the range.
      if (d != std::floor(d) || !fitsIn<T>(d))
        throw Error(where_, what_ + " \"" + key + "\" must be an integer in range");
    }
    out = checkedCast<T>(d, where_, what_ + " \"" + key + "\"");
  }
  template <typename T>
  void numbers(const char* key, std::vector<T>& out) {
    const nlohmann::json& v = at(key);
    if (!v.is_array()) throw Error(where_, what_ + " \"" + key + "\" must be an array of numbers");
    out.clear();
    for (const nlohmann::json& e : v) {
      if (!e.is_number() || !std::isfinite(e.get<double>()))
        throw Error(where_, what_ + " \"" + key + "\" must hold finite numbers only");
      out.push_back(checkedCast<T>(e.get<double>(), where_, what_ + " \"" + key + "\""));
    }
  }
  std::string text(const char* key) {
    const nlohmann::json& v = at(key);
    if (!v.is_string()) throw Error(where_, what_ + " \"" + key + "\" must be a string");
    return v.get<std::string>();
  }
  bool boolean(const char* key) {
    const nlohmann::json& v = at(key);
    if (!v.is_boolean()) throw Error(where_, what_ + " \"" + key + "\" must be true or false");
    return v.get<bool>();
  }
  // One of `names` (the first maps to 0, ...).
  size_t choice(const char* key, std::initializer_list<const char*> names) {
    const std::string v = text(key);
    size_t i = 0;
    std::string list;
    for (const char* n : names) {
      if (v == n) return i;
      list += (i++ ? ", " : "") + std::string(n);
    }
    throw Error(where_, what_ + " \"" + key + "\": unknown value '" + v + "' (expected " + list + ")");
  }
  // A nested object, read with its own StrictJson (where = this one's + "." + key).
  StrictJson object(const char* key) { return StrictJson(at(key), where_ + "." + key, what_); }
  void rejectUnknown() const {
    for (const auto& [key, value] : j_.items())
      if (std::find(seen_.begin(), seen_.end(), key) == seen_.end())
        throw Error(where_, "unknown " + what_ + " \"" + key + "\"");
  }
  const std::string& where() const { return where_; }

 private:
  const nlohmann::json& j_;
  std::string where_;
  std::string what_;
  std::vector<std::string> seen_;
};

}  // namespace farfield
