// Comparing two impostor databases record by record (timings and generation numbers left out).
#include "farfield/store/store_compare.h"

#include <algorithm>
#include <array>

#include "farfield/store/generation_names.h"

namespace farfield::store {

namespace {

constexpr std::array<const char*, 4> kTimings = {"render_ms", "build_ms", "weights_ms", "ms"};
constexpr std::array<const char*, 4> kFiles = {"texture", "mesh", "ids", "streets"};

// A file name without its generation prefix ("cells/g000002.e000012.png" -> "cells/e000012.png").
std::string withoutGeneration(const std::string& name) {
  const size_t slash = name.rfind('/');
  const std::string dir = slash == std::string::npos ? "" : name.substr(0, slash + 1);
  const std::string file = slash == std::string::npos ? name : name.substr(slash + 1);
  const uint64_t g = generationOf(file);
  if (g == 0) return name;
  return dir + file.substr(generationPrefix(g).size());
}

void normalize(nlohmann::json& j) {
  if (j.is_array()) {
    for (nlohmann::json& e : j) normalize(e);
    return;
  }
  if (!j.is_object()) return;
  for (const char* key : kTimings) j.erase(key);
  for (const char* key : kFiles)
    if (j.contains(key) && j[key].is_string()) j[key] = withoutGeneration(j[key].get<std::string>());
  for (auto it = j.begin(); it != j.end(); ++it) normalize(it.value());
}

}  // namespace

nlohmann::json comparableRecords(const StoreIndex& index, bool with_shard) {
  nlohmann::json j = indexToJson(index);
  j.erase("generation");
  j.erase("checksum");
  if (!with_shard) j.erase("shard");
  normalize(j);
  return j;
}

std::string firstDifference(const nlohmann::json& a, const nlohmann::json& b, const std::string& at) {
  const std::string here = at.empty() ? "top level" : at;
  if (a.is_number() && b.is_number()) return a == b ? "" : here + ": " + a.dump() + " vs " + b.dump();
  if (a.type() != b.type()) return here + ": " + a.type_name() + " vs " + b.type_name();
  if (a.is_array()) {
    for (size_t k = 0; k < std::min(a.size(), b.size()); ++k) {
      std::string d = firstDifference(a[k], b[k], at + "[" + std::to_string(k) + "]");
      if (!d.empty()) return d;
    }
    if (a.size() != b.size())
      return here + ": " + std::to_string(a.size()) + " vs " + std::to_string(b.size()) + " elements";
    return "";
  }
  if (a.is_object()) {
    for (auto it = a.begin(); it != a.end(); ++it) {
      const std::string path = at.empty() ? it.key() : at + "." + it.key();
      if (!b.contains(it.key())) return path + ": only in the first";
      std::string d = firstDifference(it.value(), b[it.key()], path);
      if (!d.empty()) return d;
    }
    for (auto it = b.begin(); it != b.end(); ++it)
      if (!a.contains(it.key())) return (at.empty() ? it.key() : at + "." + it.key()) + ": only in the second";
    return "";
  }
  if (a != b) return here + ": " + a.dump() + " vs " + b.dump();
  return "";
}

}  // namespace farfield::store
