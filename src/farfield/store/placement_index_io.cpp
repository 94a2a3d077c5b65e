// Reading and committing the placement database's index file (readPlacementIndex, writePlacementIndex), its
// generations, and the bytes the database takes on disk.
//
// Why the writer reads its own JSON back before writing: a database that its own reader refuses is worse than no
// database (the old one would be replaced by it), so every rule is checked once, by the reader's code, before the
// first byte of the index is written.
#include "farfield/store/placement_store.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/store/generation_names.h"
#include "farfield/store/store_files.h"

namespace fs = std::filesystem;

namespace farfield::store {

uint64_t nextPlacementGeneration(const std::string& dir) {
  uint64_t top = 0;
  try {
    const nlohmann::json j =
        nlohmann::json::parse(readCheckedFile(joinPath(dir, kPlacementIndexFile), FileCheck{}, ""));
    if (j.is_object() && j.contains("generation") && j["generation"].is_number_unsigned())
      top = j["generation"].get<uint64_t>();
  } catch (const std::exception&) {
    // No index, or a damaged one: the file names decide.
  }
  std::error_code ec;
  for (fs::directory_iterator it(fs::path(dir) / kImpostorDir, ec), end; !ec && it != end; it.increment(ec))
    top = std::max(top, generationOf(it->path().filename().string()));
  return top + 1;
}

std::string placementFileText(nlohmann::json j) {
  j["checksum"] = indexChecksum(j);
  return j.dump(1) + "\n";
}

void writePlacementIndex(const std::string& dir, PlacementIndex& index) {
  const std::string file = joinPath(dir, kPlacementIndexFile);
  index.version = kPlacementVersion;
  const nlohmann::json j = placementToJson(index);
  placementFromJson(j, file + " (refused before writing)");  // throws for an index its reader would refuse
  for (StoredPlacedImpostor& imp : index.impostors) imp.record = recordName(imp.id);
  createDirectory(dir);
  // The layer files were renamed into place without a directory sync: their directory is synced once here, before
  // the index that names them replaces the old one.
  const fs::path data = fs::path(dir) / kImpostorDir;
  std::error_code ec;
  if (fs::is_directory(data, ec)) syncFile(data.string(), true);
  syncFile(dir, true);
  writeFileAtomic(file, placementFileText(j), true);

  // The new index is in place: remove what it does not name (older generations, temporaries of killed writes), in
  // name order. A failure here leaves stale files that the next write removes; the database is already the new one.
  std::set<std::string> keep;
  for (const StoredPlacedImpostor& imp : index.impostors)
    for (const StoredImpostorLayer& l : imp.layers) {
      keep.insert(fs::path(l.texture).lexically_normal().generic_string());
      if (!l.ids.empty()) keep.insert(fs::path(l.ids).lexically_normal().generic_string());
    }
  std::vector<fs::path> stale;
  for (fs::directory_iterator it(data, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code type_ec;
    if (!it->is_regular_file(type_ec)) continue;
    const std::string name = it->path().filename().string();
    if (generationOf(name) > 0 && !keep.count(std::string(kImpostorDir) + "/" + name)) stale.push_back(it->path());
  }
  std::sort(stale.begin(), stale.end());
  for (const fs::path& p : stale) fs::remove(p, ec);
  fs::remove(file + ".tmp", ec);
}

PlacementIndex readPlacementIndex(const std::string& dir) {
  const std::string file = joinPath(dir, kPlacementIndexFile);
  if (!fs::is_directory(dir)) throw Error(dir, "placement database directory not found");
  std::error_code ec;
  if (!fs::is_regular_file(file, ec))
    throw Error(file, "cannot open (is this a placement database written by farfield place?)");
  const std::string text = readCheckedFile(file, FileCheck{}, "");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, std::string("not valid JSON: ") + e.what());
  }
  if (!j.is_object()) throw Error(file, "top level: expected an object");
  const auto checksum = j.find("checksum");
  if (checksum == j.end()) throw Error(file, "top level: missing \"checksum\" (the CRC-32 of the index's content)");
  if (!checksum->is_number_unsigned() || checksum->get<uint64_t>() > 0xffffffffu)
    throw Error(file, "top level: \"checksum\" must be a CRC-32 (0..4294967295)");
  const uint32_t stored = checksum->get<uint32_t>(), actual = indexChecksum(j);
  if (stored != actual) {
    char buf[96];
    std::snprintf(buf, sizeof(buf), "checksum mismatch: the content has CRC-32 %08x, \"checksum\" says %08x", actual,
                  stored);
    throw Error(file, std::string(buf) + " (the index is damaged)");
  }
  if (text != j.dump(1) + "\n")
    throw Error(file, "not the text the placement writer wrote for its content (truncated, edited or damaged)");
  return placementFromJson(j, file);
}

uint64_t placementBytes(const std::string& dir, const PlacementIndex& index) {
  const auto size = [&](const std::string& relative) {
    const std::string path = joinPath(dir, relative);
    std::error_code ec;
    const uintmax_t bytes = fs::file_size(path, ec);
    if (ec) throw Error(path, "cannot read its size: " + ec.message());
    return uint64_t(bytes);
  };
  uint64_t total = size(kPlacementIndexFile);
  for (const StoredPlacedImpostor& imp : index.impostors)
    for (const StoredImpostorLayer& l : imp.layers) {
      total += size(l.texture);
      if (!l.ids.empty()) total += size(l.ids);
    }
  return total;
}

}  // namespace farfield::store
