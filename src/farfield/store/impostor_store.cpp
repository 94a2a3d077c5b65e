// The simple impostor store: JSON index, binary meshes, PNG textures (format in impostor_store.h).
//
// Why a raw binary mesh instead of glTF: the runtime loads an impostor inside a frame when the viewer enters a new
// cell, so the load must be a few reads and a validation pass, and the format must be trivial to check for
// truncation (the size is fixed by the counts in the header). glTF export of impostors is a later issue's.
#include "farfield/store/impostor_store.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <filesystem>
#include <fstream>

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

nlohmann::json vec3Json(const Vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); }

nlohmann::json cameraJson(const Camera& c) {
  return {{"eye", vec3Json(c.eye)}, {"at", vec3Json(c.at)},      {"up", vec3Json(c.up)},
          {"fov_y", c.fov_y},       {"width", c.width},          {"height", c.height},
          {"near", c.near_plane},   {"far", c.far_plane}};
}

// Typed access with errors naming the source and the element.
class JsonReader {
 public:
  JsonReader(const std::string& source) : source_(source) {}
  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw Error(source_, where + ": " + what);
  }
  const nlohmann::json& member(const nlohmann::json& j, const char* key, const std::string& where) const {
    if (!j.is_object()) fail(where, "expected an object");
    const auto it = j.find(key);
    if (it == j.end()) fail(where, std::string("missing \"") + key + "\"");
    return *it;
  }
  double number(const nlohmann::json& j, const char* key, const std::string& where) const {
    const nlohmann::json& v = member(j, key, where);
    if (!v.is_number()) fail(where, std::string("\"") + key + "\" must be a number");
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(where, std::string("\"") + key + "\" is not finite");
    return d;
  }
  uint64_t count(const nlohmann::json& j, const char* key, const std::string& where) const {
    const nlohmann::json& v = member(j, key, where);
    if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<int64_t>() >= 0))
      fail(where, std::string("\"") + key + "\" must be a non-negative integer");
    return v.get<uint64_t>();
  }
  std::string text(const nlohmann::json& j, const char* key, const std::string& where) const {
    const nlohmann::json& v = member(j, key, where);
    if (!v.is_string()) fail(where, std::string("\"") + key + "\" must be a string");
    return v.get<std::string>();
  }
  // A file name relative to the store directory: no absolute path, no "..".
  std::string relativeFile(const nlohmann::json& j, const char* key, const std::string& where,
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
  Vec3 vec3(const nlohmann::json& j, const char* key, const std::string& where) const {
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
  Camera camera(const nlohmann::json& j, const std::string& where) const {
    const nlohmann::json& c = member(j, "camera", where);
    const std::string at = where + ": camera";
    Camera cam;
    cam.eye = vec3(c, "eye", at);
    cam.at = vec3(c, "at", at);
    cam.up = vec3(c, "up", at);
    cam.fov_y = float(number(c, "fov_y", at));
    cam.width = int(count(c, "width", at));
    cam.height = int(count(c, "height", at));
    cam.near_plane = float(number(c, "near", at));
    cam.far_plane = float(number(c, "far", at));
    try {
      cam.validate("camera");
    } catch (const Error& e) {
      fail(at, e.what());
    }
    return cam;
  }

 private:
  std::string source_;
};

nlohmann::json viewJson(const StoredView& v) {
  return {{"camera", cameraJson(v.camera)}, {"texture", v.texture},         {"mesh", v.mesh}, {"ids", v.ids},
          {"triangles", v.triangles},       {"vertices", v.vertices},       {"data_pixels", v.data_pixels},
          {"render_ms", v.render_ms},       {"build_ms", v.build_ms},       {"station", v.station}};
}

nlohmann::json layerJson(const StoredLayer& l) {
  nlohmann::json views = nlohmann::json::array();
  for (const StoredView& v : l.views) views.push_back(viewJson(v));
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

nlohmann::json pipelineJson(const CellPipeline& p) {
  nlohmann::json j = nlohmann::json::object();
  if (p.has_pvs) j["pvs"] = {{"ids", p.pvs}, {"samples", p.pvs_samples}, {"ms", p.pvs_ms}};
  if (p.has_split) j["split"] = {{"near", p.near}, {"far", p.far}};
  if (p.has_mmi) {
    nlohmann::json layers = nlohmann::json::array();
    for (const StoredLayer& l : p.layers) layers.push_back(layerJson(l));
    j["mmi"] = {{"threshold_rad", p.threshold_rad}, {"event_edges", p.event_edges},
                {"max_weight_rad", p.max_weight_rad}, {"weights_ms", p.weights_ms},
                {"layers", std::move(layers)},       {"single", layerJson(p.single)}};
  }
  return j;
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
                      bool require_validity) {
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

CellPipeline readPipeline(const JsonReader& r, const nlohmann::json& j, const std::string& where,
                          size_t scene_objects, bool require_validity) {
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
      p.layers.push_back(
          readLayer(r, layers[l], at + ".layers[" + std::to_string(l) + "]", scene_objects, require_validity));
    p.single = readLayer(r, r.member(m, "single", at), at + ".single", scene_objects, require_validity);
  }
  return p;
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
  j["format"] = kIndexFormat;
  j["version"] = index.version;
  j["techniques"] = index.techniques;
  j["streets"] = index.streets;
  j["scene"] = index.scene;
  j["scene_objects"] = index.scene_objects;
  j["local_model"] = index.local_model;
  j["cell_lookup"] = index.cell_lookup;
  j["options"] = index.options;
  if (!index.pipeline.empty()) {
    j["pipeline"] = index.pipeline;
    j["online"] = index.online;
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
    nlohmann::json imps = nlohmann::json::object();
    for (const auto& [technique, imp] : c.impostors)
      imps[technique] = {{"mesh", imp.mesh},
                         {"triangles", imp.triangles},
                         {"vertices", imp.vertices},
                         {"build_ms", imp.build_ms}};
    cell["impostors"] = std::move(imps);
    if (c.pipeline) cell["pipeline"] = pipelineJson(*c.pipeline);
    cells.push_back(std::move(cell));
  }
  j["cells"] = std::move(cells);
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
  if (j.contains("scene") && j["scene"].is_string()) index.scene = j["scene"].get<std::string>();
  index.scene_objects = size_t(r.count(j, "scene_objects", "top level"));
  index.local_model = r.text(j, "local_model", "top level");
  if (j.contains("cell_lookup")) index.cell_lookup = r.text(j, "cell_lookup", "top level");
  if (j.contains("options")) index.options = j["options"];
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
    const nlohmann::json& imps = r.member(c, "impostors", where);
    if (!imps.is_object()) r.fail(where, "\"impostors\" must be an object (technique -> impostor)");
    for (const std::string& technique : index.techniques) {
      const std::string at = where + ": impostors." + technique;
      if (!imps.contains(technique)) r.fail(where, "no impostor for technique \"" + technique + "\"");
      const nlohmann::json& imp = imps[technique];
      StoredImpostor s;
      s.mesh = r.relativeFile(imp, "mesh", at, false);
      s.triangles = size_t(r.count(imp, "triangles", at));
      s.vertices = size_t(r.count(imp, "vertices", at));
      s.build_ms = r.number(imp, "build_ms", at);
      if (s.triangles > 0 && e.texture.empty()) r.fail(at, "has triangles but the cell has no texture");
      e.impostors[technique] = std::move(s);
    }
    if (c.contains("pipeline")) e.pipeline = readPipeline(r, c["pipeline"], where + ": pipeline", index.scene_objects,
                                                                index.version >= 3);
    index.cells.push_back(std::move(e));
  }
  return index;
}

void writeIndex(const std::string& dir, const StoreIndex& index) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(dir, "cannot create the store directory: " + ec.message());
  const std::string file = joinPath(dir, kIndexFile);
  // Written to a temporary name first so that an interrupted bake never leaves a half-written index.
  const std::string tmp = file + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw Error(tmp, "cannot open for writing");
    out << indexToJson(index).dump(1) << "\n";
    if (!out) throw Error(tmp, "write failed");
  }
  fs::rename(tmp, file, ec);
  if (ec) throw Error(file, "cannot replace the index: " + ec.message());
}

StoreIndex readIndex(const std::string& dir) {
  const std::string file = joinPath(dir, kIndexFile);
  if (!fs::is_directory(dir)) throw Error(dir, "impostor store directory not found");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(file, "cannot open (is this an impostor store written by farfield bake?)");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, std::string("not valid JSON: ") + e.what());
  }
  return indexFromJson(j, file);
}

void writeMesh(const std::string& file, const impostor::DepthMeshImpostor& impostor) {
  const scene::Mesh& m = impostor.mesh;
  const uint32_t v = uint32_t(m.positions.size()), i = uint32_t(m.indices.size());
  const uint32_t t = uint32_t(impostor.triangle_ids.size());
  if (m.positions.size() >= 0xffffffffu || m.indices.size() >= 0xffffffffu)
    throw Error(file, "mesh too large for the format");
  if (i % 3 != 0) throw Error(file, "index count is not a multiple of 3");
  if (t != 0 && t != i / 3) throw Error(file, "triangle id count must be 0 or one per triangle");
  if (!m.uvs.empty() && m.uvs.size() != m.positions.size()) throw Error(file, "uv count differs from vertex count");
  std::ofstream out(file, std::ios::binary);
  if (!out) throw Error(file, "cannot open for writing");
  const uint32_t header[4] = {kMeshVersion, v, i, t};
  out.write(kMeshMagic, sizeof(kMeshMagic));
  out.write(reinterpret_cast<const char*>(header), sizeof(header));
  out.write(reinterpret_cast<const char*>(m.positions.data()), std::streamsize(sizeof(Vec3) * v));
  if (m.uvs.empty()) {
    const std::vector<Vec2> zeros(v, Vec2(0.0f));
    out.write(reinterpret_cast<const char*>(zeros.data()), std::streamsize(sizeof(Vec2) * v));
  } else {
    out.write(reinterpret_cast<const char*>(m.uvs.data()), std::streamsize(sizeof(Vec2) * v));
  }
  out.write(reinterpret_cast<const char*>(m.indices.data()), std::streamsize(sizeof(uint32_t) * i));
  out.write(reinterpret_cast<const char*>(impostor.triangle_ids.data()), std::streamsize(sizeof(uint32_t) * t));
  if (!out) throw Error(file, "write failed");
}

impostor::DepthMeshImpostor readMesh(const std::string& file) {
  static_assert(sizeof(Vec3) == 12 && sizeof(Vec2) == 8);
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) throw Error(file, "cannot open impostor mesh");
  const std::streamoff size = in.tellg();
  in.seekg(0);
  if (size < std::streamoff(kMeshHeaderBytes))
    throw Error(file, "truncated: " + std::to_string(size) + " bytes, shorter than the 24-byte header");
  char magic[8];
  uint32_t header[4];
  in.read(magic, sizeof(magic));
  in.read(reinterpret_cast<char*>(header), sizeof(header));
  if (!in) throw Error(file, "cannot read the header");
  if (std::memcmp(magic, kMeshMagic, sizeof(magic)) != 0)
    throw Error(file, "bad magic: not a Farfield impostor mesh (expected \"FFIMESH\")");
  if (header[0] != kMeshVersion)
    throw Error(file, "unsupported mesh version " + std::to_string(header[0]) + " (this build reads version " +
                          std::to_string(kMeshVersion) + ")");
  const uint64_t v = header[1], i = header[2], t = header[3];
  if (i % 3 != 0) throw Error(file, "index count " + std::to_string(i) + " is not a multiple of 3");
  if (t != 0 && t != i / 3)
    throw Error(file, "triangle id count " + std::to_string(t) + " must be 0 or " + std::to_string(i / 3));
  const uint64_t expected = kMeshHeaderBytes + 20 * v + 4 * i + 4 * t;
  if (uint64_t(size) < expected)
    throw Error(file, "truncated: " + std::to_string(size) + " bytes, the header's counts need " +
                          std::to_string(expected));
  if (uint64_t(size) > expected)
    throw Error(file, "trailing data: " + std::to_string(size) + " bytes, the header's counts need " +
                          std::to_string(expected));
  impostor::DepthMeshImpostor out;
  scene::Mesh& m = out.mesh;
  m.positions.resize(v);
  m.uvs.resize(v);
  m.indices.resize(i);
  out.triangle_ids.resize(t);
  in.read(reinterpret_cast<char*>(m.positions.data()), std::streamsize(12 * v));
  in.read(reinterpret_cast<char*>(m.uvs.data()), std::streamsize(8 * v));
  in.read(reinterpret_cast<char*>(m.indices.data()), std::streamsize(4 * i));
  in.read(reinterpret_cast<char*>(out.triangle_ids.data()), std::streamsize(4 * t));
  if (!in) throw Error(file, "read failed");
  for (uint64_t k = 0; k < v; ++k)
    if (!isFinite(m.positions[k]) || !isFinite(m.uvs[k]))
      throw Error(file, "vertex " + std::to_string(k) + ": non-finite position or uv");
  for (uint64_t k = 0; k < i; ++k)
    if (m.indices[k] >= v)
      throw Error(file, "index " + std::to_string(k) + " is " + std::to_string(m.indices[k]) +
                            ", out of range for " + std::to_string(v) + " vertices");
  m.computeBounds();
  out.stats.triangles = m.triangleCount();
  out.stats.vertices = m.vertexCount();
  return out;
}

std::string textureFileName(uint32_t half_edge) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "cells/e%06u.png", half_edge);
  return buf;
}

std::string meshFileName(uint32_t half_edge, const std::string& technique) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "cells/e%06u.", half_edge);
  return buf + technique + ".ffmesh";
}

void writeCell(const std::string& dir, CellEntry& entry,
               const std::map<std::string, const impostor::DepthMeshImpostor*>& impostors) {
  std::error_code ec;
  fs::create_directories(fs::path(dir) / "cells", ec);
  if (ec) throw Error(dir, "cannot create the cells directory: " + ec.message());
  entry.texture.clear();
  const image::ColorImage* written = nullptr;
  for (const auto& [technique, imp] : impostors) {
    StoredImpostor& s = entry.impostors[technique];
    s.mesh = meshFileName(entry.half_edge, technique);
    s.triangles = imp->mesh.triangleCount();
    s.vertices = imp->mesh.vertexCount();
    writeMesh(joinPath(dir, s.mesh), *imp);
    if (imp->empty() || !imp->texture) continue;
    if (!written) {
      entry.texture = textureFileName(entry.half_edge);
      image::writePng(joinPath(dir, entry.texture), *imp->texture);
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
  view.mesh = it->second.mesh;
  view.triangles = it->second.triangles;
  view.vertices = it->second.vertices;
  return loadLayerView(dir, view);
}

std::string layerFileStem(uint32_t half_edge, const std::string& kind, size_t layer, size_t view) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "cells/e%06u.%s.%02zu.%zu", half_edge, kind.c_str(), layer, view);
  return buf;
}

StoredView writeLayerView(const std::string& dir, const std::string& stem, const impostor::DepthMeshImpostor& view) {
  std::error_code ec;
  fs::create_directories(fs::path(dir) / "cells", ec);
  if (ec) throw Error(dir, "cannot create the cells directory: " + ec.message());
  StoredView out;
  out.camera = view.camera;
  out.mesh = stem + ".ffmesh";
  out.triangles = view.mesh.triangleCount();
  out.vertices = view.mesh.vertexCount();
  writeMesh(joinPath(dir, out.mesh), view);
  if (!view.empty() && view.texture) {
    out.texture = stem + ".png";
    image::writePng(joinPath(dir, out.texture), *view.texture);
  }
  if (!view.empty() && view.ids) {
    // 32-bit ids in the four 8-bit channels: PNG keeps them exactly and compresses the large runs of one id.
    image::ColorImage packed(view.ids->width(), view.ids->height());
    for (size_t i = 0; i < packed.pixelCount(); ++i) {
      const uint32_t id = view.ids->pixels()[i];
      packed.pixels()[i] = image::Rgba8(uint8_t(id), uint8_t(id >> 8), uint8_t(id >> 16), uint8_t(id >> 24));
    }
    out.ids = stem + ".ids.png";
    image::writePng(joinPath(dir, out.ids), packed);
  }
  return out;
}

impostor::DepthMeshImpostor loadLayerView(const std::string& dir, const StoredView& view) {
  const std::string mesh_file = joinPath(dir, view.mesh);
  impostor::DepthMeshImpostor out = readMesh(mesh_file);
  if (out.mesh.triangleCount() != view.triangles || out.mesh.vertexCount() != view.vertices)
    throw Error(mesh_file, "holds " + std::to_string(out.mesh.triangleCount()) + " triangles and " +
                               std::to_string(out.mesh.vertexCount()) + " vertices, the index says " +
                               std::to_string(view.triangles) + " and " + std::to_string(view.vertices));
  out.camera = view.camera;
  if (out.empty()) return out;
  const std::string texture_file = joinPath(dir, view.texture);
  auto texture = std::make_shared<image::ColorImage>(image::readPng(texture_file));
  if (texture->width() != view.camera.width || texture->height() != view.camera.height)
    throw Error(texture_file, "texture is " + std::to_string(texture->width()) + "x" +
                                  std::to_string(texture->height()) + " but the creation camera is " +
                                  std::to_string(view.camera.width) + "x" + std::to_string(view.camera.height));
  out.texture = std::move(texture);
  if (!view.ids.empty()) {
    const std::string ids_file = joinPath(dir, view.ids);
    const image::ColorImage packed = image::readPng(ids_file);
    if (packed.width() != view.camera.width || packed.height() != view.camera.height)
      throw Error(ids_file, "id image is " + std::to_string(packed.width()) + "x" + std::to_string(packed.height()) +
                                " but the creation camera is " + std::to_string(view.camera.width) + "x" +
                                std::to_string(view.camera.height));
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
