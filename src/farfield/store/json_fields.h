// Typed, strict access to the JSON indexes of the store's databases (impostor_store.h, placement_store.h): every
// reader error is a farfield::Error "SOURCE: WHERE: WHAT" naming the file, the element and what was expected. And
// the JSON forms both indexes share: vectors, file checks next to file names, ascending object id lists.
//
// Floats go through JSON numbers (nlohmann writes a double with enough digits to read it back exactly; a float
// widened to double and read back as float is the same float), so every value written here reads back bit for bit.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/core/math.h"
#include "farfield/store/impostor_store.h"

namespace farfield::store {

nlohmann::json vec3Json(const Vec3& v);
// {"lo": [x, y, z], "hi": [x, y, z]}
nlohmann::json box3Json(const Box3& b);

// Typed access with errors naming the source and the element.
class JsonReader {
 public:
  explicit JsonReader(const std::string& source) : source_(source) {}
  [[noreturn]] void fail(const std::string& where, const std::string& what) const;
  const nlohmann::json& member(const nlohmann::json& j, const char* key, const std::string& where) const;
  // Finite number.
  double number(const nlohmann::json& j, const char* key, const std::string& where) const;
  uint64_t count(const nlohmann::json& j, const char* key, const std::string& where) const;
  // Integer in [lo, hi].
  int64_t integer(const nlohmann::json& j, const char* key, const std::string& where, int64_t lo, int64_t hi) const;
  bool flag(const nlohmann::json& j, const char* key, const std::string& where) const;
  std::string text(const nlohmann::json& j, const char* key, const std::string& where) const;
  // A file name relative to the store directory: no absolute path, no "..".
  std::string relativeFile(const nlohmann::json& j, const char* key, const std::string& where,
                           bool allow_empty) const;
  Vec3 vec3(const nlohmann::json& j, const char* key, const std::string& where) const;
  // A box written by box3Json: finite, lo <= hi on every axis (not empty).
  Box3 box3(const nlohmann::json& j, const char* key, const std::string& where) const;
  Camera camera(const nlohmann::json& j, const std::string& where) const;
  // j is an object with no member outside `allowed` (missing members are found by member()).
  void onlyKeys(const nlohmann::json& j, std::initializer_list<const char*> allowed, const std::string& where) const;

 private:
  std::string source_;
};

// "KEY_crc32" and "KEY_bytes" next to a file name (version 3, non-empty names with a known check).
void putCheck(nlohmann::json& j, const std::string& key, const std::string& file, const FileCheck& check,
              bool with_checks);
// The check of the file named by j[key]: required for non-empty names when `required`, read whenever present.
FileCheck readCheck(const JsonReader& r, const nlohmann::json& j, const std::string& key, const std::string& where,
                    const std::string& file, bool required);
// j[key]: object ids in 1..scene_objects, ascending without repeats.
std::vector<uint32_t> readIds(const JsonReader& r, const nlohmann::json& j, const char* key, const std::string& where,
                              size_t scene_objects);

}  // namespace farfield::store
