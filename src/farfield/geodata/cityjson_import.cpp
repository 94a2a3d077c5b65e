// CityJSON import. The document is read with nlohmann::json and walked defensively: every array is checked before
// use, so a malformed object or face is skipped and counted instead of throwing halfway through the city. Only a
// document that cannot be CityJSON at all (bad JSON, wrong type, unknown version, unusable vertex list or
// transform) is an error.
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
#include "farfield/geodata/triangulate.h"

namespace farfield::geodata {

namespace {

using Json = nlohmann::json;

// Skip reasons.
constexpr const char* kBadIndex = "faces with vertex indices out of range or not integers";
constexpr const char* kBadVertex = "faces using malformed vertices";
constexpr const char* kTooFew = "faces with fewer than 3 vertices";
constexpr const char* kNoArea = "faces without area";
constexpr const char* kMalformedSurface = "malformed faces (not arrays of rings)";
constexpr const char* kMalformedGeometry = "malformed geometries";
constexpr const char* kUnsupportedGeometry = "geometries of unsupported type (points, lines)";
constexpr const char* kTemplates = "geometry instances (templates not supported)";
constexpr const char* kNoGeometry = "objects without usable geometry";
constexpr const char* kLodFiltered = "objects without geometry at the requested LoD";
constexpr const char* kMalformedObject = "malformed city objects";

enum class Category { Building, BuildingPart, Ground, Other };

// Colour classes: one material each.
enum SurfaceClass : int {
  kWall = 0, kRoof, kGroundSurface, kRoad, kLand, kVegetation, kWater, kTerrain, kStructure, kClassCount
};

struct ClassStyle {
  const char* name;
  Vec4 colour;
};
constexpr ClassStyle kStyles[kClassCount] = {
    {"wall", {0.86f, 0.82f, 0.74f, 1.0f}},       {"roof", {0.72f, 0.32f, 0.24f, 1.0f}},
    {"ground surface", {0.38f, 0.36f, 0.34f, 1.0f}}, {"road", {0.33f, 0.33f, 0.35f, 1.0f}},
    {"land use", {0.66f, 0.68f, 0.50f, 1.0f}},   {"vegetation", {0.32f, 0.55f, 0.27f, 1.0f}},
    {"water", {0.26f, 0.46f, 0.70f, 1.0f}},      {"terrain", {0.58f, 0.52f, 0.42f, 1.0f}},
    {"structure", {0.62f, 0.62f, 0.64f, 1.0f}},
};

Category categoryOf(const std::string& type) {
  if (type == "Building") return Category::Building;
  if (type.rfind("Building", 0) == 0) return Category::BuildingPart;  // BuildingPart, BuildingInstallation, ...
  static const std::set<std::string> ground = {"Road",     "Railway",    "TransportSquare", "Waterway",
                                               "LandUse",  "PlantCover", "WaterBody",       "TINRelief"};
  if (ground.count(type)) return Category::Ground;
  return Category::Other;
}

// The colour class of an object type's surfaces when no semantics say otherwise (buildings: by normal).
SurfaceClass defaultClass(const std::string& type) {
  if (type == "Road" || type == "Railway" || type == "TransportSquare") return kRoad;
  if (type == "LandUse") return kLand;
  if (type == "PlantCover" || type == "SolitaryVegetationObject") return kVegetation;
  if (type == "WaterBody" || type == "Waterway") return kWater;
  if (type == "TINRelief") return kTerrain;
  return kStructure;
}

std::optional<SurfaceClass> semanticClass(const std::string& s) {
  if (s == "RoofSurface") return kRoof;
  if (s == "WallSurface" || s == "ClosureSurface" || s == "OuterCeilingSurface" || s == "Window" || s == "Door" ||
      s == "InteriorWallSurface" || s == "CeilingSurface")
    return kWall;
  if (s == "GroundSurface" || s == "OuterFloorSurface" || s == "FloorSurface") return kGroundSurface;
  if (s == "TrafficArea" || s == "TransportationMarking" || s == "TransportationHole") return kRoad;
  if (s == "AuxiliaryTrafficArea") return kLand;
  if (s == "WaterSurface" || s == "WaterGroundSurface" || s == "WaterClosureSurface") return kWater;
  return std::nullopt;
}

std::optional<double> lodOf(const Json& g) {
  auto it = g.find("lod");
  if (it == g.end()) return std::nullopt;
  if (it->is_number()) return it->get<double>();
  if (it->is_string()) {
    const std::string s = it->get<std::string>();
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (end != s.c_str()) return v;
  }
  return std::nullopt;
}

// Output meshes of one scene object, one per surface class.
struct ObjectMeshes {
  scene::Mesh meshes[kClassCount];
  std::vector<Vec2> hull_points;
};

struct Importer {
  const std::string& path;
  const CityJsonImportOptions& options;
  CityJsonStats& st;
  std::vector<DVec3> vertices;  // transformed, in file coordinates
  std::vector<char> vertex_ok;
  DVec3 origin{0.0};
  DVec3 used_min{std::numeric_limits<double>::max()}, used_max{std::numeric_limits<double>::lowest()};

  void skip(const char* reason, size_t n = 1) { st.skipped[reason] += n; }

  // One surface: [outer ring, hole, ...], each ring an array of vertex indices.
  void surface(const Json& s, std::optional<SurfaceClass> semantic, SurfaceClass fallback, bool by_normal,
               ObjectMeshes& out) {
    if (!s.is_array() || s.empty()) return skip(kMalformedSurface);
    std::vector<std::vector<DVec3>> rings;
    rings.reserve(s.size());
    for (size_t r = 0; r < s.size(); ++r) {
      const Json& ring = s[r];
      if (!ring.is_array()) return skip(kMalformedSurface);
      std::vector<DVec3> pts;
      pts.reserve(ring.size());
      for (const Json& idx : ring) {
        if (!idx.is_number_integer()) return skip(kBadIndex);
        const int64_t i = idx.get<int64_t>();
        if (i < 0 || uint64_t(i) >= vertices.size()) return skip(kBadIndex);
        if (!vertex_ok[size_t(i)]) return skip(kBadVertex);
        pts.push_back(vertices[size_t(i)] - origin);
      }
      // A repeated closing vertex is tolerated.
      if (pts.size() > 3 && pts.front() == pts.back()) pts.pop_back();
      if (pts.size() < 3) {
        if (r == 0) return skip(kTooFew);
        continue;  // a degenerate hole is dropped, the face kept
      }
      rings.push_back(std::move(pts));
    }
    PolygonTriangulation t;
    DVec3 n(0.0, 0.0, 1.0);
    if (!triangulateFace3(rings, t, &n)) return skip(kNoArea);

    SurfaceClass cls = fallback;
    if (semantic) {
      cls = *semantic;
      ++st.semantic_surfaces;
    } else if (by_normal) {
      cls = n.z > 0.3 ? kRoof : (n.z < -0.7 ? kGroundSurface : kWall);
      ++st.inferred_surfaces;
    }
    scene::Mesh& m = out.meshes[cls];
    const uint32_t first = uint32_t(m.positions.size());
    const Vec3 normal = Vec3(n);
    for (const auto& ring : rings)
      for (const DVec3& p : ring) {
        m.positions.emplace_back(Vec3(p));
        m.normals.push_back(normal);
        out.hull_points.emplace_back(float(p.x), float(p.y));
        used_min = glm::min(used_min, p + origin);
        used_max = glm::max(used_max, p + origin);
      }
    for (const DVec3& p : t.extra) {
      m.positions.emplace_back(Vec3(p));
      m.normals.push_back(normal);
    }
    for (uint32_t i : t.indices) m.indices.push_back(first + i);
    ++st.surfaces;
    st.holes += rings.size() - 1;
    st.triangles += t.indices.size() / 3;
  }

  // Semantic class of surface k from a (possibly nested) "values" entry and the "surfaces" list.
  std::optional<SurfaceClass> semanticOf(const Json* values, size_t k, const Json* surfaces) const {
    if (!values || !values->is_array() || k >= values->size() || !surfaces || !surfaces->is_array())
      return std::nullopt;
    const Json& v = (*values)[k];
    if (!v.is_number_integer()) return std::nullopt;
    const int64_t i = v.get<int64_t>();
    if (i < 0 || uint64_t(i) >= surfaces->size()) return std::nullopt;
    const Json& s = (*surfaces)[size_t(i)];
    if (!s.is_object() || !s.contains("type") || !s["type"].is_string()) return std::nullopt;
    return semanticClass(s["type"].get<std::string>());
  }

  // A list of surfaces (a MultiSurface, a CompositeSurface or one shell of a solid).
  void surfaceList(const Json& list, const Json* values, const Json* surfaces, SurfaceClass fallback, bool by_normal,
                   ObjectMeshes& out) {
    if (!list.is_array()) return skip(kMalformedGeometry);
    for (size_t k = 0; k < list.size(); ++k)
      surface(list[k], semanticOf(values, k, surfaces), fallback, by_normal, out);
  }

  static const Json* child(const Json* values, size_t i) {
    if (!values || !values->is_array() || i >= values->size()) return nullptr;
    return &(*values)[i];
  }

  void geometry(const Json& g, const std::string& object_type, ObjectMeshes& out) {
    if (!g.is_object() || !g.contains("type") || !g["type"].is_string()) return skip(kMalformedGeometry);
    const std::string type = g["type"].get<std::string>();
    if (type == "GeometryInstance") return skip(kTemplates);
    if (!g.contains("boundaries")) return skip(kMalformedGeometry);
    const Json& b = g["boundaries"];
    const Json* surfaces = nullptr;
    const Json* values = nullptr;
    if (auto it = g.find("semantics"); it != g.end() && it->is_object()) {
      if (auto s = it->find("surfaces"); s != it->end()) surfaces = &*s;
      if (auto v = it->find("values"); v != it->end()) values = &*v;
    }
    const Category cat = categoryOf(object_type);
    const bool building = cat == Category::Building || cat == Category::BuildingPart;
    const SurfaceClass fallback = building ? kWall : defaultClass(object_type);
    if (type == "MultiSurface" || type == "CompositeSurface") {
      surfaceList(b, values, surfaces, fallback, building, out);
    } else if (type == "Solid") {
      if (!b.is_array()) return skip(kMalformedGeometry);
      for (size_t shell = 0; shell < b.size(); ++shell)
        surfaceList(b[shell], child(values, shell), surfaces, fallback, building, out);
    } else if (type == "MultiSolid" || type == "CompositeSolid") {
      if (!b.is_array()) return skip(kMalformedGeometry);
      for (size_t solid = 0; solid < b.size(); ++solid) {
        if (!b[solid].is_array()) {
          skip(kMalformedGeometry);
          continue;
        }
        const Json* sv = child(values, solid);
        for (size_t shell = 0; shell < b[solid].size(); ++shell)
          surfaceList(b[solid][shell], child(sv, shell), surfaces, fallback, building, out);
      }
    } else if (type == "MultiPoint" || type == "MultiLineString") {
      skip(kUnsupportedGeometry);
    } else {
      skip(kMalformedGeometry);
    }
  }

  // The geometries of one object to import: those of the highest LoD allowed.
  std::vector<const Json*> chooseGeometries(const Json& object, bool* lod_filtered) const {
    *lod_filtered = false;
    std::vector<const Json*> out;
    auto it = object.find("geometry");
    if (it == object.end() || !it->is_array() || it->empty()) return out;
    std::optional<double> best;
    bool any = false;
    for (const Json& g : *it) {
      if (!g.is_object()) continue;
      const std::optional<double> lod = lodOf(g);
      if (options.max_lod && lod && *lod > *options.max_lod + 1e-9) continue;
      any = true;
      if (lod && (!best || *lod > *best)) best = lod;
    }
    if (!any) {
      *lod_filtered = true;
      return out;
    }
    for (const Json& g : *it) {
      if (!g.is_object()) continue;
      const std::optional<double> lod = lodOf(g);
      if (options.max_lod && lod && *lod > *options.max_lod + 1e-9) continue;
      if (!best || !lod || std::abs(*lod - *best) < 1e-9) out.push_back(&g);
    }
    return out;
  }
};

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

  Importer im{path, options, st, {}, {}, DVec3(0.0)};
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
        if (c.is_string() && objects.contains(c.get<std::string>())) children_of[it.key()].push_back(c.get<std::string>());
    if (auto pa = o.find("parents"); pa != o.end() && pa->is_array())
      for (const Json& p : *pa)
        if (p.is_string() && objects.contains(p.get<std::string>())) children_of[p.get<std::string>()].push_back(it.key());
  }
  for (auto& [id, list] : children_of) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }

  scene::Scene& scene = result.scene;
  uint32_t materials[kClassCount];
  for (int c = 0; c < kClassCount; ++c) {
    scene::Material m;
    m.name = kStyles[c].name;
    m.base_color = kStyles[c].colour;
    materials[c] = scene.addMaterial(std::move(m));
  }

  Progress progress("import " + path, objects.size());
  for (auto it = objects.begin(); it != objects.end(); ++it) {
    progress.advance();
    const Json& root = it.value();
    if (!root.is_object()) {
      im.skip(kMalformedObject);
      continue;
    }
    if (has_live_parent(root)) continue;
    const std::string root_type = root.contains("type") && root["type"].is_string() ? root["type"].get<std::string>() : "";
    if (root_type.empty()) {
      im.skip(kMalformedObject);
      continue;
    }
    const Category root_cat = categoryOf(root_type);
    if (root_cat == Category::Ground && !options.ground_objects) continue;
    if (root_cat == Category::Other && !options.other_objects) continue;

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
        if (depth > 0 && st.triangles > before && categoryOf(type) == Category::BuildingPart && type == "BuildingPart")
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
    for (int c = 0; c < kClassCount; ++c) {
      scene::Mesh& m = meshes.meshes[c];
      if (m.indices.empty()) continue;
      object.parts.push_back({scene.addMesh(std::move(m)), materials[c]});
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
      case Category::Building: ++st.buildings; break;
      case Category::BuildingPart: ++st.buildings; break;  // a part without its building stands for one
      case Category::Ground: ++st.ground_objects; break;
      case Category::Other: ++st.other_objects; break;
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
