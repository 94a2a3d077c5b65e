// CityJSON import. The document is read with nlohmann::json and walked defensively: every array is checked before
// use, so a malformed object or face is skipped and counted instead of throwing halfway through the city. Only a
// document that cannot be CityJSON at all (bad JSON, wrong type, unknown version, unusable vertex list or
// transform) is an error.
#include "farfield/geodata/cityjson_import.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
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
#include "farfield/geodata/city_surfaces.h"
#include "farfield/geodata/triangulate.h"
#include "farfield/scene/import.h"

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

// Output meshes of one scene object, one per material (class colour, texture or appearance material).
struct ObjectMeshes {
  std::map<uint32_t, scene::Mesh> meshes;
  std::vector<Vec2> hull_points;
};

// A geometry's per-surface arrays, stepped down in parallel through solids and shells: semantics "values",
// texture "values" of the chosen theme (one level deeper: rings) and material "values" (or one "value" for all).
struct SurfaceRefs {
  const Json* semantics = nullptr;
  const Json* texture = nullptr;
  const Json* material = nullptr;
  std::optional<int64_t> material_all;

  static const Json* child(const Json* values, size_t i) {
    if (!values || !values->is_array() || i >= values->size()) return nullptr;
    return &(*values)[i];
  }
  SurfaceRefs at(size_t i) const { return {child(semantics, i), child(texture, i), child(material, i), material_all}; }
};

// appearance: the file's textures, texture coordinates and materials, and the themes chosen.
struct Appearance {
  const Json* textures = nullptr;          // [{"type", "image", ...}]
  std::vector<std::optional<Vec2>> uvs;    // "vertices-texture", v flipped to Farfield's top-left origin
  const Json* materials = nullptr;         // [{"name", "diffuseColor", "transparency", ...}]
  std::string texture_theme, material_theme;
  std::vector<std::optional<uint32_t>> texture_materials;  // per texture index, once loaded
};

struct Importer {
  Importer(const std::string& p, const CityJsonImportOptions& o, CityJsonStats& s) : path(p), options(o), st(s) {}
  const std::string& path;
  const CityJsonImportOptions& options;
  CityJsonStats& st;
  std::vector<DVec3> vertices;  // transformed, in file coordinates
  std::vector<char> vertex_ok;
  DVec3 origin{0.0};
  DVec3 used_min{std::numeric_limits<double>::max()}, used_max{std::numeric_limits<double>::lowest()};
  Appearance app;
  CityMaterials* materials = nullptr;
  scene::TextureFiles* texture_files = nullptr;

  void skip(const char* reason, size_t n = 1) { st.skipped[reason] += n; }

  // The scene material of texture `t` (loaded on first use; a missing file gives the placeholder).
  std::optional<uint32_t> textureMaterial(int64_t t) {
    if (!app.textures || t < 0 || uint64_t(t) >= app.textures->size()) return std::nullopt;
    if (app.texture_materials.empty()) app.texture_materials.resize(app.textures->size());
    std::optional<uint32_t>& slot = app.texture_materials[size_t(t)];
    if (slot) return slot;
    const Json& tex = (*app.textures)[size_t(t)];
    std::string image = tex.is_object() && tex.contains("image") && tex["image"].is_string() ? tex["image"].get<std::string>()
                                                                                           : std::string();
    std::shared_ptr<const image::ColorImage> img;
    std::string file;
    if (image.empty()) {
      img = texture_files->placeholder("texture " + std::to_string(t), "no \"image\" string");
      image = "texture " + std::to_string(t);
    } else if (image.find("://") != std::string::npos) {
      img = texture_files->placeholder(image, "not a local file (URLs are not fetched)");
    } else {
      std::replace(image.begin(), image.end(), '\\', '/');
      const std::filesystem::path p = std::filesystem::path(image).is_absolute()
                                          ? std::filesystem::path(image)
                                          : std::filesystem::path(path).parent_path() / image;
      img = texture_files->load(image, p);
      if (!scene::TextureFiles::isPlaceholder(img)) file = p.string();
    }
    slot = materials->forTexture(image, img, file);
    return slot;
  }

  std::optional<uint32_t> appearanceMaterial(int64_t m) {
    if (!app.materials || m < 0 || uint64_t(m) >= app.materials->size()) return std::nullopt;
    const Json& mat = (*app.materials)[size_t(m)];
    if (!mat.is_object()) return std::nullopt;
    Vec4 rgba(0.8f, 0.8f, 0.8f, 1.0f);  // X3D's default diffuse colour
    if (auto d = mat.find("diffuseColor"); d != mat.end() && d->is_array() && d->size() == 3 &&
                                           (*d)[0].is_number() && (*d)[1].is_number() && (*d)[2].is_number())
      rgba = Vec4((*d)[0].get<float>(), (*d)[1].get<float>(), (*d)[2].get<float>(), 1.0f);
    if (auto tr = mat.find("transparency"); tr != mat.end() && tr->is_number())
      rgba.a = 1.0f - tr->get<float>();
    rgba = glm::clamp(rgba, Vec4(0.0f), Vec4(1.0f));
    if (!isFinite(Vec3(rgba)) || !std::isfinite(rgba.a)) return std::nullopt;
    const std::string name = mat.contains("name") && mat["name"].is_string() ? mat["name"].get<std::string>()
                                                                              : "material " + std::to_string(m);
    return materials->forColour("material " + std::to_string(m), name, rgba);
  }

  // Texture of a surface from its texture values (one [t, uv, uv, ...] per ring, or [null]): the material and the
  // uvs of each ring, or nothing when untextured or when the references do not fit the rings (counted).
  std::optional<uint32_t> surfaceTexture(const Json* tex, const std::vector<size_t>& ring_sizes,
                                         const std::vector<bool>& closing_dropped, CityFace& face) {
    if (!tex || !tex->is_array() || tex->empty()) return std::nullopt;
    const Json& first = (*tex)[0];
    if (!first.is_array() || first.empty() || first[0].is_null()) return std::nullopt;
    auto bad = [&]() -> std::optional<uint32_t> {
      ++st.bad_texture_references;
      face.uvs.clear();
      return std::nullopt;
    };
    if (!first[0].is_number_integer() || tex->size() != ring_sizes.size()) return bad();
    const int64_t t = first[0].get<int64_t>();
    face.uvs.assign(ring_sizes.size(), {});
    for (size_t r = 0; r < ring_sizes.size(); ++r) {
      const Json& ring = (*tex)[r];
      if (!ring.is_array() || ring.empty() || !ring[0].is_number_integer() || ring[0].get<int64_t>() != t) return bad();
      const size_t n = ring.size() - 1 - (closing_dropped[r] ? 1 : 0);
      if (n != ring_sizes[r]) return bad();
      for (size_t i = 0; i < n; ++i) {
        const Json& k = ring[i + 1];
        if (!k.is_number_integer()) return bad();
        const int64_t uv = k.get<int64_t>();
        if (uv < 0 || uint64_t(uv) >= app.uvs.size() || !app.uvs[size_t(uv)]) return bad();
        face.uvs[r].push_back(*app.uvs[size_t(uv)]);
      }
    }
    const std::optional<uint32_t> m = textureMaterial(t);
    if (!m) return bad();
    return m;
  }

  // One surface: [outer ring, hole, ...], each ring an array of vertex indices.
  void surface(const Json& s, const SurfaceRefs& refs, std::optional<SurfaceClass> semantic, SurfaceClass fallback,
               bool by_normal, ObjectMeshes& out) {
    if (!s.is_array() || s.empty()) return skip(kMalformedSurface);
    CityFace face;
    face.rings.reserve(s.size());
    std::vector<size_t> ring_sizes;
    std::vector<bool> closing_dropped;
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
      const bool closed = pts.size() > 3 && pts.front() == pts.back();
      if (closed) pts.pop_back();
      if (pts.size() < 3) {
        if (r == 0) return skip(kTooFew);
        // A degenerate hole is dropped, the face kept; its texture references then cannot be matched.
        ring_sizes.push_back(size_t(-1));
        closing_dropped.push_back(closed);
        continue;
      }
      ring_sizes.push_back(pts.size());
      closing_dropped.push_back(closed);
      face.rings.push_back(std::move(pts));
    }
    PolygonTriangulation t;
    DVec3 n(0.0, 0.0, 1.0);
    if (!triangulateCityFace(face, t, &n)) return skip(kNoArea);

    SurfaceClass cls = fallback;
    if (semantic) {
      cls = *semantic;
      ++st.semantic_surfaces;
    } else if (by_normal) {
      cls = classByNormal(n);
      ++st.inferred_surfaces;
    }
    std::optional<uint32_t> material;
    if (std::find(ring_sizes.begin(), ring_sizes.end(), size_t(-1)) == ring_sizes.end())
      material = surfaceTexture(refs.texture, ring_sizes, closing_dropped, face);
    else if (refs.texture)
      ++st.bad_texture_references;
    if (material) {
      ++st.textured_surfaces;
    } else {
      face.uvs.clear();
      std::optional<int64_t> m = refs.material_all;
      if (refs.material && refs.material->is_number_integer()) m = refs.material->get<int64_t>();
      if (m) material = appearanceMaterial(*m);
      if (material) ++st.material_surfaces;
    }
    scene::Mesh& mesh = out.meshes[material ? *material : materials->forClass(cls)];
    for (const auto& ring : face.rings)
      for (const DVec3& p : ring) {
        out.hull_points.emplace_back(float(p.x), float(p.y));
        used_min = glm::min(used_min, p + origin);
        used_max = glm::max(used_max, p + origin);
      }
    st.triangles += appendCityFace(face, t, n, false, mesh);
    ++st.surfaces;
    st.holes += face.rings.size() - 1;
  }

  // Semantic class of a surface from its (possibly nested) "values" entry and the "surfaces" list.
  std::optional<SurfaceClass> semanticOf(const Json* value, const Json* surfaces) const {
    if (!value || !value->is_number_integer() || !surfaces || !surfaces->is_array()) return std::nullopt;
    const int64_t i = value->get<int64_t>();
    if (i < 0 || uint64_t(i) >= surfaces->size()) return std::nullopt;
    const Json& s = (*surfaces)[size_t(i)];
    if (!s.is_object() || !s.contains("type") || !s["type"].is_string()) return std::nullopt;
    return semanticSurfaceClass(s["type"].get<std::string>());
  }

  // A list of surfaces (a MultiSurface, a CompositeSurface or one shell of a solid).
  void surfaceList(const Json& list, const SurfaceRefs& refs, const Json* surfaces, SurfaceClass fallback,
                   bool by_normal, ObjectMeshes& out) {
    if (!list.is_array()) return skip(kMalformedGeometry);
    for (size_t k = 0; k < list.size(); ++k) {
      const SurfaceRefs r = refs.at(k);
      surface(list[k], r, semanticOf(r.semantics, surfaces), fallback, by_normal, out);
    }
  }

  // The "values" of theme `theme` in a geometry's "texture" or "material" object.
  static const Json* themeValues(const Json& g, const char* key, const std::string& theme, const Json** value) {
    auto it = g.find(key);
    if (it == g.end() || !it->is_object() || theme.empty()) return nullptr;
    auto th = it->find(theme);
    if (th == it->end() || !th->is_object()) return nullptr;
    if (value) {
      if (auto v = th->find("value"); v != th->end()) *value = &*v;
    }
    auto v = th->find("values");
    return v != th->end() ? &*v : nullptr;
  }

  void geometry(const Json& g, const std::string& object_type, ObjectMeshes& out) {
    if (!g.is_object() || !g.contains("type") || !g["type"].is_string()) return skip(kMalformedGeometry);
    const std::string type = g["type"].get<std::string>();
    if (type == "GeometryInstance") return skip(kTemplates);
    if (!g.contains("boundaries")) return skip(kMalformedGeometry);
    const Json& b = g["boundaries"];
    const Json* surfaces = nullptr;
    SurfaceRefs refs;
    if (auto it = g.find("semantics"); it != g.end() && it->is_object()) {
      if (auto s = it->find("surfaces"); s != it->end()) surfaces = &*s;
      if (auto v = it->find("values"); v != it->end()) refs.semantics = &*v;
    }
    refs.texture = themeValues(g, "texture", app.texture_theme, nullptr);
    const Json* material_value = nullptr;
    refs.material = themeValues(g, "material", app.material_theme, &material_value);
    if (material_value && material_value->is_number_integer()) refs.material_all = material_value->get<int64_t>();
    const CityCategory cat = cityCategoryOf(object_type);
    const bool building = cat == CityCategory::Building || cat == CityCategory::BuildingPart;
    const SurfaceClass fallback = building ? kWall : defaultSurfaceClass(object_type);
    if (type == "MultiSurface" || type == "CompositeSurface") {
      surfaceList(b, refs, surfaces, fallback, building, out);
    } else if (type == "Solid") {
      if (!b.is_array()) return skip(kMalformedGeometry);
      for (size_t shell = 0; shell < b.size(); ++shell) surfaceList(b[shell], refs.at(shell), surfaces, fallback, building, out);
    } else if (type == "MultiSolid" || type == "CompositeSolid") {
      if (!b.is_array()) return skip(kMalformedGeometry);
      for (size_t solid = 0; solid < b.size(); ++solid) {
        if (!b[solid].is_array()) {
          skip(kMalformedGeometry);
          continue;
        }
        const SurfaceRefs sr = refs.at(solid);
        for (size_t shell = 0; shell < b[solid].size(); ++shell)
          surfaceList(b[solid][shell], sr.at(shell), surfaces, fallback, building, out);
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

// Themes named by the geometries' "texture" or "material" objects (`key`), sorted by name.
std::vector<std::string> themesOf(const Json& objects, const char* key) {
  std::set<std::string> names;
  for (auto it = objects.begin(); it != objects.end(); ++it) {
    const Json& o = it.value();
    if (!o.is_object()) continue;
    auto g = o.find("geometry");
    if (g == o.end() || !g->is_array()) continue;
    for (const Json& geom : *g) {
      if (!geom.is_object()) continue;
      auto a = geom.find(key);
      if (a == geom.end() || !a->is_object()) continue;
      for (auto t = a->begin(); t != a->end(); ++t) names.insert(t.key());
    }
  }
  return {names.begin(), names.end()};
}

// The theme to use: the one asked for, else CityJSON 1.0's "default-theme-*", else the first by name (JSON objects
// have no order a reader must keep, so "the first in the file" is not defined).
std::string chooseTheme(const std::vector<std::string>& themes, const std::string& asked, const Json& appearance,
                        const char* default_key) {
  if (themes.empty()) return {};
  if (!asked.empty() && std::find(themes.begin(), themes.end(), asked) != themes.end()) return asked;
  if (auto d = appearance.find(default_key); d != appearance.end() && d->is_string() &&
                                             std::find(themes.begin(), themes.end(), d->get<std::string>()) != themes.end())
    return d->get<std::string>();
  return themes.front();
}

void readAppearance(const Json& doc, const Json& objects, const std::string& path,
                    const CityJsonImportOptions& options, Appearance& app, CityJsonStats& st) {
  st.texture_themes = themesOf(objects, "texture");
  st.material_themes = themesOf(objects, "material");
  if (!options.theme.empty() &&
      std::find(st.texture_themes.begin(), st.texture_themes.end(), options.theme) == st.texture_themes.end() &&
      std::find(st.material_themes.begin(), st.material_themes.end(), options.theme) == st.material_themes.end()) {
    std::string known;
    for (const auto* list : {&st.texture_themes, &st.material_themes})
      for (const std::string& t : *list) known += (known.empty() ? "" : ", ") + t;
    throw Error(path, "no appearance theme '" + options.theme + "' (themes: " + (known.empty() ? "none" : known) + ")");
  }
  static const Json kEmpty = Json::object();
  auto ait = doc.find("appearance");
  const Json& a = ait != doc.end() && ait->is_object() ? *ait : kEmpty;
  st.texture_theme = chooseTheme(st.texture_themes, options.theme, a, "default-theme-texture");
  st.material_theme = chooseTheme(st.material_themes, options.theme, a, "default-theme-material");
  app.texture_theme = st.texture_theme;
  app.material_theme = st.material_theme;
  if (auto t = a.find("textures"); t != a.end() && t->is_array()) app.textures = &*t;
  if (auto m = a.find("materials"); m != a.end() && m->is_array()) app.materials = &*m;
  if (auto v = a.find("vertices-texture"); v != a.end() && v->is_array()) {
    app.uvs.reserve(v->size());
    for (const Json& uv : *v) {
      if (uv.is_array() && uv.size() == 2 && uv[0].is_number() && uv[1].is_number()) {
        // CityJSON puts (0, 0) at the bottom left of the image, Farfield at the top left.
        const Vec2 p(uv[0].get<float>(), 1.0f - uv[1].get<float>());
        if (isFinite(p)) {
          app.uvs.emplace_back(p);
          continue;
        }
      }
      app.uvs.emplace_back(std::nullopt);
      ++st.bad_texture_vertices;
    }
  }
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
    const std::string root_type = root.contains("type") && root["type"].is_string() ? root["type"].get<std::string>() : "";
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
