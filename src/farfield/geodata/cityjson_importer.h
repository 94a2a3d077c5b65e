// The CityJSON reader (cityjson_import.h) in its parts: the document, its vertices and the walk over its objects
// (cityjson_import.cpp), geometries to meshes (cityjson_geometry.cpp) and appearances (cityjson_appearance.cpp).
// Internal to the geodata module: only src/farfield/geodata/cityjson_*.cpp include it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/geodata/city_surfaces.h"
#include "farfield/geodata/cityjson_import.h"
#include "farfield/scene/import.h"

namespace farfield::geodata::cityjson_import {

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

// The import of one document: its vertices, appearance and output materials, and what it counts.
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

  // Appearances (cityjson_appearance.cpp).
  std::optional<uint32_t> textureMaterial(int64_t t);
  std::optional<uint32_t> appearanceMaterial(int64_t m);
  std::optional<uint32_t> surfaceTexture(const Json* tex, const std::vector<size_t>& ring_sizes,
                                         const std::vector<bool>& closing_dropped, CityFace& face);
  static const Json* themeValues(const Json& g, const char* key, const std::string& theme, const Json** value);

  // Geometries (cityjson_geometry.cpp).
  void surface(const Json& s, const SurfaceRefs& refs, std::optional<SurfaceClass> semantic, SurfaceClass fallback,
               bool by_normal, ObjectMeshes& out);
  std::optional<SurfaceClass> semanticOf(const Json* value, const Json* surfaces) const;
  void surfaceList(const Json& list, const SurfaceRefs& refs, const Json* surfaces, SurfaceClass fallback,
                   bool by_normal, ObjectMeshes& out);
  void geometry(const Json& g, const std::string& object_type, ObjectMeshes& out);
  std::vector<const Json*> chooseGeometries(const Json& object, bool* lod_filtered) const;
};

// The document's appearance themes (checked against options.theme and recorded in `st`), the ones chosen, and the
// textures, materials and texture vertices they use (cityjson_appearance.cpp).
void readAppearance(const Json& doc, const Json& objects, const std::string& path,
                    const CityJsonImportOptions& options, Appearance& app, CityJsonStats& st);

}  // namespace farfield::geodata::cityjson_import
