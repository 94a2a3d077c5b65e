// Strict JSON fields of the store's indexes (json_fields.h).
#include "farfield/store/json_fields.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>

#include "farfield/core/checked_cast.h"
#include "farfield/core/error.h"

namespace fs = std::filesystem;

namespace farfield::store {

nlohmann::json vec3Json(const Vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); }

nlohmann::json box3Json(const Box3& b) { return {{"lo", vec3Json(b.lo)}, {"hi", vec3Json(b.hi)}}; }

void JsonReader::fail(const std::string& where, const std::string& what) const {
  throw Error(source_, where + ": " + what);
}

const nlohmann::json& JsonReader::member(const nlohmann::json& j, const char* key, const std::string& where) const {
  if (!j.is_object()) fail(where, "expected an object");
  const auto it = j.find(key);
  if (it == j.end()) fail(where, std::string("missing \"") + key + "\"");
  return *it;
}

double JsonReader::number(const nlohmann::json& j, const char* key, const std::string& where) const {
  const nlohmann::json& v = member(j, key, where);
  if (!v.is_number()) fail(where, std::string("\"") + key + "\" must be a number");
  const double d = v.get<double>();
  if (!std::isfinite(d)) fail(where, std::string("\"") + key + "\" is not finite");
  return d;
}

uint64_t JsonReader::count(const nlohmann::json& j, const char* key, const std::string& where) const {
  const nlohmann::json& v = member(j, key, where);
  if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<int64_t>() >= 0))
    fail(where, std::string("\"") + key + "\" must be a non-negative integer");
  return v.get<uint64_t>();
}

int64_t JsonReader::integer(const nlohmann::json& j, const char* key, const std::string& where, int64_t lo,
                            int64_t hi) const {
  const nlohmann::json& v = member(j, key, where);
  bool in_range = false;
  int64_t value = 0;
  if (v.is_number_unsigned()) {
    const uint64_t u = v.get<uint64_t>();
    in_range = hi >= 0 && u <= uint64_t(hi) && int64_t(u) >= lo;
    value = in_range ? int64_t(u) : 0;
  } else if (v.is_number_integer()) {
    value = v.get<int64_t>();
    in_range = value >= lo && value <= hi;
  }
  if (!in_range)
    fail(where, std::string("\"") + key + "\" must be an integer in " + std::to_string(lo) + ".." + std::to_string(hi));
  return value;
}

bool JsonReader::flag(const nlohmann::json& j, const char* key, const std::string& where) const {
  const nlohmann::json& v = member(j, key, where);
  if (!v.is_boolean()) fail(where, std::string("\"") + key + "\" must be true or false");
  return v.get<bool>();
}

std::string JsonReader::text(const nlohmann::json& j, const char* key, const std::string& where) const {
  const nlohmann::json& v = member(j, key, where);
  if (!v.is_string()) fail(where, std::string("\"") + key + "\" must be a string");
  return v.get<std::string>();
}

std::string JsonReader::relativeFile(const nlohmann::json& j, const char* key, const std::string& where,
                                     bool allow_empty) const {
  const std::string name = text(j, key, where);
  if (name.empty()) {
    if (!allow_empty) fail(where, std::string("\"") + key + "\" is empty");
    return name;
  }
  const fs::path p(name);
  if (p.is_absolute()) fail(where, std::string("\"") + key + "\" must be relative to the store directory");
  for (const fs::path& part : p)
    if (part == "..") fail(where, std::string("\"") + key + "\" must not contain \"..\"");
  return name;
}

Vec3 JsonReader::vec3(const nlohmann::json& j, const char* key, const std::string& where) const {
  const nlohmann::json& v = member(j, key, where);
  if (!v.is_array() || v.size() != 3) fail(where, std::string("\"") + key + "\" must be [x, y, z]");
  Vec3 out;
  for (int i = 0; i < 3; ++i) {
    if (!v[size_t(i)].is_number()) fail(where, std::string("\"") + key + "\" must hold numbers");
    out[i] = v[size_t(i)].get<float>();
  }
  if (!isFinite(out)) fail(where, std::string("\"") + key + "\" is not finite");
  return out;
}

Box3 JsonReader::box3(const nlohmann::json& j, const char* key, const std::string& where) const {
  const nlohmann::json& b = member(j, key, where);
  const std::string at = where + "." + key;
  onlyKeys(b, {"lo", "hi"}, at);
  Box3 box;
  box.lo = vec3(b, "lo", at);
  box.hi = vec3(b, "hi", at);
  if (box.empty()) fail(at, "is empty (\"lo\" > \"hi\" on some axis)");
  return box;
}

Camera JsonReader::camera(const nlohmann::json& j, const std::string& where) const {
  const nlohmann::json& c = member(j, "camera", where);
  const std::string at = where + ": camera";
  Camera cam;
  cam.eye = vec3(c, "eye", at);
  cam.at = vec3(c, "at", at);
  cam.up = vec3(c, "up", at);
  cam.fov_y = float(number(c, "fov_y", at));
  // An int conversion would wrap 2^32 + 512 to 512 and pass the camera's checks.
  cam.width = checkedCast<int>(count(c, "width", at), source_, at + ": \"width\"");
  cam.height = checkedCast<int>(count(c, "height", at), source_, at + ": \"height\"");
  cam.near_plane = float(number(c, "near", at));
  cam.far_plane = float(number(c, "far", at));
  try {
    cam.validate("camera");
  } catch (const Error& e) {
    fail(at, e.what());
  }
  return cam;
}

void JsonReader::onlyKeys(const nlohmann::json& j, std::initializer_list<const char*> allowed,
                          const std::string& where) const {
  if (!j.is_object()) fail(where, "expected an object");
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& key = it.key();  // a name, not a structured binding: clang 14 (the fuzz build) cannot capture one
    if (std::none_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; }))
      fail(where, "unknown member \"" + key + "\"");
  }
}

void putCheck(nlohmann::json& j, const std::string& key, const std::string& file, const FileCheck& check,
              bool with_checks) {
  if (!with_checks || file.empty() || !check.known) return;
  j[key + "_crc32"] = check.crc32;
  j[key + "_bytes"] = check.bytes;
}

FileCheck readCheck(const JsonReader& r, const nlohmann::json& j, const std::string& key, const std::string& where,
                    const std::string& file, bool required) {
  FileCheck check;
  const std::string crc_key = key + "_crc32", bytes_key = key + "_bytes";
  if (file.empty() || (!required && !j.contains(crc_key) && !j.contains(bytes_key))) return check;
  const uint64_t crc = r.count(j, crc_key.c_str(), where);
  if (crc > 0xffffffffu) r.fail(where, "\"" + crc_key + "\" must be a CRC-32 (0..4294967295)");
  check.crc32 = uint32_t(crc);
  check.bytes = r.count(j, bytes_key.c_str(), where);
  check.known = true;
  return check;
}

std::vector<uint32_t> readIds(const JsonReader& r, const nlohmann::json& j, const char* key, const std::string& where,
                              size_t scene_objects) {
  const nlohmann::json& list = r.member(j, key, where);
  if (!list.is_array()) r.fail(where, std::string("\"") + key + "\" must be an array of object ids");
  std::vector<uint32_t> ids;
  ids.reserve(list.size());
  for (const nlohmann::json& id : list) {
    if (!id.is_number_unsigned() || id.get<uint64_t>() == 0 || id.get<uint64_t>() > scene_objects)
      r.fail(where, std::string("\"") + key + "\" holds an id outside 1.." + std::to_string(scene_objects));
    ids.push_back(id.get<uint32_t>());
  }
  if (std::adjacent_find(ids.begin(), ids.end(), std::greater_equal<uint32_t>()) != ids.end())
    r.fail(where, std::string("\"") + key + "\" must be ascending without repeats");
  return ids;
}

}  // namespace farfield::store
