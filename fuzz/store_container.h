// The input of the store targets: a database as one byte string. An index (JSON), then the data files it names, each
// after a separator line:
//
//   MODE INDEX-TEXT ["\n--ff-file--\n" FILE-BYTES]...
//
// MODE is one byte (below). The files are given, in order, to the distinct file names the index's JSON holds under
// the store's file keys ("streets", "texture", "mesh", "ids"), in the JSON's order (keys sorted); names without a file
// are left missing. With kRepairChecks the target makes the checks the readers verify first true: each file's
// "KEY_crc32"/"KEY_bytes" and the index's "checksum" and text form, so the fuzzer reaches the record readers behind
// them (mesh decoding, PNG decoding, counts, camera sizes) instead of stopping at a checksum mismatch. Without it the
// index text and the checks are as given.
#pragma once

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/store/impostor_store.h"
#include "fuzz_support.h"

namespace farfield::fuzz {

inline constexpr std::string_view kFileSeparator = "\n--ff-file--\n";
inline constexpr uint8_t kRawChecks = 1;      // MODE bit: leave checks and index text as given
inline constexpr uint8_t kThreadedReader = 2; // MODE bit (impostor store): read the cells with store::CellReader

struct StoreInput {
  uint8_t mode = 0;
  std::string index;
  std::vector<std::string> files;
};

inline StoreInput splitStoreInput(const uint8_t* data, size_t size) {
  StoreInput in;
  if (size == 0) return in;
  in.mode = data[0];
  std::string_view rest(reinterpret_cast<const char*>(data) + 1, size - 1);
  size_t at = rest.find(kFileSeparator);
  in.index = std::string(rest.substr(0, at));
  while (at != std::string_view::npos) {
    rest = rest.substr(at + kFileSeparator.size());
    at = rest.find(kFileSeparator);
    in.files.emplace_back(rest.substr(0, at));
  }
  return in;
}

// A name the harness may create under the database directory: relative, plain characters, no "..". (The readers
// refuse the others themselves; the harness only must not write outside its scratch directory.)
inline bool safeName(const std::string& name) {
  if (name.empty() || name.size() > 200 || name.front() == '/') return false;
  for (char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-' || c == '/')) return false;
  for (const auto& part : std::filesystem::path(name))
    if (part == ".." || part == ".") return false;
  return true;
}

// The distinct file names under the store's file keys of `j`, in the order the input's files are given to them: an
// object's own keys first ("ids", "mesh", "streets", "texture"), then its members in key order, arrays in order.
inline void fileNames(const nlohmann::json& j, std::vector<std::string>& out) {
  if (j.is_array()) {
    for (const nlohmann::json& e : j) fileNames(e, out);
    return;
  }
  if (!j.is_object()) return;
  for (const char* key : {"ids", "mesh", "streets", "texture"}) {
    const auto it = j.find(key);
    if (it == j.end() || !it->is_string()) continue;
    const std::string name = it->get<std::string>();
    if (safeName(name) && std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
  }
  for (const auto& [k, v] : j.items())
    if (v.is_structured()) fileNames(v, out);
}

// Sets "KEY_crc32" and "KEY_bytes" next to every name of `j` that `checks` holds.
inline void repairChecks(nlohmann::json& j, const std::map<std::string, store::FileCheck>& checks) {
  if (j.is_array()) {
    for (nlohmann::json& e : j) repairChecks(e, checks);
    return;
  }
  if (!j.is_object()) return;
  for (const char* key : {"ids", "mesh", "streets", "texture"}) {
    const auto it = j.find(key);
    if (it == j.end() || !it->is_string()) continue;
    const auto c = checks.find(it->get<std::string>());
    if (c == checks.end()) continue;
    j[std::string(key) + "_crc32"] = c->second.crc32;
    j[std::string(key) + "_bytes"] = c->second.bytes;
  }
  for (auto& [k, v] : j.items())
    if (v.is_structured()) repairChecks(v, checks);
}

// Writes the input's files under `dir` for the names of `j` and returns their checks.
inline std::map<std::string, store::FileCheck> placeFiles(const nlohmann::json& j, const std::filesystem::path& dir,
                                                          const std::vector<std::string>& files) {
  std::vector<std::string> names;
  fileNames(j, names);
  std::map<std::string, store::FileCheck> checks;
  for (size_t i = 0; i < names.size() && i < files.size(); ++i) {
    const std::filesystem::path p = dir / names[i];
    std::error_code ec;
    std::filesystem::create_directories(p.parent_path(), ec);
    if (ec || std::filesystem::exists(p, ec)) continue;  // a name that is a directory of another name
    writeBytes(p, files[i]);
    checks[names[i]] = store::fileCheck(files[i]);
  }
  return checks;
}

// Writes the input's files under `dir` and its index to `dir / index_name`. Unless the MODE bit kRawChecks is set,
// the index's file checks are repaired to match the files and the index is written in its checksummed text form
// (`text`: the store's writer of that form), so that the fuzzer reaches past the checksums.
template <typename IndexText>
void writeStore(const StoreInput& in, const std::filesystem::path& dir, const std::string& index_name, IndexText text) {
  std::string index_text = in.index;
  nlohmann::json j = nlohmann::json::parse(in.index, nullptr, false);
  if (!j.is_discarded()) {
    const auto checks = placeFiles(j, dir, in.files);
    if (!(in.mode & kRawChecks) && j.is_object()) {
      repairChecks(j, checks);
      index_text = text(j);
    }
  }
  writeBytes(dir / index_name, index_text);
}

// The input as one byte string (what the seed writer produces from a database written by Farfield's writers).
inline std::string joinStoreInput(uint8_t mode, const std::string& index, const std::vector<std::string>& files) {
  std::string out(1, char(mode));
  out += index;
  for (const std::string& f : files) {
    out += kFileSeparator;
    out += f;
  }
  return out;
}

}  // namespace farfield::fuzz
