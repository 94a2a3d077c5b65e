// Reading and committing the impostor store's index file (readIndex, writeIndex), the streets file, and the
// generations of the data files: the stale files of older generations are removed after the new index is in place.
//
// Why generations instead of writing over the old files: a bake killed half-way must leave the store it replaces
// readable, and a reader must never see an index whose files belong to another bake. New data files get names the
// old index does not use, the index is renamed over the old one last (the one atomic step), and only then are the old
// files removed.
#include "farfield/store/impostor_store.h"

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/store/generation_names.h"
#include "farfield/store/store_files.h"

namespace fs = std::filesystem;

namespace farfield::store {

namespace {

// Names the store writes: cells/eNNNNNN.* (versions 1, 2), cells/gG.*, streets.json, gG.streets.json, index.json.tmp
// and the temporaries of all of them. `relative` is relative to the store directory.
bool isStoreFileName(const std::string& relative) {
  std::string name = relative;
  if (name.size() > 4 && name.compare(name.size() - 4, 4, ".tmp") == 0) name.resize(name.size() - 4);
  if (name.rfind("cells/", 0) == 0) {
    const std::string file = name.substr(6);
    if (file.find('/') != std::string::npos) return false;
    if (generationOf(file) > 0) return true;
    return file.size() > 8 && file[0] == 'e' && file[7] == '.' &&
           std::all_of(file.begin() + 1, file.begin() + 7, [](char c) { return c >= '0' && c <= '9'; });
  }
  if (name == kStreetsFile || name == kIndexFile) return true;
  const uint64_t g = generationOf(name);
  return g > 0 && name == streetsFileName(g);
}

// Every file a version 3 index names must come with its check (a file written outside the store's writers has none).
void requireChecks(const StoreIndex& index, const std::string& file) {
  const auto need = [&](const std::string& name, const FileCheck& check, const std::string& record) {
    if (!name.empty() && !check.known)
      throw Error(file, record + ": no size and CRC-32 for " + name +
                            " (a version 3 index needs them: write the file with the store's writers)");
  };
  need(index.streets, index.streets_check, "streets");
  for (const CellEntry& c : index.cells) {
    const std::string cell = "cell " + std::to_string(c.half_edge);
    need(c.texture, c.texture_check, cell + " texture");
    for (const auto& [technique, imp] : c.impostors) need(imp.mesh, imp.mesh_check, cell + " " + technique + " mesh");
    if (!c.pipeline) continue;
    const auto layer = [&](const StoredLayer& l, const std::string& what) {
      for (size_t v = 0; v < l.views.size(); ++v) {
        const std::string at = cell + ": " + what + " view " + std::to_string(v);
        need(l.views[v].texture, l.views[v].texture_check, at + " texture");
        need(l.views[v].mesh, l.views[v].mesh_check, at + " mesh");
        need(l.views[v].ids, l.views[v].ids_check, at + " ids");
      }
    };
    for (size_t l = 0; l < c.pipeline->layers.size(); ++l)
      layer(c.pipeline->layers[l], "mmi layer " + std::to_string(l));
    layer(c.pipeline->single, "single mesh");
  }
}

// The files an index names (and the index itself), relative to the store directory.
std::set<std::string> referencedFiles(const StoreIndex& index) {
  std::set<std::string> out{kIndexFile};
  const auto add = [&](const std::string& name) {
    if (!name.empty()) out.insert(fs::path(name).lexically_normal().generic_string());
  };
  add(index.streets);
  for (const CellEntry& c : index.cells) {
    add(c.texture);
    for (const auto& [technique, imp] : c.impostors) add(imp.mesh);
    if (!c.pipeline) continue;
    std::vector<const StoredLayer*> layers{&c.pipeline->single};
    for (const StoredLayer& l : c.pipeline->layers) layers.push_back(&l);
    for (const StoredLayer* l : layers)
      for (const StoredView& v : l->views) {
        add(v.texture);
        add(v.mesh);
        add(v.ids);
      }
  }
  return out;
}

// After the new index is in place: the files with store names it does not name (older generations, temporaries of
// a killed bake) go. In name order, so that the sequence of file operations is reproducible.
void removeStaleFiles(const std::string& dir, const StoreIndex& index) {
  const std::set<std::string> keep = referencedFiles(index);
  const auto sweep = [&](const fs::path& folder, const std::string& prefix) {
    std::error_code ec;
    fs::directory_iterator it(folder, ec);
    if (ec) return;
    std::vector<fs::path> stale;
    for (const fs::directory_entry& f : it) {
      std::error_code type_ec;
      if (!f.is_regular_file(type_ec)) continue;
      const std::string relative = prefix + f.path().filename().string();
      if (!keep.count(relative) && isStoreFileName(relative)) stale.push_back(f.path());
    }
    std::sort(stale.begin(), stale.end());
    for (const fs::path& p : stale) {
      fileOperation("remove", p.string());
      std::error_code remove_ec;
      if (!fs::remove(p, remove_ec) && remove_ec)
        throw Error(p.string(), "cannot remove a file the new index does not name: " + remove_ec.message());
    }
  };
  sweep(fs::path(dir) / "cells", "cells/");
  sweep(fs::path(dir), "");
}

// An index of version 3 or later (or any carrying "checksum"): the checksum matches its content and the file is
// exactly the writer's text, so a damaged byte anywhere, whitespace included, is reported.
void checkIndexText(const nlohmann::json& j, const std::string& text, const std::string& file) {
  if (!j.is_object()) return;  // indexFromJson names it
  const auto version = j.find("version");
  const bool required = version != j.end() && version->is_number_integer() && version->get<int64_t>() >= 3;
  const auto checksum = j.find("checksum");
  if (checksum == j.end()) {
    if (required)
      throw Error(file, "top level: missing \"checksum\" (an index of version 3 or later carries the CRC-32 of its "
                        "content)");
    return;
  }
  if (!checksum->is_number_unsigned() || checksum->get<uint64_t>() > 0xffffffffu)
    throw Error(file, "top level: \"checksum\" must be a CRC-32 (0..4294967295)");
  const uint32_t stored = checksum->get<uint32_t>(), actual = indexChecksum(j);
  if (stored != actual)
    throw Error(file, "checksum mismatch: the index's content has CRC-32 " + hex32(actual) + ", \"checksum\" says " +
                          hex32(stored) + " (the index is damaged)");
  if (text != j.dump(1) + "\n")
    throw Error(file, "not the text the store writer wrote for its content (truncated, edited or damaged)");
}

}  // namespace

void writeIndex(const std::string& dir, const StoreIndex& index) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(dir, "cannot create the store directory: " + ec.message());
  const std::string file = joinPath(dir, kIndexFile);
  if (index.version >= 3) requireChecks(index, file);
  const std::string text = indexFileText(indexToJson(index));
  // The data files were renamed into place without a directory sync: their directories are synced once here, before
  // the index that names them is renamed over the old one.
  const fs::path cells = fs::path(dir) / "cells";
  if (fs::is_directory(cells, ec)) syncDirectory(cells.string());
  syncDirectory(dir);
  writeFileAtomic(file, text, true);
  removeStaleFiles(dir, index);
}

StoreIndex readIndex(const std::string& dir) {
  const std::string file = joinPath(dir, kIndexFile);
  if (!fs::is_directory(dir)) throw Error(dir, "impostor store directory not found");
  std::error_code ec;
  if (!fs::is_regular_file(file, ec))
    throw Error(file, "cannot open (is this an impostor store written by farfield bake?)");
  const std::string text = readWholeFile(file, "");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, std::string("not valid JSON: ") + e.what());
  }
  checkIndexText(j, text, file);
  StoreIndex index = indexFromJson(j, file);
  if (index.streets_check.known)
    readCheckedFile(joinPath(dir, index.streets), index.streets_check, "streets (the street graph of the cells)");
  return index;
}

uint64_t nextGeneration(const std::string& dir) {
  uint64_t top = 0;
  try {
    const nlohmann::json j = nlohmann::json::parse(readWholeFile(joinPath(dir, kIndexFile), ""));
    if (j.is_object() && j.contains("generation") && j["generation"].is_number_unsigned())
      top = j["generation"].get<uint64_t>();
  } catch (const std::exception&) {
    // No index, or a damaged one: the file names decide.
  }
  for (const fs::path& folder : {fs::path(dir), fs::path(dir) / "cells"}) {
    std::error_code ec;
    for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec))
      top = std::max(top, generationOf(it->path().filename().string()));
  }
  return top + 1;
}

std::string streetsFileName(uint64_t generation) { return generationPrefix(generation) + kStreetsFile; }

void writeStreets(const std::string& dir, StoreIndex& index, std::string_view text) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(dir, "cannot create the store directory: " + ec.message());
  index.streets = streetsFileName(index.generation);
  index.streets_check = writeFileAtomic(joinPath(dir, index.streets), text, false);
}

}  // namespace farfield::store
