// Joining the shards of a sharded bake into one impostor database.
#include "farfield/bake/merge.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>

#include "farfield/bake/pipeline.h"
#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/extract/pipeline_options.h"
#include "farfield/store/bake_journal.h"
#include "farfield/store/generation_names.h"
#include "farfield/store/impostor_store.h"
#include "farfield/store/store_compare.h"

namespace fs = std::filesystem;

namespace farfield::bake {

namespace {

// What every shard of one bake shares: the index without cells, storage, generation, file checks of the streets
// (compared by content below) and the shard's own part.
nlohmann::json sharedHeader(const store::StoreIndex& index) {
  nlohmann::json j = store::indexToJson(index);
  for (const char* key : {"cells", "storage", "generation", "checksum", "streets", "streets_crc32", "streets_bytes"})
    j.erase(key);
  j["shard"].erase("index");
  j["shard"].erase("cells");
  return j;
}

store::StoreIndex readShard(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_regular_file(fs::path(dir) / store::kIndexFile, ec) &&
      fs::is_regular_file(fs::path(dir) / store::kJournalFile, ec))
    throw Error(dir, "an unfinished shard (a bake journal and no index): run its bake again with --resume");
  store::StoreIndex index = store::readIndex(dir);
  if (!index.shard) throw Error(dir, "not a shard (its bake had no --shard K/N): a whole database needs no merge");
  return index;
}

// Moves a checked data file of a shard to its name in the merged database: a hard link where possible, else a copy.
bool placeFile(const std::string& from, const std::string& to, const std::string& bytes) {
  const std::string tmp = to + ".tmp";
  std::error_code ec;
  fs::remove(tmp, ec);
  fs::create_hard_link(from, tmp, ec);
  if (!ec) {
    fs::rename(tmp, to, ec);
    if (ec) throw Error(to, "cannot rename " + tmp + " over it: " + ec.message());
    return true;
  }
  store::writeFileAtomic(to, bytes, false);
  return false;
}

}  // namespace

MergeReport mergeShards(const std::vector<std::string>& shard_dirs, const std::string& out_dir) {
  Stopwatch wall;
  if (shard_dirs.empty()) throw Error("merge", "no shard databases given");
  std::vector<store::StoreIndex> shards;
  for (const std::string& d : shard_dirs) shards.push_back(readShard(d));
  const store::StoreIndex& first = shards.front();
  const uint32_t count = first.shard->count;
  const nlohmann::json header = sharedHeader(first);
  std::map<uint32_t, size_t> by_part;
  for (size_t k = 0; k < shards.size(); ++k) {
    const store::StoreIndex& s = shards[k];
    const std::string& dir = shard_dirs[k];
    if (s.shard->count != count)
      throw Error(dir, "a shard of " + std::to_string(s.shard->count) + " (" + shard_dirs[0] + " is one of " +
                           std::to_string(count) + ")");
    if (s.shard->scene_crc32 != first.shard->scene_crc32)
      throw Error(dir, "baked from another scene than " + shard_dirs[0] + " (scene digests differ)");
    if (s.streets_check.crc32 != first.streets_check.crc32 || s.streets_check.bytes != first.streets_check.bytes)
      throw Error(dir, "baked on another street graph than " + shard_dirs[0]);
    const std::string difference = store::firstDifference(header, sharedHeader(s));
    if (!difference.empty())
      throw Error(dir, "not a shard of the same bake as " + shard_dirs[0] + " (" + difference + ")");
    const auto [it, fresh] = by_part.emplace(s.shard->index, k);
    if (!fresh)
      throw Error(dir, "shard " + std::to_string(s.shard->index) + "/" + std::to_string(count) +
                           " is given twice (also " + shard_dirs[it->second] + ")");
    std::vector<uint32_t> have;
    for (const store::CellEntry& e : s.cells) have.push_back(e.half_edge);
    for (uint32_t c : s.shard->cells)
      if (!std::binary_search(have.begin(), have.end(), c))
        throw Error(dir, "cell " + std::to_string(c) + " of its part is missing (the shard's bake did not bake it)");
  }
  for (uint32_t p = 0; p < count; ++p)
    if (!by_part.count(p))
      throw Error("merge", "shard " + std::to_string(p) + "/" + std::to_string(count) +
                               " is missing: give the databases of all " + std::to_string(count) + " shards");
  // Every cell of the view space exactly once.
  std::map<uint32_t, size_t> owner;
  for (size_t k = 0; k < shards.size(); ++k)
    for (const store::CellEntry& e : shards[k].cells) {
      const auto [it, fresh] = owner.emplace(e.half_edge, k);
      if (!fresh)
        throw Error(shard_dirs[k], "cell " + std::to_string(e.half_edge) + " is also in " + shard_dirs[it->second] +
                                       " (a view region must be baked once)");
    }
  for (uint32_t c : first.shard->view_space)
    if (!owner.count(c)) throw Error("merge", "cell " + std::to_string(c) + " of the view space is in no shard");
  if (owner.size() != first.shard->view_space.size())
    throw Error("merge", "the shards hold cells outside their view space");

  // The whole database: a new generation in out_dir, each shard's files under their new names.
  store::StoreIndex merged = first;
  merged.shard.reset();
  merged.generation = store::nextGeneration(out_dir);
  merged.cells.clear();
  {
    std::error_code ec;
    fs::create_directories(fs::path(out_dir) / "cells", ec);
    if (ec) throw Error(out_dir, "cannot create the database directory: " + ec.message());
  }
  store::writeStreets(out_dir, merged,
                      store::readCheckedFile((fs::path(shard_dirs[0]) / first.streets).string(), first.streets_check,
                                             "streets"));
  MergeReport report;
  report.shards = shards.size();
  const std::string prefix = store::generationPrefix(merged.generation);
  const auto move_file = [&](const std::string& dir, std::string& name, store::FileCheck& check,
                             const std::string& record) {
    if (name.empty()) return;
    const std::string from = (fs::path(dir) / name).string();
    const std::string bytes = store::readCheckedFile(from, check, record);
    const fs::path relative(name);
    std::string file = relative.filename().string();
    const uint64_t g = store::generationOf(file);
    file = prefix + file.substr(store::generationPrefix(g).size());
    name = (relative.parent_path() / file).generic_string();
    report.linked += placeFile(from, (fs::path(out_dir) / name).string(), bytes) ? 1 : 0;
    report.bytes += bytes.size();
    ++report.files;
  };
  for (const auto& [cell, k] : owner) {
    store::CellEntry e = *shards[k].find(cell);
    if (!e.pipeline) throw Error(shard_dirs[k], "cell " + std::to_string(cell) + " has no pipeline record");
    const std::string at = "cell " + std::to_string(cell);
    std::vector<store::StoredLayer*> layers{&e.pipeline->single};
    for (store::StoredLayer& l : e.pipeline->layers) layers.push_back(&l);
    for (store::StoredLayer* l : layers)
      for (store::StoredView& v : l->views) {
        move_file(shard_dirs[k], v.texture, v.texture_check, at + " texture");
        move_file(shard_dirs[k], v.mesh, v.mesh_check, at + " mesh");
        move_file(shard_dirs[k], v.ids, v.ids_check, at + " ids");
      }
    merged.cells.push_back(std::move(e));
  }
  // The storage report of the whole, as a single-process bake writes it.
  const extract::PipelineOptions options =
      extract::pipelineOptionsFromJson(merged.options.at("pipeline"), shard_dirs[0], merged.version);
  size_t city_cells = 0;
  for (const store::StoreIndex& s : shards) city_cells = std::max(city_cells, s.storage.value("city_cells", size_t(0)));
  merged.storage = storageReport(merged, out_dir, options, city_cells);
  store::writeIndex(out_dir, merged);
  report.cells = merged.cells.size();
  report.wall_s = wall.seconds();
  return report;
}

}  // namespace farfield::bake
