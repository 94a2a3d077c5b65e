// The impostor store's index as JSON (indexToJson, indexFromJson): cells, their pipeline records (layers, views,
// validity regions), the shard record and the older versions still read; and the index's checksum and text form.
#include "farfield/store/impostor_store.h"

#include <algorithm>
#include <string>
#include <vector>

#include "farfield/store/json_fields.h"

namespace farfield::store {

namespace {

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

}  // namespace farfield::store
