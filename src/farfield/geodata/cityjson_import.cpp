// CityJSON import. The document is read with nlohmann::json and walked defensively: every array is checked before
// use, so a malformed object or face is skipped and counted instead of throwing halfway through the city. Only a
// document that cannot be CityJSON at all (bad JSON, wrong type, unknown version, unusable vertex list or
// transform) is an error.
// Here: the document, its vertices and the walk over its objects; cityjson_importer.h lists the other parts.
#include "farfield/geodata/cityjson_import.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <set>
#include <sstream>
#include <unordered_map>

#include <nlohmann/json.hpp>

#include "farfield/core/error.h"
#include "farfield/core/polygon2d.h"
#include "farfield/core/progress.h"
#include "farfield/core/timer.h"
#include "farfield/geodata/cityjson_importer.h"
#include "farfield/scene/import.h"

namespace farfield::geodata {

namespace {

using namespace cityjson_import;

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "cannot open file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

DVec3 readTriple(const Json& j, const std::string& path, const char* what) {
  if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number())
    throw Error(path, std::string("transform: \"") + what + "\" must be an array of three numbers");
  const DVec3 v(j[0].get<double>(), j[1].get<double>(), j[2].get<double>());
  if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
    throw Error(path, std::string("transform: \"") + what + "\" must hold finite numbers");
  return v;
}

}  // namespace

size_t CityJsonStats::skippedTotal() const {
  size_t n = 0;
  for (const auto& [reason, count] : skipped) n += count;
  return n;
}

CityJsonScene importCityJson(const std::string& path, const CityJsonImportOptions& options) {
  CityJsonScene result;
  CityJsonStats& st = result.stats;
  Stopwatch clock;

  const std::string text = readText(path);
  if (text.empty()) throw Error(path, "empty file");
  Json doc;
  try {
    doc = Json::parse(text);
  } catch (const Json::exception& e) {
    throw Error(path, std::string("not valid JSON: ") + e.what());
  }
  if (!doc.is_object() || !doc.contains("type") || doc["type"] != "CityJSON")
    throw Error(path, "not a CityJSON document (expected an object with \"type\": \"CityJSON\")");
  if (!doc.contains("version") || !doc["version"].is_string())
    throw Error(path, "no \"version\" string (supported CityJSON versions: 1.0, 1.1, 2.0)");
  st.version = doc["version"].get<std::string>();
  if (st.version != "1.0" && st.version != "1.1" && st.version != "2.0")
    throw Error(path, "unsupported CityJSON version '" + st.version + "' (supported: 1.0, 1.1, 2.0)");

  DVec3 scale(1.0), translate(0.0);
  if (auto it = doc.find("transform"); it != doc.end()) {
    if (!it->is_object() || !it->contains("scale") || !it->contains("translate"))
      throw Error(path, "transform: expected an object with \"scale\" and \"translate\"");
    scale = readTriple((*it)["scale"], path, "scale");
    translate = readTriple((*it)["translate"], path, "translate");
    if (scale.x == 0.0 || scale.y == 0.0 || scale.z == 0.0) throw Error(path, "transform: \"scale\" must not be 0");
  } else if (st.version != "1.0") {
    // Required from 1.1 on; without it the vertices are taken as they are.
  }

  auto vit = doc.find("vertices");
  if (vit == doc.end() || !vit->is_array()) throw Error(path, "no \"vertices\" array");
  auto oit = doc.find("CityObjects");
  if (oit == doc.end() || !oit->is_object()) throw Error(path, "no \"CityObjects\" object");
  if (auto md = doc.find("metadata"); md != doc.end() && md->is_object()) {
    if (auto rs = md->find("referenceSystem"); rs != md->end() && rs->is_string()) {
      const std::string crs = rs->get<std::string>();
      result.reference.description = crs;
      const size_t pos = crs.find("EPSG/");
      if (pos != std::string::npos) {
        // ".../def/crs/EPSG/0/7415" -> "EPSG:7415"
        const size_t last = crs.find_last_of('/');
        result.reference.crs = "EPSG:" + crs.substr(last + 1);
      } else {
        result.reference.crs = crs;
      }
    }
  }
  if (result.reference.crs.empty()) result.reference.crs = "unknown (CityJSON without referenceSystem)";

  Importer im{path, options, st};
  const Json& verts = *vit;
  st.vertices = verts.size();
  im.vertices.resize(verts.size());
  im.vertex_ok.assign(verts.size(), 0);
  DVec3 lo(std::numeric_limits<double>::max()), hi(std::numeric_limits<double>::lowest());
  for (size_t i = 0; i < verts.size(); ++i) {
    const Json& v = verts[i];
    if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number()) {
      ++st.bad_vertices;
      continue;
    }
    const DVec3 p = DVec3(v[0].get<double>(), v[1].get<double>(), v[2].get<double>()) * scale + translate;
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      ++st.bad_vertices;
      continue;
    }
    im.vertices[i] = p;
    im.vertex_ok[i] = 1;
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  if (st.bad_vertices == verts.size()) throw Error(path, "no usable vertex (each must be an array of 3 numbers)");
  im.origin = DVec3(std::round(0.5 * (lo.x + hi.x)), std::round(0.5 * (lo.y + hi.y)), 0.0);
  result.reference.origin = im.origin;
  st.read_s = clock.seconds();
  clock.restart();

  // Root objects: those without parents (or whose parents are missing); children are merged into their root.
  const Json& objects = *oit;
  st.city_objects = objects.size();
  auto has_live_parent = [&](const Json& o) {
    auto p = o.find("parents");
    if (p == o.end() || !p->is_array()) return false;
    for (const Json& id : *p)
      if (id.is_string() && objects.contains(id.get<std::string>())) return true;
    return false;
  };

  // Children of each object, from both sides of the link ("children" of the parent, "parents" of the child), so
  // that a file listing only one side still keeps its parts.
  std::unordered_map<std::string, std::vector<std::string>> children_of;
  for (auto it = objects.begin(); it != objects.end(); ++it) {
    const Json& o = it.value();
    if (!o.is_object()) continue;
    if (auto ch = o.find("children"); ch != o.end() && ch->is_array())
      for (const Json& c : *ch)
        if (c.is_string() && objects.contains(c.get<std::string>()))
          children_of[it.key()].push_back(c.get<std::string>());
    if (auto pa = o.find("parents"); pa != o.end() && pa->is_array())
      for (const Json& p : *pa)
        if (p.is_string() && objects.contains(p.get<std::string>()))
          children_of[p.get<std::string>()].push_back(it.key());
  }
  for (auto& [id, list] : children_of) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }

  scene::Scene& scene = result.scene;
  CityMaterials materials(scene);
  scene::TextureFiles texture_files(st.import);
  im.materials = &materials;
  im.texture_files = &texture_files;
  readAppearance(doc, objects, path, options, im.app, st);

  Progress progress("import " + path, objects.size());
  for (auto it = objects.begin(); it != objects.end(); ++it) {
    progress.advance();
    const Json& root = it.value();
    if (!root.is_object()) {
      im.skip(kMalformedObject);
      continue;
    }
    if (has_live_parent(root)) continue;
    const std::string root_type =
        root.contains("type") && root["type"].is_string() ? root["type"].get<std::string>() : "";
    if (root_type.empty()) {
      im.skip(kMalformedObject);
      continue;
    }
    const CityCategory root_cat = cityCategoryOf(root_type);
    if (root_cat == CityCategory::Ground && !options.ground_objects) continue;
    if (root_cat == CityCategory::Other && !options.other_objects) continue;

    ObjectMeshes meshes;
    size_t parts = 0;
    bool lod_filtered_any = false;
    std::map<std::string, size_t> types;
    // Depth-first over the object and its descendants (a visited set guards against cycles in bad files).
    std::set<std::string> visited;
    std::function<void(const std::string&, const Json&, int)> visit = [&](const std::string& id, const Json& o,
                                                                          int depth) {
      if (depth > 32 || !visited.insert(id).second || !o.is_object()) return;
      const std::string type = o.contains("type") && o["type"].is_string() ? o["type"].get<std::string>() : "";
      try {
        bool lod_filtered = false;
        const std::vector<const Json*> geometries = im.chooseGeometries(o, &lod_filtered);
        lod_filtered_any |= lod_filtered;
        const uint64_t before = st.triangles;
        for (const Json* g : geometries) im.geometry(*g, type, meshes);
        if (st.triangles > before || depth == 0) ++types[type];
        if (depth > 0 && st.triangles > before && type == "BuildingPart")
          ++parts;
      } catch (const Json::exception&) {
        im.skip(kMalformedObject);
      }
      if (auto ch = children_of.find(id); ch != children_of.end())
        for (const std::string& c : ch->second) visit(c, objects.at(c), depth + 1);
    };
    visit(it.key(), root, 0);

    scene::Object object;
    object.name = it.key();
    for (auto& [material, m] : meshes.meshes) {
      if (m.indices.empty()) continue;
      object.parts.push_back({scene.addMesh(std::move(m)), material});
    }
    if (object.parts.empty()) {
      im.skip(lod_filtered_any ? kLodFiltered : kNoGeometry);
      continue;
    }
    object.footprint = convexHull(meshes.hull_points);
    scene.addObject(std::move(object));
    for (const auto& [type, n] : types) st.objects_by_type[type] += n;
    st.building_parts += parts;
    switch (root_cat) {
      case CityCategory::Building: ++st.buildings; break;
      case CityCategory::BuildingPart: ++st.buildings; break;  // a part without its building stands for one
      case CityCategory::Ground: ++st.ground_objects; break;
      case CityCategory::Other: ++st.other_objects; break;
    }
  }
  progress.finish();
  scene.updateBounds();
  st.build_s = clock.seconds();
  if (scene.objects.empty()) {
    std::string why;
    for (const auto& [reason, n] : st.skipped) why += (why.empty() ? "" : ", ") + std::to_string(n) + " " + reason;
    throw Error(path, "no usable surface in " + std::to_string(st.city_objects) + " city objects" +
                          (why.empty() ? std::string() : " (skipped: " + why + ")"));
  }
  result.file_min = im.used_min;
  result.file_max = im.used_max;
  return result;
}

}  // namespace farfield::geodata
