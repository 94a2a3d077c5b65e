// The first pass: what a root city object draws. The highest LoD of it and of each of its BuildingParts (not above
// max_lod), that LoD's polygons once each, and their semantic class or how to colour them without one.
#include <algorithm>
#include <optional>
#include <unordered_set>
#include <vector>

#include <citygml/cityobject.h>
#include <citygml/geometry.h>
#include <citygml/polygon.h>

#include "farfield/geodata/citygml_importer.h"

namespace farfield::geodata::citygml_import {

namespace {

// A geometry of an object to draw, with the semantic type of the city object holding it ("RoofSurface", ...).
struct GeometryRef {
  const citygml::Geometry* geometry;
  std::string holder_type;
};

// Geometries of `o` and of its descendants that belong to it (boundary surfaces, installations, openings), and the
// BuildingParts below it, which choose their LoD on their own.
void collectGeometries(const citygml::CityObject& o, std::vector<GeometryRef>& out,
                       std::vector<const citygml::CityObject*>& parts, size_t& implicit, int depth = 0) {
  if (depth > 64) return;  // libcitygml builds a tree; a bound keeps a pathological one from exhausting the stack
  for (unsigned i = 0; i < o.getGeometriesCount(); ++i) out.push_back({&o.getGeometry(i), o.getTypeAsString()});
  implicit += o.getImplicitGeometryCount();
  for (unsigned i = 0; i < o.getChildCityObjectsCount(); ++i) {
    const citygml::CityObject& c = o.getChildCityObject(i);
    if (c.getType() == CityObjectType::COT_BuildingPart)
      parts.push_back(&c);
    else
      collectGeometries(c, out, parts, implicit, depth + 1);
  }
}

void collectPolygons(const citygml::Geometry& g, std::vector<const citygml::Polygon*>& out, int depth = 0) {
  if (depth > 64) return;
  for (unsigned i = 0; i < g.getPolygonsCount(); ++i)
    if (auto p = g.getPolygon(i)) out.push_back(p.get());
  for (unsigned i = 0; i < g.getGeometriesCount(); ++i) collectPolygons(g.getGeometry(i), out, depth + 1);
}

}  // namespace

// Chooses a root object's LoD and polygons (its own and its BuildingParts', each at their own highest LoD).
void Importer::chooseSurfaces(const citygml::CityObject& root) {
  Unit u;
  u.object = &root;
  u.type = root.getTypeAsString();
  u.category = cityCategoryOf(u.type);
  if (u.category == CityCategory::Ground && !options_.ground_objects) return;
  if (u.category == CityCategory::Other && !options_.other_objects) return;
  std::unordered_set<const citygml::Polygon*> seen;
  std::vector<const citygml::CityObject*> pending{&root};
  bool any_geometry = false;
  while (!pending.empty()) {
    const citygml::CityObject* o = pending.back();
    pending.pop_back();
    std::vector<GeometryRef> refs;
    std::vector<const citygml::CityObject*> parts;
    size_t implicit = 0;
    collectGeometries(*o, refs, parts, implicit);
    if (implicit) st_.skipped[kImplicit] += implicit;
    for (const citygml::CityObject* p : parts) pending.push_back(p);
    std::optional<unsigned> best;
    for (const GeometryRef& r : refs) {
      any_geometry = true;
      const unsigned lod = r.geometry->getLOD();
      if (options_.max_lod && lod > *options_.max_lod) continue;
      if (!best || lod > *best) best = lod;
    }
    if (!best) continue;
    if (!u.lod || *best > *u.lod) u.lod = best;
    const size_t before = u.surfaces.size();
    // Boundary surfaces first, so that a polygon an LoD2 solid links again keeps its semantic class.
    std::stable_sort(refs.begin(), refs.end(), [](const GeometryRef& a, const GeometryRef& b) {
      return semanticSurfaceClass(a.holder_type).has_value() > semanticSurfaceClass(b.holder_type).has_value();
    });
    const CityCategory cat = cityCategoryOf(o->getTypeAsString());
    const bool building = cat == CityCategory::Building || cat == CityCategory::BuildingPart;
    const SurfaceClass fallback = building ? kWall : defaultSurfaceClass(u.type);
    for (const GeometryRef& r : refs) {
      if (r.geometry->getLOD() != *best) continue;
      std::vector<const citygml::Polygon*> polygons;
      collectPolygons(*r.geometry, polygons);
      const std::optional<SurfaceClass> semantic = semanticSurfaceClass(r.holder_type);
      for (const citygml::Polygon* p : polygons) {
        if (!seen.insert(p).second) {
          ++st_.shared_polygons;
          continue;
        }
        u.surfaces.push_back({p, semantic, fallback, building && !semantic});
      }
    }
    if (o != &root && u.surfaces.size() > before && o->getType() == CityObjectType::COT_BuildingPart) ++u.parts;
  }
  if (u.surfaces.empty()) {
    if (any_geometry) u.lod_filtered = true;
    ++st_.skipped[any_geometry ? kLodFiltered : kNoGeometry];
    return;
  }
  units_.push_back(std::move(u));
}

}  // namespace farfield::geodata::citygml_import
