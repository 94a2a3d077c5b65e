// Geometries to meshes: per object those of the highest LoD allowed, their boundaries (multi-surfaces, solids,
// multi-solids) walked down to faces, each face triangulated into the mesh of its appearance or semantic class.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "farfield/geodata/cityjson_importer.h"
#include "farfield/geodata/triangulate.h"

namespace farfield::geodata::cityjson_import {

namespace {

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

}  // namespace

// One surface: [outer ring, hole, ...], each ring an array of vertex indices.
void Importer::surface(const Json& s, const SurfaceRefs& refs, std::optional<SurfaceClass> semantic,
                       SurfaceClass fallback, bool by_normal, ObjectMeshes& out) {
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
std::optional<SurfaceClass> Importer::semanticOf(const Json* value, const Json* surfaces) const {
  if (!value || !value->is_number_integer() || !surfaces || !surfaces->is_array()) return std::nullopt;
  const int64_t i = value->get<int64_t>();
  if (i < 0 || uint64_t(i) >= surfaces->size()) return std::nullopt;
  const Json& s = (*surfaces)[size_t(i)];
  if (!s.is_object() || !s.contains("type") || !s["type"].is_string()) return std::nullopt;
  return semanticSurfaceClass(s["type"].get<std::string>());
}

// A list of surfaces (a MultiSurface, a CompositeSurface or one shell of a solid).
void Importer::surfaceList(const Json& list, const SurfaceRefs& refs, const Json* surfaces, SurfaceClass fallback,
                           bool by_normal, ObjectMeshes& out) {
  if (!list.is_array()) return skip(kMalformedGeometry);
  for (size_t k = 0; k < list.size(); ++k) {
    const SurfaceRefs r = refs.at(k);
    surface(list[k], r, semanticOf(r.semantics, surfaces), fallback, by_normal, out);
  }
}

void Importer::geometry(const Json& g, const std::string& object_type, ObjectMeshes& out) {
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
    for (size_t shell = 0; shell < b.size(); ++shell)
      surfaceList(b[shell], refs.at(shell), surfaces, fallback, building, out);
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
std::vector<const Json*> Importer::chooseGeometries(const Json& object, bool* lod_filtered) const {
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

}  // namespace farfield::geodata::cityjson_import
