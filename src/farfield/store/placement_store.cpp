// The placement database (format in placement_store.h).
//
// Why the plan is re-derived and not stored: a LayeredPlan is some thirty numbers per impostor and per layer, all
// functions of four inputs; storing them would give the reader two sources of truth to reconcile. planLayered is pure
// float and double arithmetic in a fixed order, so the same inputs give the same plan bit for bit, and the image sizes
// on disk check that it did.
//
// Why the writer reads its own JSON back before writing: a database that its own reader refuses is worse than no
// database (the old one would be replaced by it), so every rule is checked once, by the reader's code, before the
// first byte of the index is written.
//
// Why PNG for the layers: the layers are mostly transparent (alpha 0 outside the slab's objects) and compress well;
// ids are packed in RGBA like the impostor store's layer views (PNG keeps them exactly).
#include "farfield/store/placement_store.h"

#include "farfield/store/generation_names.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <set>

#include "farfield/core/error.h"
#include "farfield/image/png_io.h"
#include "farfield/store/json_fields.h"

namespace fs = std::filesystem;

namespace farfield::store {

namespace {

constexpr char kImpostorDir[] = "impostors";

std::string joinPath(const std::string& dir, const std::string& relative) {
  return (fs::path(dir) / relative).string();
}

// fsync of a directory, so that the renames into it are durable before the index that names the files is.
void syncDirectory(const std::string& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_CLOEXEC | O_DIRECTORY);
  if (fd < 0) throw Error(dir, std::string("cannot open to sync: ") + std::strerror(errno));
  if (::fsync(fd) != 0) {
    const int error = errno;
    ::close(fd);
    throw Error(dir, std::string("fsync failed: ") + std::strerror(error));
  }
  ::close(fd);
}

void createDirectory(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(dir.string(), "cannot create the directory: " + ec.message());
}

// image::writePng writes to a path: the PNG is encoded into NAME.tmp, read back and then written through
// writeFileAtomic, which reuses NAME.tmp (so the file operation hook sees every step that matters and a killed write
// leaves at most a temporary that the next write removes).
FileCheck writePngFile(const std::string& path, const image::ColorImage& image) {
  const std::string tmp = path + ".tmp";
  image::writePng(tmp, image);
  return writeFileAtomic(path, readCheckedFile(tmp, FileCheck{}, ""), false);
}

image::ColorImage packIds(const image::IdImage& ids) {
  image::ColorImage packed(ids.width(), ids.height());
  for (size_t i = 0; i < packed.pixelCount(); ++i) {
    const uint32_t id = ids.pixels()[i];
    packed.pixels()[i] = image::Rgba8(uint8_t(id), uint8_t(id >> 8), uint8_t(id >> 16), uint8_t(id >> 24));
  }
  return packed;
}

image::IdImage unpackIds(const image::ColorImage& packed) {
  image::IdImage ids(packed.width(), packed.height(), 0u);
  for (size_t i = 0; i < packed.pixelCount(); ++i) {
    const image::Rgba8 c = packed.pixels()[i];
    ids.pixels()[i] = uint32_t(c.r) | uint32_t(c.g) << 8 | uint32_t(c.b) << 16 | uint32_t(c.a) << 24;
  }
  return ids;
}

// A layer file named by the index: size and CRC-32 checked before the PNG is decoded; errors name the record.
image::ColorImage readLayerPng(const std::string& path, const FileCheck& check, const std::string& record) {
  readCheckedFile(path, check, record);
  try {
    return image::readPng(path);
  } catch (const Error& e) {
    throw Error(record + ": " + e.what());
  }
}

std::string sizeText(int width, int height) { return std::to_string(width) + "x" + std::to_string(height); }

std::string recordName(uint32_t id) { return "impostor " + std::to_string(id); }

// ---- JSON -------------------------------------------------------------------------------------------------------

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

std::string placedLayerFileName(uint64_t generation, uint32_t id, size_t layer, bool ids) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "i%06u.%02zu%s", id, layer, ids ? ".ids.png" : ".png");
  return std::string(kImpostorDir) + "/" + generationPrefix(generation) + buf;
}

StoredPlacedImpostor writePlacedImpostor(const std::string& dir, uint64_t generation, uint32_t id, uint32_t node,
                                         const std::vector<uint32_t>& objects,
                                         const impostor::LayeredImpostor& impostor, const Box3& box,
                                         const Shaft& shaft, const ErrorBound& bound,
                                         const impostor::LayeredOptions& options) {
  StoredPlacedImpostor out;
  out.id = id;
  out.node = node;
  out.objects = objects;
  std::sort(out.objects.begin(), out.objects.end());  // a set: the caller's order (e.g. a BVH's) carries no meaning
  out.box = box;
  out.shaft = shaft;
  out.bound = bound;
  out.options = options;
  out.bytes = impostor.plan.bytes();
  out.capture_ms = impostor.capture_ms;
  out.record = recordName(id);
  const auto fail = [&](const std::string& what) { throw Error(dir, out.record + ": " + what); };
  if (generation == 0) fail("generation 0 (the data files of a placement database have generations 1, 2, ...)");
  if (out.objects.empty() || out.objects.front() == 0 ||
      std::adjacent_find(out.objects.begin(), out.objects.end()) != out.objects.end())
    fail("objects must be at least one id >= 1, without repeats");
  impostor::LayeredPlan plan;
  try {
    plan = impostor::planLayered(box, shaft, bound, options);
  } catch (const Error& e) {
    fail(std::string("its box, shaft, bound and options give no layered plan: ") + e.what());
  }
  const size_t count = plan.layers.size();
  if (impostor.layers.size() != count || impostor.plan.layers.size() != count)
    fail("the impostor has " + std::to_string(impostor.layers.size()) + " layers (its plan " +
         std::to_string(impostor.plan.layers.size()) + "), the plan of its box, shaft, bound and options " +
         std::to_string(count) + " (was it captured with other inputs?)");
  // The part of each captured image the impostor holds (all of it when not cropped).
  std::vector<impostor::LayerCrop> crops;
  for (size_t l = 0; l < count; ++l) {
    const impostor::LayerPlan& lp = impostor.plan.layers[l];
    crops.push_back(impostor.plan.cropped ? impostor::LayerCrop{lp.crop_x, lp.crop_y, lp.width, lp.height}
                                          : impostor::LayerCrop{0, 0, plan.layers[l].width, plan.layers[l].height});
  }
  try {
    impostor::cropLayers(plan, crops);
  } catch (const Error& e) {
    fail(e.what());
  }
  for (size_t l = 0; l < count; ++l) {
    const impostor::LayerPlan& p = plan.layers[l];
    const impostor::Layer& layer = impostor.layers[l];
    const std::string at = "layer " + std::to_string(l) + ": ";
    if (impostor.plan.layers[l].width != p.width || impostor.plan.layers[l].height != p.height)
      fail(at + "the impostor's plan is " + sizeText(impostor.plan.layers[l].width, impostor.plan.layers[l].height) +
           ", the plan of its box, shaft, bound and options " + sizeText(p.width, p.height));
    if (layer.color.width() != p.width || layer.color.height() != p.height)
      fail(at + "colour image is " + sizeText(layer.color.width(), layer.color.height()) + ", the plan needs " +
           sizeText(p.width, p.height));
    if (options.id_textures && (layer.ids.width() != p.width || layer.ids.height() != p.height))
      fail(at + "id image is " + sizeText(layer.ids.width(), layer.ids.height()) + ", the plan needs " +
           sizeText(p.width, p.height));
    if (!options.id_textures && !layer.ids.empty()) fail(at + "has an id image but the options have no id_textures");
  }
  createDirectory(fs::path(dir) / kImpostorDir);
  for (size_t l = 0; l < count; ++l) {
    const impostor::Layer& layer = impostor.layers[l];
    StoredImpostorLayer s;
    s.texture = placedLayerFileName(generation, id, l, false);
    s.texture_check = writePngFile(joinPath(dir, s.texture), layer.color);
    if (options.id_textures) {
      s.ids = placedLayerFileName(generation, id, l, true);
      s.ids_check = writePngFile(joinPath(dir, s.ids), packIds(layer.ids));
    }
    s.data_texels = layer.data_texels;
    s.render_ms = layer.render_ms;
    s.crop = crops[l];
    out.layers.push_back(std::move(s));
  }
  return out;
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
  if (fs::is_directory(data, ec)) syncDirectory(data.string());
  syncDirectory(dir);
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

namespace {

// storedLayeredPlan, its errors naming `source` (the index file, when known) and the record.
impostor::LayeredPlan storedPlanIn(const StoredPlacedImpostor& imp, const std::string& source) {
  const std::string record = imp.record.empty() ? recordName(imp.id) : imp.record;
  impostor::LayeredPlan plan;
  try {
    plan = impostor::planLayered(imp.box, imp.shaft, imp.bound, imp.options);
  } catch (const Error& e) {
    throw Error(source, record + ": its box, shaft, bound and options give no layered plan: " + e.what());
  }
  if (plan.layers.size() != imp.layers.size())
    throw Error(source, record + ": lists " + std::to_string(imp.layers.size()) + " layers, its plan has " +
                            std::to_string(plan.layers.size()));
  std::vector<impostor::LayerCrop> crops;
  for (const StoredImpostorLayer& s : imp.layers) crops.push_back(s.crop);
  try {
    impostor::cropLayers(plan, crops);
  } catch (const Error& e) {
    throw Error(source, record + ": " + e.what());
  }
  return plan;
}

}  // namespace

impostor::LayeredPlan storedLayeredPlan(const StoredPlacedImpostor& imp) {
  return storedPlanIn(imp, "placement database");
}

impostor::LayeredImpostor loadPlacedImpostor(const std::string& dir, const StoredPlacedImpostor& imp) {
  const std::string record = imp.record.empty() ? recordName(imp.id) : imp.record;
  const std::string index_file = joinPath(dir, kPlacementIndexFile);
  impostor::LayeredImpostor out;
  out.plan = storedPlanIn(imp, index_file);
  out.capture_ms = imp.capture_ms;
  for (size_t l = 0; l < imp.layers.size(); ++l) {
    const StoredImpostorLayer& s = imp.layers[l];
    const impostor::LayerPlan& p = out.plan.layers[l];
    const std::string at = record + " layer " + std::to_string(l);
    impostor::Layer layer;
    const std::string texture_file = joinPath(dir, s.texture);
    layer.color = readLayerPng(texture_file, s.texture_check, at + " texture");
    if (layer.color.width() != p.width || layer.color.height() != p.height)
      throw Error(texture_file, at + " texture: " + sizeText(layer.color.width(), layer.color.height()) +
                                    " but the plan needs " + sizeText(p.width, p.height));
    if (s.ids.empty() == imp.options.id_textures)
      throw Error(index_file, at + (imp.options.id_textures ? ": no ids file but the options have id_textures"
                                                            : ": an ids file but the options have no id_textures"));
    if (!s.ids.empty()) {
      const std::string ids_file = joinPath(dir, s.ids);
      const image::ColorImage packed = readLayerPng(ids_file, s.ids_check, at + " ids");
      if (packed.width() != p.width || packed.height() != p.height)
        throw Error(ids_file, at + " ids: " + sizeText(packed.width(), packed.height()) + " but the plan needs " +
                                  sizeText(p.width, p.height));
      layer.ids = unpackIds(packed);
    }
    layer.data_texels = s.data_texels;
    layer.render_ms = s.render_ms;
    out.layers.push_back(std::move(layer));
  }
  impostor::measureLayerCover(out);  // what GpuLayeredImpostor will draw of each layer
  return out;
}

std::optional<uint32_t> lookupLeaf(const PlacementIndex& index, const Vec3& eye) {
  const std::vector<StoredViewSpaceNode>& nodes = index.nodes;
  if (nodes.empty() || !nodes[0].box.contains(eye)) return std::nullopt;
  size_t at = 0;
  while (nodes[at].children[0] >= 0) {
    const int lower = nodes[at].children[0], upper = nodes[at].children[1];
    // Guards for an index built in memory and never checked (a read index always passes them).
    if (lower <= int(at) || upper <= int(at) || size_t(lower) >= nodes.size() || size_t(upper) >= nodes.size())
      return std::nullopt;
    at = nodes[size_t(lower)].box.contains(eye) ? size_t(lower) : size_t(upper);
  }
  return uint32_t(at);
}

std::optional<uint32_t> lookupCpv(const PlacementIndex& index, const Vec3& eye, const Vec3& dir) {
  const std::optional<uint32_t> leaf = lookupLeaf(index, eye);
  return leaf ? cpvInLeaf(index, *leaf, eye, dir) : std::nullopt;
}

std::optional<uint32_t> cpvInLeaf(const PlacementIndex& index, uint32_t leaf_index, const Vec3& eye, const Vec3& dir) {
  if (leaf_index >= index.nodes.size()) return std::nullopt;
  const StoredViewSpaceNode& leaf = index.nodes[leaf_index];
  const uint64_t end = std::min<uint64_t>(uint64_t(leaf.cpv_first) + leaf.cpv_count, index.cpvs.size());
  for (uint64_t k = leaf.cpv_first; k < end; ++k)
    if (index.cpvs[k].region.contains(eye) && index.cpvs[k].vdi.contains(dir)) return uint32_t(k);
  return std::nullopt;
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
