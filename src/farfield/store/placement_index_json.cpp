// The placement database's index as JSON (placementToJson, placementFromJson): the layered impostor records, the CPVs
// and the BSP of the view space, every rule of placement_store.h checked on reading.
//
// Why the plan is re-derived and not stored: a LayeredPlan is some thirty numbers per impostor and per layer, all
// functions of four inputs; storing them would give the reader two sources of truth to reconcile. planLayered is pure
// float and double arithmetic in a fixed order, so the same inputs give the same plan bit for bit, and the image sizes
// on disk check that it did.
#include "farfield/store/placement_store.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/store/json_fields.h"
#include "farfield/store/store_files.h"

namespace farfield::store {

namespace {

nlohmann::json shaftJson(const Shaft& s) {
  return {{"apex", vec3Json(s.apex)},
          {"axis", vec3Json(s.axis)},
          {"apex_angle", s.apex_angle},
          {"min_distance", s.min_distance}};
}

nlohmann::json boundJson(const ErrorBound& b) {
  return {{"pixels", b.pixels}, {"width", b.width}, {"height", b.height}, {"fov_y", b.fov_y}};
}

nlohmann::json layeredOptionsJson(const impostor::LayeredOptions& o) {
  return {{"texel_pixels", o.texel_pixels},   {"max_texture_size", o.max_texture_size},
          {"max_layers", o.max_layers},       {"layer_count", o.layer_count},
          {"bound_cracks", o.bound_cracks},   {"id_textures", o.id_textures},
          {"solid_slices", o.solid_slices},   {"dilate_texels", o.dilate_texels}};
}

nlohmann::json impostorJson(const StoredPlacedImpostor& imp) {
  nlohmann::json layers = nlohmann::json::array();
  for (const StoredImpostorLayer& l : imp.layers) {
    nlohmann::json j = {{"texture", l.texture},
                        {"ids", l.ids},
                        {"data_texels", l.data_texels},
                        {"render_ms", l.render_ms},
                        {"crop", {l.crop.x, l.crop.y, l.crop.width, l.crop.height}}};
    putCheck(j, "texture", l.texture, l.texture_check, true);
    putCheck(j, "ids", l.ids, l.ids_check, true);
    layers.push_back(std::move(j));
  }
  return {{"id", imp.id},
          {"node", imp.node},
          {"objects", imp.objects},
          {"box", box3Json(imp.box)},
          {"shaft", shaftJson(imp.shaft)},
          {"bound", boundJson(imp.bound)},
          {"options", layeredOptionsJson(imp.options)},
          {"layers", std::move(layers)},
          {"bytes", imp.bytes},
          {"capture_ms", imp.capture_ms}};
}

float floatNumber(const JsonReader& r, const nlohmann::json& j, const char* key, const std::string& where) {
  const double d = r.number(j, key, where);
  if (std::abs(d) > double(std::numeric_limits<float>::max())) r.fail(where, std::string("\"") + key + "\" too large");
  return float(d);
}

double nonNegative(const JsonReader& r, const nlohmann::json& j, const char* key, const std::string& where) {
  const double d = r.number(j, key, where);
  if (!(d >= 0.0)) r.fail(where, std::string("\"") + key + "\" must be >= 0");
  return d;
}

uint32_t id32(const JsonReader& r, const nlohmann::json& j, const char* key, const std::string& where) {
  const uint64_t v = r.count(j, key, where);
  if (v > 0xffffffffu) r.fail(where, std::string("\"") + key + "\" must be 0..4294967295");
  return uint32_t(v);
}

Shaft readShaft(const JsonReader& r, const nlohmann::json& j, const std::string& where) {
  const nlohmann::json& s = r.member(j, "shaft", where);
  const std::string at = where + ".shaft";
  r.onlyKeys(s, {"apex", "axis", "apex_angle", "min_distance"}, at);
  Shaft shaft;
  shaft.apex = r.vec3(s, "apex", at);
  shaft.axis = r.vec3(s, "axis", at);
  shaft.apex_angle = floatNumber(r, s, "apex_angle", at);
  shaft.min_distance = floatNumber(r, s, "min_distance", at);
  return shaft;
}

ErrorBound readBound(const JsonReader& r, const nlohmann::json& j, const std::string& where) {
  const nlohmann::json& b = r.member(j, "bound", where);
  const std::string at = where + ".bound";
  r.onlyKeys(b, {"pixels", "width", "height", "fov_y"}, at);
  ErrorBound bound;
  bound.pixels = r.number(b, "pixels", at);
  bound.width = int(r.integer(b, "width", at, 1, std::numeric_limits<int>::max()));
  bound.height = int(r.integer(b, "height", at, 1, std::numeric_limits<int>::max()));
  bound.fov_y = r.number(b, "fov_y", at);
  return bound;
}

impostor::LayeredOptions readLayeredOptions(const JsonReader& r, const nlohmann::json& j, const std::string& where) {
  const nlohmann::json& o = r.member(j, "options", where);
  const std::string at = where + ".options";
  r.onlyKeys(o,
             {"texel_pixels", "max_texture_size", "max_layers", "layer_count", "bound_cracks", "id_textures",
              "solid_slices", "dilate_texels"},
             at);
  impostor::LayeredOptions options;
  options.texel_pixels = r.number(o, "texel_pixels", at);
  options.max_texture_size = int(r.integer(o, "max_texture_size", at, 1, 16384));
  options.max_layers = int(r.integer(o, "max_layers", at, 1, std::numeric_limits<int>::max()));
  options.layer_count = int(r.integer(o, "layer_count", at, 0, 4096));
  options.bound_cracks = r.flag(o, "bound_cracks", at);
  options.id_textures = r.flag(o, "id_textures", at);
  options.solid_slices = r.flag(o, "solid_slices", at);
  options.dilate_texels = int(r.integer(o, "dilate_texels", at, 0, 16));
  return options;
}

StoredPlacedImpostor readImpostor(const JsonReader& r, const nlohmann::json& j, const std::string& where,
                                  size_t scene_objects) {
  r.onlyKeys(j, {"id", "node", "objects", "box", "shaft", "bound", "options", "layers", "bytes", "capture_ms"},
             where);
  StoredPlacedImpostor imp;
  imp.id = id32(r, j, "id", where);
  imp.record = recordName(imp.id);
  imp.node = id32(r, j, "node", where);
  imp.objects = readIds(r, j, "objects", where, scene_objects);
  if (imp.objects.empty()) r.fail(where, "\"objects\" is empty (an impostor replaces at least one object)");
  imp.box = r.box3(j, "box", where);
  imp.shaft = readShaft(r, j, where);
  imp.bound = readBound(r, j, where);
  imp.options = readLayeredOptions(r, j, where);
  imp.bytes = r.count(j, "bytes", where);
  imp.capture_ms = nonNegative(r, j, "capture_ms", where);
  impostor::LayeredPlan plan;
  try {
    plan = impostor::planLayered(imp.box, imp.shaft, imp.bound, imp.options);
  } catch (const Error& e) {
    r.fail(where, std::string("its box, shaft, bound and options give no layered plan: ") + e.what());
  }
  const nlohmann::json& layers = r.member(j, "layers", where);
  if (!layers.is_array()) r.fail(where, "\"layers\" must be an array");
  if (layers.size() != plan.layers.size())
    r.fail(where + ".layers", "holds " + std::to_string(layers.size()) + " layers, the plan of its box, shaft, bound "
                              "and options has " + std::to_string(plan.layers.size()));
  for (size_t l = 0; l < layers.size(); ++l) {
    const std::string at = where + ".layers[" + std::to_string(l) + "]";
    const nlohmann::json& lj = layers[l];
    r.onlyKeys(lj, {"texture", "texture_crc32", "texture_bytes", "ids", "ids_crc32", "ids_bytes", "data_texels",
                    "render_ms", "crop"},
               at);
    StoredImpostorLayer layer;
    layer.texture = r.relativeFile(lj, "texture", at, false);
    layer.texture_check = readCheck(r, lj, "texture", at, layer.texture, true);
    layer.ids = r.relativeFile(lj, "ids", at, true);
    layer.ids_check = readCheck(r, lj, "ids", at, layer.ids, true);
    if (layer.ids.empty() && (lj.contains("ids_crc32") || lj.contains("ids_bytes")))
      r.fail(at, "\"ids_crc32\"/\"ids_bytes\" without an ids file");
    if (layer.ids.empty() == imp.options.id_textures)
      r.fail(at, imp.options.id_textures ? "\"ids\" is empty but the options have id_textures"
                                         : "\"ids\" names a file but the options have no id_textures");
    layer.data_texels = size_t(r.count(lj, "data_texels", at));
    const nlohmann::json& crop = r.member(lj, "crop", at);
    if (!crop.is_array() || crop.size() != 4 || !std::all_of(crop.begin(), crop.end(), [](const nlohmann::json& v) {
          return v.is_number_integer() && v.get<int64_t>() >= 0 && v.get<int64_t>() <= (int64_t(1) << 20);
        }))
      r.fail(at, "\"crop\" must be [x, y, width, height], integers of 0 .. 2^20");
    layer.crop = {crop[0].get<int>(), crop[1].get<int>(), crop[2].get<int>(), crop[3].get<int>()};
    layer.render_ms = nonNegative(r, lj, "render_ms", at);
    imp.layers.push_back(std::move(layer));
  }
  std::vector<impostor::LayerCrop> crops;
  for (const StoredImpostorLayer& layer : imp.layers) crops.push_back(layer.crop);
  try {
    impostor::cropLayers(plan, crops);
  } catch (const Error& e) {
    r.fail(where + ".layers", e.what());
  }
  for (size_t l = 0; l < imp.layers.size(); ++l) {
    const uint64_t texels = uint64_t(plan.layers[l].width) * uint64_t(plan.layers[l].height);
    if (imp.layers[l].data_texels > texels)
      r.fail(where + ".layers[" + std::to_string(l) + "]", "\"data_texels\" " +
                 std::to_string(imp.layers[l].data_texels) + " exceeds the layer's " + std::to_string(texels) +
                 " texels");
  }
  return imp;
}

Vdi readVdi(const JsonReader& r, const nlohmann::json& j, const std::string& where) {
  const nlohmann::json& v = r.member(j, "vdi", where);
  const std::string at = where + ".vdi";
  r.onlyKeys(v, {"face", "u0", "u1", "v0", "v1"}, at);
  Vdi vdi;
  vdi.face = int(r.integer(v, "face", at, 0, 5));
  vdi.u0 = floatNumber(r, v, "u0", at);
  vdi.u1 = floatNumber(r, v, "u1", at);
  vdi.v0 = floatNumber(r, v, "v0", at);
  vdi.v1 = floatNumber(r, v, "v1", at);
  if (!(-1.0f <= vdi.u0 && vdi.u0 < vdi.u1 && vdi.u1 <= 1.0f))
    r.fail(at, "needs -1 <= u0 < u1 <= 1");
  if (!(-1.0f <= vdi.v0 && vdi.v0 < vdi.v1 && vdi.v1 <= 1.0f))
    r.fail(at, "needs -1 <= v0 < v1 <= 1");
  return vdi;
}

bool inside(const Box3& inner, const Box3& outer) {
  for (int i = 0; i < 3; ++i)
    if (inner.lo[i] < outer.lo[i] || inner.hi[i] > outer.hi[i]) return false;
  return true;
}

bool sameBox(const Box3& a, const Box3& b) { return a.lo == b.lo && a.hi == b.hi; }

std::string nodeName(size_t k) { return "nodes[" + std::to_string(k) + "]"; }

// The BSP's shape and its CPV ranges (the rules in the header). First the indices (ranges inside the list, children
// after their parent, one parent each), so that the second pass may follow them: boxes, range splits, leaf regions.
void checkNodes(const JsonReader& r, const PlacementIndex& index) {
  const size_t n = index.nodes.size();
  const uint64_t cpv_total = index.cpvs.size();
  if (n == 0) r.fail("\"nodes\"", "is empty (node 0 is the whole view space)");
  const StoredViewSpaceNode& root = index.nodes[0];
  if (!sameBox(root.box, index.view_space)) r.fail(nodeName(0), "its box is not \"view_space\"");
  if (root.cpv_first != 0 || root.cpv_count != cpv_total)
    r.fail(nodeName(0), "must hold every CPV: [0, " + std::to_string(cpv_total) + ")");
  std::vector<int> parent(n, -1);
  for (size_t k = 0; k < n; ++k) {
    const StoredViewSpaceNode& node = index.nodes[k];
    if (uint64_t(node.cpv_first) + node.cpv_count > cpv_total)
      r.fail(nodeName(k), "its CPVs [" + std::to_string(node.cpv_first) + ", " +
                              std::to_string(uint64_t(node.cpv_first) + node.cpv_count) + ") leave the " +
                              std::to_string(cpv_total) + " CPVs");
    const int a = node.children[0], b = node.children[1];
    if (a < 0 && b < 0) continue;
    for (const int c : {a, b})
      if (c <= int(k) || size_t(c) >= n)
        r.fail(nodeName(k) + ".children", "must be both -1 (a leaf) or both nodes after it (" +
                                              std::to_string(k + 1) + ".." + std::to_string(n - 1) + "), not [" +
                                              std::to_string(a) + ", " + std::to_string(b) + "]");
    if (a == b) r.fail(nodeName(k) + ".children", "names node " + std::to_string(a) + " twice");
    for (const int c : {a, b}) {
      if (parent[size_t(c)] >= 0)
        r.fail(nodeName(size_t(c)), "is a child of both " + nodeName(size_t(parent[size_t(c)])) + " and " +
                                        nodeName(k));
      parent[size_t(c)] = int(k);
    }
  }
  for (size_t k = 1; k < n; ++k)
    if (parent[k] < 0) r.fail(nodeName(k), "is no node's child (not reachable from node 0)");
  for (size_t k = 0; k < n; ++k) {
    const StoredViewSpaceNode& node = index.nodes[k];
    if (node.children[0] < 0) {
      for (uint32_t c = node.cpv_first; c < node.cpv_first + node.cpv_count; ++c)
        if (!inside(index.cpvs[c].region, node.box))
          r.fail("cpvs[" + std::to_string(c) + "].region", "lies outside the box of " + nodeName(k) +
                                                               ", the leaf holding it");
      continue;
    }
    for (const int c : node.children)
      if (!inside(index.nodes[size_t(c)].box, node.box))
        r.fail(nodeName(size_t(c)), "its box leaves the box of its parent " + nodeName(k));
    const StoredViewSpaceNode &lower = index.nodes[size_t(node.children[0])],
                              &upper = index.nodes[size_t(node.children[1])];
    if (lower.cpv_first != node.cpv_first || uint64_t(upper.cpv_first) != uint64_t(lower.cpv_first) + lower.cpv_count ||
        uint64_t(lower.cpv_count) + upper.cpv_count != node.cpv_count)
      r.fail(nodeName(k), "its children's CPV ranges do not split its range [" + std::to_string(node.cpv_first) +
                              ", " + std::to_string(uint64_t(node.cpv_first) + node.cpv_count) + ") in order");
  }
}

}  // namespace

const StoredPlacedImpostor* PlacementIndex::find(uint32_t id) const {
  const auto it = std::lower_bound(impostors.begin(), impostors.end(), id,
                                   [](const StoredPlacedImpostor& i, uint32_t v) { return i.id < v; });
  return it != impostors.end() && it->id == id ? &*it : nullptr;
}

nlohmann::json placementToJson(const PlacementIndex& index) {
  nlohmann::json j;
  j["format"] = kPlacementFormat;
  j["version"] = index.version;
  j["generation"] = index.generation;
  j["scene"] = index.scene;
  j["scene_objects"] = index.scene_objects;
  j["options"] = index.options;
  j["summary"] = index.summary;
  j["view_space"] = box3Json(index.view_space);
  nlohmann::json nodes = nlohmann::json::array();
  for (const StoredViewSpaceNode& n : index.nodes)
    nodes.push_back({{"box", box3Json(n.box)},
                     {"children", {n.children[0], n.children[1]}},
                     {"cpv_first", n.cpv_first},
                     {"cpv_count", n.cpv_count},
                     {"visible", n.has_visible ? nlohmann::json(n.visible) : nlohmann::json(nullptr)}});
  j["nodes"] = std::move(nodes);
  nlohmann::json cpvs = nlohmann::json::array();
  for (const StoredCpv& c : index.cpvs)
    cpvs.push_back({{"region", box3Json(c.region)},
                    {"vdi", {{"face", c.vdi.face}, {"u0", c.vdi.u0}, {"u1", c.vdi.u1}, {"v0", c.vdi.v0},
                             {"v1", c.vdi.v1}}},
                    {"t_enc", c.t_enc},
                    {"t_after", c.t_after},
                    {"impostors", c.impostors}});
  j["cpvs"] = std::move(cpvs);
  nlohmann::json impostors = nlohmann::json::array();
  for (const StoredPlacedImpostor& imp : index.impostors) impostors.push_back(impostorJson(imp));
  j["impostors"] = std::move(impostors);
  return j;
}

PlacementIndex placementFromJson(const nlohmann::json& j, const std::string& source) {
  const JsonReader r(source);
  const std::string top = "top level";
  r.onlyKeys(j,
             {"format", "version", "generation", "checksum", "scene", "scene_objects", "options", "summary",
              "view_space", "nodes", "cpvs", "impostors"},
             top);
  PlacementIndex index;
  if (r.text(j, "format", top) != kPlacementFormat)
    r.fail("\"format\"", std::string("expected \"") + kPlacementFormat + "\"");
  const uint64_t version = r.count(j, "version", top);
  if (version != uint64_t(kPlacementVersion))
    r.fail("\"version\"", "unsupported version " + std::to_string(version) + " (this build reads version " +
                              std::to_string(kPlacementVersion) + "; run farfield place again)");
  index.version = int(version);
  index.generation = r.count(j, "generation", top);
  if (index.generation == 0) r.fail("\"generation\"", "must be >= 1");
  index.scene = r.text(j, "scene", top);
  index.scene_objects = size_t(r.count(j, "scene_objects", top));
  if (index.scene_objects > 0xffffffffu) r.fail("\"scene_objects\"", "must be at most 4294967295");
  index.options = r.member(j, "options", top);
  index.summary = r.member(j, "summary", top);
  index.view_space = r.box3(j, "view_space", top);

  const nlohmann::json& impostors = r.member(j, "impostors", top);
  if (!impostors.is_array()) r.fail("\"impostors\"", "must be an array");
  for (size_t k = 0; k < impostors.size(); ++k) {
    const std::string where = "impostors[" + std::to_string(k) + "]";
    index.impostors.push_back(readImpostor(r, impostors[k], where, index.scene_objects));
    if (k > 0 && index.impostors[k].id <= index.impostors[k - 1].id)
      r.fail(where + ".id", "impostors must be sorted by id without repeats (" +
                                std::to_string(index.impostors[k].id) + " after " +
                                std::to_string(index.impostors[k - 1].id) + ")");
  }

  const nlohmann::json& cpvs = r.member(j, "cpvs", top);
  if (!cpvs.is_array()) r.fail("\"cpvs\"", "must be an array");
  for (size_t k = 0; k < cpvs.size(); ++k) {
    const std::string where = "cpvs[" + std::to_string(k) + "]";
    const nlohmann::json& c = cpvs[k];
    r.onlyKeys(c, {"region", "vdi", "t_enc", "t_after", "impostors"}, where);
    StoredCpv cpv;
    cpv.region = r.box3(c, "region", where);
    cpv.vdi = readVdi(r, c, where);
    cpv.t_enc = nonNegative(r, c, "t_enc", where);
    cpv.t_after = nonNegative(r, c, "t_after", where);
    const nlohmann::json& list = r.member(c, "impostors", where);
    if (!list.is_array()) r.fail(where, "\"impostors\" must be an array of impostor ids");
    for (size_t i = 0; i < list.size(); ++i) {
      const std::string at = where + ".impostors[" + std::to_string(i) + "]";
      if (!list[i].is_number_unsigned() || list[i].get<uint64_t>() > 0xffffffffu)
        r.fail(at, "must be an impostor id (0..4294967295)");
      const uint32_t id = list[i].get<uint32_t>();
      if (!index.find(id)) r.fail(at, "names impostor " + std::to_string(id) + ", which the index does not hold");
      if (!cpv.impostors.empty() && id <= cpv.impostors.back())
        r.fail(at, "the ids must be ascending without repeats (" + std::to_string(id) + " after " +
                       std::to_string(cpv.impostors.back()) + ")");
      cpv.impostors.push_back(id);
    }
    index.cpvs.push_back(std::move(cpv));
  }

  const nlohmann::json& nodes = r.member(j, "nodes", top);
  if (!nodes.is_array()) r.fail("\"nodes\"", "must be an array");
  for (size_t k = 0; k < nodes.size(); ++k) {
    const std::string where = nodeName(k);
    const nlohmann::json& n = nodes[k];
    r.onlyKeys(n, {"box", "children", "cpv_first", "cpv_count", "visible"}, where);
    StoredViewSpaceNode node;
    node.box = r.box3(n, "box", where);
    const nlohmann::json& children = r.member(n, "children", where);
    if (!children.is_array() || children.size() != 2)
      r.fail(where + ".children", "must be [lower, upper] (node indices, or [-1, -1] for a leaf)");
    for (size_t c = 0; c < 2; ++c) {
      const nlohmann::json& v = children[c];
      if (!v.is_number_integer() || (v.is_number_unsigned() && v.get<uint64_t>() > uint64_t(nodes.size())) ||
          (!v.is_number_unsigned() && (v.get<int64_t>() < -1 || v.get<int64_t>() > int64_t(nodes.size()))))
        r.fail(where + ".children[" + std::to_string(c) + "]",
               "must be a node index 0.." + std::to_string(nodes.size() - 1) + " or -1");
      node.children[c] = int(v.is_number_unsigned() ? int64_t(v.get<uint64_t>()) : v.get<int64_t>());
    }
    node.cpv_first = id32(r, n, "cpv_first", where);
    node.cpv_count = id32(r, n, "cpv_count", where);
    if (!r.member(n, "visible", where).is_null()) {
      node.has_visible = true;
      node.visible = readIds(r, n, "visible", where, index.scene_objects);
    }
    index.nodes.push_back(node);
  }
  checkNodes(r, index);
  return index;
}

}  // namespace farfield::store
