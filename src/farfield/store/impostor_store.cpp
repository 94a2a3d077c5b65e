// The simple impostor store: JSON index, binary meshes, PNG textures (format in impostor_store.h).
//
// Why a raw binary mesh instead of glTF: the runtime loads an impostor inside a frame when the viewer enters a new
// cell, so the load must be a few reads and a validation pass, and the format must be trivial to check for
// truncation (the size is fixed by the counts in the header). glTF export of impostors is a later issue's.
//
// Why generations instead of writing over the old files: a bake killed half-way must leave the store it replaces
// readable, and a reader must never see an index whose files belong to another bake. New data files get names the
// old index does not use, the index is renamed over the old one last (the one atomic step), and only then are the old
// files removed. Why CRC-32 per file and not per store: the runtime loads one view at a time inside a frame, so each
// file must be checkable alone, before it is parsed.
#include "farfield/store/impostor_store.h"

#include "farfield/store/generation_names.h"

#include "farfield/store/json_fields.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <filesystem>
#include <set>

#include "farfield/core/error.h"
#include "farfield/image/png_io.h"

namespace fs = std::filesystem;

namespace farfield::store {

static_assert(std::endian::native == std::endian::little, "the mesh format is little-endian");

namespace {

constexpr char kMeshMagic[8] = {'F', 'F', 'I', 'M', 'E', 'S', 'H', '\0'};
constexpr size_t kMeshHeaderBytes = 24;

std::string joinPath(const std::string& dir, const std::string& relative) {
  return (fs::path(dir) / relative).string();
}

// ---- Integrity: checks, atomic writes -------------------------------------------------------------------------

std::function<void(const char*, const std::string&)>& fileHook() {
  static std::function<void(const char*, const std::string&)> hook;
  return hook;
}

void fileOperation(const char* operation, const std::string& path) {
  if (fileHook()) fileHook()(operation, path);
}

[[noreturn]] void systemError(const std::string& path, const std::string& what, int error) {
  throw Error(path, what + ": " + std::strerror(error));
}

std::string parentDirectory(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? "." : parent.string();
}

void syncFile(const std::string& path, bool directory) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | (directory ? O_DIRECTORY : 0));
  if (fd < 0) systemError(path, "cannot open to sync", errno);
  if (::fsync(fd) != 0) {
    const int error = errno;
    ::close(fd);
    systemError(path, "fsync failed", error);
  }
  ::close(fd);
}

void syncDirectory(const std::string& dir) {
  fileOperation("sync-dir", dir);
  syncFile(dir, true);
}

std::string tempName(const std::string& path) { return path + ".tmp"; }

// fsync a finished temporary file and rename it over its target.
void commitTemp(const std::string& tmp, const std::string& path, bool sync_directory) {
  fileOperation("fsync", tmp);
  syncFile(tmp, false);
  fileOperation("rename", path);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) systemError(path, "cannot rename " + tmp + " over it", errno);
  if (sync_directory) syncDirectory(parentDirectory(path));
}

std::string readWholeFile(const std::string& path, const std::string& record) {
  const std::string prefix = record.empty() ? "" : record + ": ";
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) systemError(path, prefix + "cannot open", errno);
  std::string bytes;
  struct stat st {};
  if (::fstat(fd, &st) == 0 && st.st_size > 0) bytes.reserve(size_t(st.st_size));
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof(buffer));
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      const int error = errno;
      ::close(fd);
      systemError(path, prefix + "read failed", error);
    }
    bytes.append(buffer, size_t(n));
  }
  ::close(fd);
  return bytes;
}

std::string hex32(uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof(buf), "%08x", v);
  return buf;
}

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

nlohmann::json cameraJson(const Camera& c) {
  return {{"eye", vec3Json(c.eye)}, {"at", vec3Json(c.at)},      {"up", vec3Json(c.up)},
          {"fov_y", c.fov_y},       {"width", c.width},          {"height", c.height},
          {"near", c.near_plane},   {"far", c.far_plane}};
}


nlohmann::json viewJson(const StoredView& v, bool with_checks) {
  nlohmann::json j = {{"camera", cameraJson(v.camera)}, {"texture", v.texture},   {"mesh", v.mesh},
                      {"ids", v.ids},                   {"triangles", v.triangles}, {"vertices", v.vertices},
                      {"data_pixels", v.data_pixels},   {"render_ms", v.render_ms}, {"build_ms", v.build_ms},
                      {"station", v.station}};
  putCheck(j, "texture", v.texture, v.texture_check, with_checks);
  putCheck(j, "mesh", v.mesh, v.mesh_check, with_checks);
  putCheck(j, "ids", v.ids, v.ids_check, with_checks);
  return j;
}

nlohmann::json layerJson(const StoredLayer& l, bool with_checks) {
  nlohmann::json views = nlohmann::json::array();
  for (const StoredView& v : l.views) views.push_back(viewJson(v, with_checks));
  nlohmann::json j = {{"objects", l.objects}, {"views", std::move(views)}};
  if (!l.validity.empty()) {
    nlohmann::json regions = nlohmann::json::array();
    for (const impostor::ValidityRegion& v : l.validity)
      regions.push_back({{"origin", vec3Json(v.origin)}, {"end", vec3Json(v.end)}, {"half_width", v.half_width},
                         {"below", v.below},             {"above", v.above},     {"back", v.back},
                         {"step", v.step},               {"laterals", v.laterals},
                         {"envelope", v.envelope}});
    j["validity"] = std::move(regions);
  }
  return j;
}

// Version 4: the single mesh is its own record; versions 2 and 3 kept it inside "mmi" (see the header).
nlohmann::json pipelineJson(const CellPipeline& p, int version) {
  const bool with_checks = version >= 3;
  nlohmann::json j = nlohmann::json::object();
  if (p.has_pvs) j["pvs"] = {{"ids", p.pvs}, {"samples", p.pvs_samples}, {"ms", p.pvs_ms}};
  if (p.has_split) j["split"] = {{"near", p.near}, {"far", p.far}};
  if (p.has_single && version >= 4) j["single"] = layerJson(p.single, with_checks);
  if (p.has_mmi) {
    nlohmann::json layers = nlohmann::json::array();
    for (const StoredLayer& l : p.layers) layers.push_back(layerJson(l, with_checks));
    j["mmi"] = {{"threshold_rad", p.threshold_rad}, {"event_edges", p.event_edges},
                {"max_weight_rad", p.max_weight_rad}, {"weights_ms", p.weights_ms},
                {"layers", std::move(layers)}};
    if (version <= 3) j["mmi"]["single"] = layerJson(p.single, with_checks);
  }
  return j;
}

impostor::ValidityRegion readValidity(const JsonReader& r, const nlohmann::json& m, const std::string& at) {
  impostor::ValidityRegion v;
  v.origin = r.vec3(m, "origin", at);
  v.end = r.vec3(m, "end", at);
  auto non_negative = [&](const char* key) {
    const double x = r.number(m, key, at);
    if (x < 0.0) r.fail(at, std::string("\"") + key + "\" must be >= 0");
    return float(x);
  };
  v.half_width = non_negative("half_width");
  v.below = non_negative("below");
  v.above = non_negative("above");
  v.back = non_negative("back");
  v.step = non_negative("step");
  if (!(v.step > 0.0f)) r.fail(at, "\"step\" must be > 0");
  const uint64_t laterals = r.count(m, "laterals", at);
  if (laterals < 1 || laterals % 2 == 0 || laterals > 1001) r.fail(at, "\"laterals\" must be an odd count 1..1001");
  v.laterals = int(laterals);
  const nlohmann::json& envelope = r.member(m, "envelope", at);
  if (!envelope.is_array()) r.fail(at, "\"envelope\" must be an array of angles");
  if (envelope.size() % laterals != 0) r.fail(at, "\"envelope\" must hold \"laterals\" rows of equal length");
  const size_t row = envelope.size() / laterals;
  for (size_t i = 0; i < envelope.size(); ++i) {
    const nlohmann::json& e = envelope[i];
    if (!e.is_number() || !(e.get<double>() >= 0.0) || !(e.get<double>() <= kPi + 1e-6))
      r.fail(at, "\"envelope\" must hold angles in [0, pi]");
    if (i % row != 0 && e.get<float>() < v.envelope.back()) r.fail(at, "\"envelope\" rows must not decrease");
    v.envelope.push_back(e.get<float>());
  }
  return v;
}

StoredLayer readLayer(const JsonReader& r, const nlohmann::json& j, const std::string& where, size_t scene_objects,
                      bool require_validity, bool require_checks, const std::string& record) {
  StoredLayer layer;
  layer.objects = readIds(r, j, "objects", where, scene_objects);
  const nlohmann::json& views = r.member(j, "views", where);
  if (!views.is_array()) r.fail(where, "\"views\" must be an array");
  for (size_t v = 0; v < views.size(); ++v) {
    const std::string at = where + ": views[" + std::to_string(v) + "]";
    StoredView view;
    view.camera = r.camera(views[v], at);
    view.texture = r.relativeFile(views[v], "texture", at, true);
    view.mesh = r.relativeFile(views[v], "mesh", at, false);
    if (views[v].contains("ids")) view.ids = r.relativeFile(views[v], "ids", at, true);
    view.texture_check = readCheck(r, views[v], "texture", at, view.texture, require_checks);
    view.mesh_check = readCheck(r, views[v], "mesh", at, view.mesh, require_checks);
    view.ids_check = readCheck(r, views[v], "ids", at, view.ids, require_checks);
    view.record = record + " view " + std::to_string(v);
    view.triangles = size_t(r.count(views[v], "triangles", at));
    view.vertices = size_t(r.count(views[v], "vertices", at));
    view.data_pixels = size_t(r.count(views[v], "data_pixels", at));
    view.render_ms = r.number(views[v], "render_ms", at);
    view.build_ms = r.number(views[v], "build_ms", at);
    if (require_validity || views[v].contains("station")) {
      const uint64_t station = r.count(views[v], "station", at);
      if (station > 1000) r.fail(at, "\"station\" must be 0..1000");
      view.station = uint32_t(station);
    }
    if (view.triangles > 0 && view.texture.empty()) r.fail(at, "has triangles but no texture");
    layer.views.push_back(std::move(view));
  }
  uint32_t stations = 0;
  for (const StoredView& view : layer.views) stations = std::max(stations, view.station + 1);
  if (j.contains("validity") || (require_validity && !layer.views.empty())) {
    const nlohmann::json& list = r.member(j, "validity", where);
    if (!list.is_array() || list.size() != stations)
      r.fail(where, "\"validity\" must be an array with one region per station (" + std::to_string(stations) + ")");
    for (size_t k = 0; k < list.size(); ++k)
      layer.validity.push_back(readValidity(r, list[k], where + ": validity[" + std::to_string(k) + "]"));
  }
  return layer;
}

// legacy_single (versions 2 and 3): the mmi stage built the single mesh too (options.pipeline.single_mesh), held in
// "mmi.single": it becomes the single stage's record.
CellPipeline readPipeline(const JsonReader& r, const nlohmann::json& j, const std::string& where,
                          size_t scene_objects, int version, bool legacy_single, uint32_t half_edge) {
  const bool require_validity = version >= 3, require_checks = version >= 3;
  const std::string cell = "cell " + std::to_string(half_edge) + ": ";
  if (!j.is_object()) r.fail(where, "expected an object");
  CellPipeline p;
  if (j.contains("pvs")) {
    const std::string at = where + ".pvs";
    p.has_pvs = true;
    p.pvs = readIds(r, j["pvs"], "ids", at, scene_objects);
    p.pvs_samples = size_t(r.count(j["pvs"], "samples", at));
    p.pvs_ms = r.number(j["pvs"], "ms", at);
  }
  if (j.contains("split")) {
    const std::string at = where + ".split";
    p.has_split = true;
    p.near = readIds(r, j["split"], "near", at, scene_objects);
    p.far = readIds(r, j["split"], "far", at, scene_objects);
  }
  if (j.contains("mmi")) {
    const std::string at = where + ".mmi";
    const nlohmann::json& m = j["mmi"];
    p.has_mmi = true;
    p.threshold_rad = r.number(m, "threshold_rad", at);
    p.event_edges = size_t(r.count(m, "event_edges", at));
    p.max_weight_rad = r.number(m, "max_weight_rad", at);
    p.weights_ms = r.number(m, "weights_ms", at);
    const nlohmann::json& layers = r.member(m, "layers", at);
    if (!layers.is_array()) r.fail(at, "\"layers\" must be an array");
    for (size_t l = 0; l < layers.size(); ++l)
      p.layers.push_back(readLayer(r, layers[l], at + ".layers[" + std::to_string(l) + "]", scene_objects,
                                   require_validity, require_checks, cell + "mmi layer " + std::to_string(l)));
    if (version <= 3) {
      p.single = readLayer(r, r.member(m, "single", at), at + ".single", scene_objects, require_validity,
                           require_checks, cell + "single mesh");
      p.has_single = legacy_single;
      if (!legacy_single) p.single = {};
    } else if (m.contains("single")) {
      r.fail(at, "a version 4 mmi record holds no \"single\" (the single mesh is the single stage's record)");
    }
  }
  if (version >= 4 && j.contains("single")) {
    p.has_single = true;
    p.single = readLayer(r, j["single"], where + ".single", scene_objects, require_validity, require_checks,
                         cell + "single mesh");
  } else if (version <= 3 && j.contains("single")) {
    r.fail(where + ".single", "a version " + std::to_string(version) + " record has no single stage");
  }
  return p;
}

// Cell ids, ascending without repeats.
std::vector<uint32_t> readCellIds(const JsonReader& r, const nlohmann::json& j, const char* key,
                                  const std::string& where) {
  const nlohmann::json& list = r.member(j, key, where);
  if (!list.is_array()) r.fail(where, std::string("\"") + key + "\" must be an array of cell ids");
  std::vector<uint32_t> out;
  for (const nlohmann::json& id : list) {
    if (!id.is_number_unsigned() || id.get<uint64_t>() >= 0xffffffffu)
      r.fail(where, std::string("\"") + key + "\" holds something that is not a cell id");
    if (!out.empty() && id.get<uint32_t>() <= out.back())
      r.fail(where, std::string("\"") + key + "\" must be ascending without repeats");
    out.push_back(id.get<uint32_t>());
  }
  return out;
}

ShardRecord readShard(const JsonReader& r, const nlohmann::json& j, const std::vector<CellEntry>& cells) {
  const std::string where = "\"shard\"";
  if (!j.is_object()) r.fail(where, "must be an object");
  r.onlyKeys(j, {"index", "count", "scene_crc32", "view_space", "cells"}, where);
  ShardRecord s;
  s.count = uint32_t(r.integer(j, "count", where, 1, 0xffffffffLL));
  s.index = uint32_t(r.integer(j, "index", where, 0, int64_t(s.count) - 1));
  s.scene_crc32 = uint32_t(r.integer(j, "scene_crc32", where, 0, 0xffffffffLL));
  s.view_space = readCellIds(r, j, "view_space", where);
  s.cells = readCellIds(r, j, "cells", where);
  for (uint32_t c : s.cells)
    if (!std::binary_search(s.view_space.begin(), s.view_space.end(), c))
      r.fail(where, "cell " + std::to_string(c) + " of the shard's part is not in its view space");
  for (const CellEntry& e : cells)
    if (!std::binary_search(s.cells.begin(), s.cells.end(), e.half_edge))
      r.fail("cells", "cell " + std::to_string(e.half_edge) + " is not in this shard's part (\"shard\".cells)");
  return s;
}

}  // namespace

const CellEntry* StoreIndex::find(uint32_t half_edge) const {
  const auto it = std::lower_bound(cells.begin(), cells.end(), half_edge,
                                   [](const CellEntry& c, uint32_t e) { return c.half_edge < e; });
  return it != cells.end() && it->half_edge == half_edge ? &*it : nullptr;
}

bool StoreIndex::hasTechnique(const std::string& technique) const {
  return std::find(techniques.begin(), techniques.end(), technique) != techniques.end();
}

nlohmann::json indexToJson(const StoreIndex& index) {
  nlohmann::json j;
  const bool with_checks = index.version >= 3;
  j["format"] = kIndexFormat;
  j["version"] = index.version;
  if (with_checks) j["generation"] = index.generation;
  j["techniques"] = index.techniques;
  j["streets"] = index.streets;
  putCheck(j, "streets", index.streets, index.streets_check, with_checks);
  j["scene"] = index.scene;
  j["scene_objects"] = index.scene_objects;
  j["local_model"] = index.local_model;
  j["cell_lookup"] = index.cell_lookup;
  j["options"] = index.options;
  if (!index.pipeline.empty()) {
    // Versions 2 and 3 had no single stage: the mmi stage built the single mesh (options.pipeline.single_mesh).
    const auto stages = [&](std::vector<std::string> list) {
      if (index.version <= 3) std::erase(list, std::string("single"));
      return list;
    };
    j["pipeline"] = stages(index.pipeline);
    j["online"] = stages(index.online);
    j["storage"] = index.storage;
  }
  nlohmann::json cells = nlohmann::json::array();
  for (const CellEntry& c : index.cells) {
    nlohmann::json cell;
    cell["half_edge"] = c.half_edge;
    cell["camera"] = cameraJson(c.camera);
    cell["local_objects"] = c.local_objects;
    cell["distant_objects"] = c.distant_objects;
    cell["data_pixels"] = c.data_pixels;
    cell["render_ms"] = c.render_ms;
    cell["texture"] = c.texture;
    putCheck(cell, "texture", c.texture, c.texture_check, with_checks);
    nlohmann::json imps = nlohmann::json::object();
    for (const auto& [technique, imp] : c.impostors) {
      imps[technique] = {{"mesh", imp.mesh},
                         {"triangles", imp.triangles},
                         {"vertices", imp.vertices},
                         {"build_ms", imp.build_ms}};
      putCheck(imps[technique], "mesh", imp.mesh, imp.mesh_check, with_checks);
    }
    cell["impostors"] = std::move(imps);
    if (c.pipeline) cell["pipeline"] = pipelineJson(*c.pipeline, index.version);
    cells.push_back(std::move(cell));
  }
  j["cells"] = std::move(cells);
  if (index.shard)
    j["shard"] = {{"index", index.shard->index},           {"count", index.shard->count},
                  {"scene_crc32", index.shard->scene_crc32}, {"view_space", index.shard->view_space},
                  {"cells", index.shard->cells}};
  return j;
}

StoreIndex indexFromJson(const nlohmann::json& j, const std::string& source) {
  const JsonReader r(source);
  StoreIndex index;
  if (!j.is_object()) r.fail("top level", "expected an object");
  if (r.text(j, "format", "top level") != kIndexFormat)
    r.fail("\"format\"", std::string("expected \"") + kIndexFormat + "\"");
  const uint64_t version = r.count(j, "version", "top level");
  if (version < 1 || version > uint64_t(kIndexVersion))
    r.fail("\"version\"", "unsupported version " + std::to_string(version) + " (this build reads versions 1.." +
                              std::to_string(kIndexVersion) + ")");
  index.version = int(version);
  const bool require_checks = index.version >= 3;
  if (require_checks) index.generation = r.count(j, "generation", "top level");
  for (const char* key : {"pipeline", "online"}) {
    if (!j.contains(key)) continue;
    const nlohmann::json& list = j[key];
    if (!list.is_array()) r.fail(std::string("\"") + key + "\"", "must be an array of stage names");
    for (const nlohmann::json& s : list) {
      if (!s.is_string() || s.get<std::string>().empty())
        r.fail(std::string("\"") + key + "\"", "stage names must be non-empty strings");
      (std::string(key) == "pipeline" ? index.pipeline : index.online).push_back(s.get<std::string>());
    }
  }
  for (const std::string& s : index.online)
    if (std::find(index.pipeline.begin(), index.pipeline.end(), s) == index.pipeline.end())
      r.fail("\"online\"", "stage \"" + s + "\" is not in the pipeline");
  if (j.contains("storage")) index.storage = j["storage"];
  const nlohmann::json& techniques = r.member(j, "techniques", "top level");
  if (!techniques.is_array() || (techniques.empty() && index.pipeline.empty()))
    r.fail("\"techniques\"", "must be a non-empty array of names (or empty in a pipeline store)");
  for (const nlohmann::json& t : techniques) {
    if (!t.is_string() || t.get<std::string>().empty()) r.fail("\"techniques\"", "names must be non-empty strings");
    index.techniques.push_back(t.get<std::string>());
  }
  index.streets = r.relativeFile(j, "streets", "top level", false);
  index.streets_check = readCheck(r, j, "streets", "top level", index.streets, require_checks);
  if (j.contains("scene") && j["scene"].is_string()) index.scene = j["scene"].get<std::string>();
  index.scene_objects = size_t(r.count(j, "scene_objects", "top level"));
  // Object ids are 32-bit: a larger count would let an id wrap when it is stored.
  if (index.scene_objects > 0xffffffffu) r.fail("\"scene_objects\"", "must be at most 4294967295");
  index.local_model = r.text(j, "local_model", "top level");
  if (j.contains("cell_lookup")) index.cell_lookup = r.text(j, "cell_lookup", "top level");
  if (j.contains("options")) index.options = j["options"];
  // Versions 2 and 3: the single mesh was built by the mmi stage when options.pipeline.single_mesh; it is the single
  // stage now (see the header).
  const auto has_stage = [](const std::vector<std::string>& list, const char* stage) {
    return std::find(list.begin(), list.end(), stage) != list.end();
  };
  bool legacy_single = false;
  if (index.version <= 3 && has_stage(index.pipeline, "single"))
    r.fail("\"pipeline\"", "stage \"single\" is not a stage of version " + std::to_string(index.version) +
                               " stores (it came with version 4)");
  if (index.version <= 3 && has_stage(index.pipeline, "mmi")) {
    const nlohmann::json& o = index.options;
    const nlohmann::json* single_mesh = nullptr;
    if (o.is_object() && o.contains("pipeline") && o["pipeline"].is_object() && o["pipeline"].contains("single_mesh"))
      single_mesh = &o["pipeline"]["single_mesh"];
    if (!single_mesh || !single_mesh->is_boolean())
      r.fail("\"options\".pipeline", "a version " + std::to_string(index.version) +
                                         " store with an mmi stage needs \"single_mesh\" (true or false): whether "
                                         "that stage built the single mesh");
    legacy_single = single_mesh->get<bool>();
    if (legacy_single)
      for (std::vector<std::string>* list : {&index.pipeline, &index.online})
        if (has_stage(*list, "mmi")) list->insert(std::find(list->begin(), list->end(), "mmi"), "single");
  }
  const nlohmann::json& cells = r.member(j, "cells", "top level");
  if (!cells.is_array()) r.fail("\"cells\"", "must be an array");
  for (size_t k = 0; k < cells.size(); ++k) {
    const nlohmann::json& c = cells[k];
    const std::string where = "cells[" + std::to_string(k) + "]";
    CellEntry e;
    const uint64_t he = r.count(c, "half_edge", where);
    if (he >= 0xffffffffu) r.fail(where, "half_edge out of range");
    e.half_edge = uint32_t(he);
    if (!index.cells.empty() && e.half_edge <= index.cells.back().half_edge)
      r.fail(where, "cells must be sorted by half_edge without repeats");
    e.camera = r.camera(c, where);
    const nlohmann::json& local = r.member(c, "local_objects", where);
    if (!local.is_array()) r.fail(where, "\"local_objects\" must be an array of object ids");
    for (const nlohmann::json& id : local) {
      if (!id.is_number_unsigned() || id.get<uint64_t>() == 0 || id.get<uint64_t>() > index.scene_objects)
        r.fail(where, "\"local_objects\" holds an id outside 1.." + std::to_string(index.scene_objects));
      e.local_objects.push_back(id.get<uint32_t>());
    }
    if (!std::is_sorted(e.local_objects.begin(), e.local_objects.end()))
      r.fail(where, "\"local_objects\" must be ascending");
    e.distant_objects = size_t(r.count(c, "distant_objects", where));
    e.data_pixels = size_t(r.count(c, "data_pixels", where));
    e.render_ms = r.number(c, "render_ms", where);
    e.texture = r.relativeFile(c, "texture", where, true);
    e.texture_check = readCheck(r, c, "texture", where, e.texture, require_checks);
    const nlohmann::json& imps = r.member(c, "impostors", where);
    if (!imps.is_object()) r.fail(where, "\"impostors\" must be an object (technique -> impostor)");
    for (const std::string& technique : index.techniques) {
      const std::string at = where + ": impostors." + technique;
      if (!imps.contains(technique)) r.fail(where, "no impostor for technique \"" + technique + "\"");
      const nlohmann::json& imp = imps[technique];
      StoredImpostor s;
      s.mesh = r.relativeFile(imp, "mesh", at, false);
      s.mesh_check = readCheck(r, imp, "mesh", at, s.mesh, require_checks);
      s.triangles = size_t(r.count(imp, "triangles", at));
      s.vertices = size_t(r.count(imp, "vertices", at));
      s.build_ms = r.number(imp, "build_ms", at);
      if (s.triangles > 0 && e.texture.empty()) r.fail(at, "has triangles but the cell has no texture");
      e.impostors[technique] = std::move(s);
    }
    if (c.contains("pipeline"))
      e.pipeline = readPipeline(r, c["pipeline"], where + ": pipeline", index.scene_objects, index.version,
                                legacy_single, e.half_edge);
    index.cells.push_back(std::move(e));
  }
  if (j.contains("shard")) index.shard = readShard(r, j["shard"], index.cells);
  return index;
}

namespace {

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

// An index of version 3 or later (or any carrying "checksum"): the checksum matches its content and the file is exactly the
// writer's text, so a damaged byte anywhere, whitespace included, is reported.
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

std::string meshBytes(const impostor::DepthMeshImpostor& impostor, const std::string& file) {
  const scene::Mesh& m = impostor.mesh;
  const uint32_t v = uint32_t(m.positions.size()), i = uint32_t(m.indices.size());
  const uint32_t t = uint32_t(impostor.triangle_ids.size());
  if (m.positions.size() >= 0xffffffffu || m.indices.size() >= 0xffffffffu)
    throw Error(file, "mesh too large for the format");
  if (i % 3 != 0) throw Error(file, "index count is not a multiple of 3");
  if (t != 0 && t != i / 3) throw Error(file, "triangle id count must be 0 or one per triangle");
  if (!m.uvs.empty() && m.uvs.size() != m.positions.size()) throw Error(file, "uv count differs from vertex count");
  std::string out;
  out.reserve(kMeshHeaderBytes + 20 * size_t(v) + 4 * size_t(i) + 4 * size_t(t));
  const auto put = [&](const void* data, size_t bytes) { out.append(static_cast<const char*>(data), bytes); };
  const uint32_t header[4] = {kMeshVersion, v, i, t};
  put(kMeshMagic, sizeof(kMeshMagic));
  put(header, sizeof(header));
  put(m.positions.data(), sizeof(Vec3) * v);
  if (m.uvs.empty())
    out.append(sizeof(Vec2) * v, '\0');
  else
    put(m.uvs.data(), sizeof(Vec2) * v);
  put(m.indices.data(), sizeof(uint32_t) * i);
  put(impostor.triangle_ids.data(), sizeof(uint32_t) * t);
  return out;
}

impostor::DepthMeshImpostor meshFromBytes(const std::string& bytes, const std::string& file,
                                          const std::string& record) {
  static_assert(sizeof(Vec3) == 12 && sizeof(Vec2) == 8);
  const std::string at = record.empty() ? "" : record + ": ";
  const uint64_t size = bytes.size();
  if (size < kMeshHeaderBytes)
    throw Error(file, at + "truncated: " + std::to_string(size) + " bytes, shorter than the 24-byte header");
  char magic[8];
  uint32_t header[4];
  std::memcpy(magic, bytes.data(), sizeof(magic));
  std::memcpy(header, bytes.data() + sizeof(magic), sizeof(header));
  if (std::memcmp(magic, kMeshMagic, sizeof(magic)) != 0)
    throw Error(file, at + "bad magic: not a Farfield impostor mesh (expected \"FFIMESH\")");
  if (header[0] != kMeshVersion)
    throw Error(file, at + "unsupported mesh version " + std::to_string(header[0]) + " (this build reads version " +
                          std::to_string(kMeshVersion) + ")");
  const uint64_t v = header[1], i = header[2], t = header[3];
  if (i % 3 != 0) throw Error(file, at + "index count " + std::to_string(i) + " is not a multiple of 3");
  if (t != 0 && t != i / 3)
    throw Error(file, at + "triangle id count " + std::to_string(t) + " must be 0 or " + std::to_string(i / 3));
  const uint64_t expected = kMeshHeaderBytes + 20 * v + 4 * i + 4 * t;
  if (size < expected)
    throw Error(file, at + "truncated: " + std::to_string(size) + " bytes, the header's counts need " +
                          std::to_string(expected));
  if (size > expected)
    throw Error(file, at + "trailing data: " + std::to_string(size) + " bytes, the header's counts need " +
                          std::to_string(expected));
  impostor::DepthMeshImpostor out;
  scene::Mesh& m = out.mesh;
  m.positions.resize(v);
  m.uvs.resize(v);
  m.indices.resize(i);
  out.triangle_ids.resize(t);
  const char* p = bytes.data() + kMeshHeaderBytes;
  const auto take = [&](void* dst, size_t n) {
    if (n > 0) std::memcpy(dst, p, n);  // an empty vector's data() may be null: memcpy must not see it
    p += n;
  };
  take(m.positions.data(), 12 * v);
  take(m.uvs.data(), 8 * v);
  take(m.indices.data(), 4 * i);
  take(out.triangle_ids.data(), 4 * t);
  for (uint64_t k = 0; k < v; ++k)
    if (!isFinite(m.positions[k]) || !isFinite(m.uvs[k]))
      throw Error(file, at + "vertex " + std::to_string(k) + ": non-finite position or uv");
  for (uint64_t k = 0; k < i; ++k)
    if (m.indices[k] >= v)
      throw Error(file, at + "index " + std::to_string(k) + " is " + std::to_string(m.indices[k]) +
                            ", out of range for " + std::to_string(v) + " vertices");
  m.computeBounds();
  out.stats.triangles = m.triangleCount();
  out.stats.vertices = m.vertexCount();
  return out;
}

// PNG through a temporary name (image::writePng writes to a path); the check is taken from the bytes written.
FileCheck writePngAtomic(const std::string& path, const image::ColorImage& image) {
  const std::string tmp = tempName(path);
  fileOperation("create", tmp);
  image::writePng(tmp, image);
  const FileCheck check = fileCheck(readWholeFile(tmp, ""));
  commitTemp(tmp, path, false);
  return check;
}

// A PNG named by the index: checked, then decoded; errors name the record too.
image::ColorImage readCheckedPng(const std::string& path, const FileCheck& check, const std::string& record) {
  if (check.known) readCheckedFile(path, check, record);
  try {
    return image::readPng(path);
  } catch (const Error& e) {
    throw Error(record + ": " + e.what());
  }
}

void createCellsDirectory(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(fs::path(dir) / "cells", ec);
  if (ec) throw Error(dir, "cannot create the cells directory: " + ec.message());
}

}  // namespace

uint32_t indexChecksum(const nlohmann::json& index_json) {
  nlohmann::json content = index_json;
  if (content.is_object()) content.erase("checksum");
  return fileCheck(content.dump()).crc32;
}

std::string indexFileText(nlohmann::json j) {
  if (j.is_object() && j.contains("version") && j["version"].is_number() && j["version"].get<double>() >= 3.0)
    j["checksum"] = indexChecksum(j);
  return j.dump(1) + "\n";
}

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

void syncCellFiles(const std::string& dir) {
  std::error_code ec;
  const fs::path cells = fs::path(dir) / "cells";
  if (fs::is_directory(cells, ec)) syncDirectory(cells.string());
  syncDirectory(dir);
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

FileCheck fileCheck(std::string_view bytes) {
  FileCheck check;
  check.bytes = bytes.size();
  check.crc32 = uint32_t(crc32_z(crc32_z(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(bytes.data()), bytes.size()));
  check.known = true;
  return check;
}

FileCheck writeFileAtomic(const std::string& path, std::string_view bytes, bool sync_directory) {
  const std::string tmp = tempName(path);
  fileOperation("create", tmp);
  struct Descriptor {
    int fd;
    ~Descriptor() {
      if (fd >= 0) ::close(fd);
    }
  } file{::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644)};
  if (file.fd < 0) systemError(tmp, "cannot open for writing", errno);
  const auto write_all = [&](std::string_view part) {
    while (!part.empty()) {
      const ssize_t n = ::write(file.fd, part.data(), part.size());
      if (n < 0) {
        if (errno == EINTR) continue;
        systemError(tmp, "write failed (disk full?)", errno);
      }
      part.remove_prefix(size_t(n));
    }
  };
  const size_t half = bytes.size() / 2;
  write_all(bytes.substr(0, half));
  fileOperation("write", tmp);  // a crash here leaves a torn temporary file, never a torn NAME
  write_all(bytes.substr(half));
  fileOperation("fsync", tmp);
  if (::fsync(file.fd) != 0) systemError(tmp, "fsync failed", errno);
  const int fd = file.fd;
  file.fd = -1;
  if (::close(fd) != 0) systemError(tmp, "write failed (close)", errno);
  fileOperation("rename", path);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) systemError(path, "cannot rename " + tmp + " over it", errno);
  if (sync_directory) syncDirectory(parentDirectory(path));
  return fileCheck(bytes);
}

std::string readCheckedFile(const std::string& path, const FileCheck& check, const std::string& record) {
  std::string bytes = readWholeFile(path, record);
  if (!check.known) return bytes;
  const std::string at = record.empty() ? "" : record + ": ";
  if (bytes.size() < check.bytes)
    throw Error(path, at + "truncated: " + std::to_string(bytes.size()) + " of " + std::to_string(check.bytes) +
                          " bytes");
  if (bytes.size() > check.bytes)
    throw Error(path, at + "too long: " + std::to_string(bytes.size()) + " bytes, the index says " +
                          std::to_string(check.bytes));
  const uint32_t crc = fileCheck(bytes).crc32;
  if (crc != check.crc32)
    throw Error(path, at + "checksum mismatch: CRC-32 " + hex32(crc) + ", the index says " + hex32(check.crc32));
  return bytes;
}

void setFileOperationHook(std::function<void(const char* operation, const std::string& path)> hook) {
  fileHook() = std::move(hook);
}

FileCheck writeMesh(const std::string& file, const impostor::DepthMeshImpostor& impostor) {
  return writeFileAtomic(file, meshBytes(impostor, file), false);
}

impostor::DepthMeshImpostor readMesh(const std::string& file) { return meshFromBytes(readWholeFile(file, ""), file, ""); }

std::string textureFileName(uint32_t half_edge, uint64_t generation) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "e%06u.png", half_edge);
  return "cells/" + generationPrefix(generation) + buf;
}

std::string meshFileName(uint32_t half_edge, const std::string& technique, uint64_t generation) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "e%06u.", half_edge);
  return "cells/" + generationPrefix(generation) + buf + technique + ".ffmesh";
}

void writeCell(const std::string& dir, CellEntry& entry,
               const std::map<std::string, const impostor::DepthMeshImpostor*>& impostors, uint64_t generation) {
  createCellsDirectory(dir);
  entry.texture.clear();
  entry.texture_check = {};
  const image::ColorImage* written = nullptr;
  for (const auto& [technique, imp] : impostors) {
    StoredImpostor& s = entry.impostors[technique];
    s.mesh = meshFileName(entry.half_edge, technique, generation);
    s.triangles = imp->mesh.triangleCount();
    s.vertices = imp->mesh.vertexCount();
    s.mesh_check = writeMesh(joinPath(dir, s.mesh), *imp);
    if (imp->empty() || !imp->texture) continue;
    if (!written) {
      entry.texture = textureFileName(entry.half_edge, generation);
      entry.texture_check = writePngAtomic(joinPath(dir, entry.texture), *imp->texture);
      written = imp->texture.get();
    } else if (written->width() != imp->texture->width() || written->height() != imp->texture->height() ||
               written->pixels() != imp->texture->pixels()) {
      // Different textures for the same cell: the format has one texture per cell, so this is a caller error.
      throw Error(dir, "cell " + std::to_string(entry.half_edge) + ": technique " + technique +
                           " has a texture different from the cell's (impostors of a cell must share one capture)");
    }
  }
}

impostor::DepthMeshImpostor loadImpostor(const std::string& dir, const CellEntry& entry,
                                         const std::string& technique) {
  const auto it = entry.impostors.find(technique);
  if (it == entry.impostors.end())
    throw Error(joinPath(dir, kIndexFile), "cell " + std::to_string(entry.half_edge) + " has no " + technique +
                                               " impostor");
  // A Sillion cell impostor is a one-view layer whose texture is the cell's.
  StoredView view;
  view.camera = entry.camera;
  view.texture = entry.texture;
  view.texture_check = entry.texture_check;
  view.mesh = it->second.mesh;
  view.mesh_check = it->second.mesh_check;
  view.triangles = it->second.triangles;
  view.vertices = it->second.vertices;
  view.record = "cell " + std::to_string(entry.half_edge) + " " + technique;
  return loadLayerView(dir, view);
}

std::string layerFileStem(uint32_t half_edge, const std::string& kind, size_t layer, size_t view,
                          uint64_t generation) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "e%06u.%s.%02zu.%zu", half_edge, kind.c_str(), layer, view);
  return "cells/" + generationPrefix(generation) + buf;
}

StoredView writeLayerView(const std::string& dir, const std::string& stem, const impostor::DepthMeshImpostor& view) {
  createCellsDirectory(dir);
  StoredView out;
  out.camera = view.camera;
  out.mesh = stem + ".ffmesh";
  out.triangles = view.mesh.triangleCount();
  out.vertices = view.mesh.vertexCount();
  out.mesh_check = writeMesh(joinPath(dir, out.mesh), view);
  if (!view.empty() && view.texture) {
    out.texture = stem + ".png";
    out.texture_check = writePngAtomic(joinPath(dir, out.texture), *view.texture);
  }
  if (!view.empty() && view.ids) {
    // 32-bit ids in the four 8-bit channels: PNG keeps them exactly and compresses the large runs of one id.
    image::ColorImage packed(view.ids->width(), view.ids->height());
    for (size_t i = 0; i < packed.pixelCount(); ++i) {
      const uint32_t id = view.ids->pixels()[i];
      packed.pixels()[i] = image::Rgba8(uint8_t(id), uint8_t(id >> 8), uint8_t(id >> 16), uint8_t(id >> 24));
    }
    out.ids = stem + ".ids.png";
    out.ids_check = writePngAtomic(joinPath(dir, out.ids), packed);
  }
  return out;
}

impostor::DepthMeshImpostor loadLayerView(const std::string& dir, const StoredView& view) {
  const std::string record = view.record.empty() ? "layer view" : view.record;
  const std::string mesh_file = joinPath(dir, view.mesh);
  impostor::DepthMeshImpostor out =
      meshFromBytes(readCheckedFile(mesh_file, view.mesh_check, record + " mesh"), mesh_file, record + " mesh");
  if (out.mesh.triangleCount() != view.triangles || out.mesh.vertexCount() != view.vertices)
    throw Error(mesh_file, record + " mesh: holds " + std::to_string(out.mesh.triangleCount()) + " triangles and " +
                               std::to_string(out.mesh.vertexCount()) + " vertices, the index says " +
                               std::to_string(view.triangles) + " and " + std::to_string(view.vertices));
  out.camera = view.camera;
  if (out.empty()) return out;
  const std::string texture_file = joinPath(dir, view.texture);
  auto texture =
      std::make_shared<image::ColorImage>(readCheckedPng(texture_file, view.texture_check, record + " texture"));
  if (texture->width() != view.camera.width || texture->height() != view.camera.height)
    throw Error(texture_file, record + " texture: " + std::to_string(texture->width()) + "x" +
                                  std::to_string(texture->height()) + " but the creation camera is " +
                                  std::to_string(view.camera.width) + "x" + std::to_string(view.camera.height));
  out.texture = std::move(texture);
  if (!view.ids.empty()) {
    const std::string ids_file = joinPath(dir, view.ids);
    const image::ColorImage packed = readCheckedPng(ids_file, view.ids_check, record + " ids");
    if (packed.width() != view.camera.width || packed.height() != view.camera.height)
      throw Error(ids_file, record + " ids: id image is " + std::to_string(packed.width()) + "x" +
                                std::to_string(packed.height()) + " but the creation camera is " +
                                std::to_string(view.camera.width) + "x" + std::to_string(view.camera.height));
    auto ids = std::make_shared<image::IdImage>(packed.width(), packed.height(), 0u);
    for (size_t i = 0; i < packed.pixelCount(); ++i) {
      const image::Rgba8 c = packed.pixels()[i];
      ids->pixels()[i] = uint32_t(c.r) | uint32_t(c.g) << 8 | uint32_t(c.b) << 16 | uint32_t(c.a) << 24;
    }
    out.ids = std::move(ids);
  }
  return out;
}

}  // namespace farfield::store
