// Polygons to triangles: a chosen polygon's rings in local coordinates, triangulated in its plane with its holes
// into the mesh of its texture, material or class colour, with its outline for the object's footprint.
#include <cmath>
#include <map>
#include <optional>
#include <vector>

#include <citygml/polygon.h>

#include "farfield/geodata/citygml_importer.h"

namespace farfield::geodata::citygml_import {

// The ring's vertices in local coordinates without a repeated closing vertex; `closed` says whether one was
// dropped. False for a non-finite coordinate.
bool Importer::ringOf(const citygml::LinearRing& ring, std::vector<DVec3>& out, bool& closed) const {
  out.clear();
  for (const TVec3d& v : ring.getVertices()) {
    const DVec3 p(v.x, v.y, v.z);
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
    out.push_back(p - origin_);
  }
  closed = out.size() > 3 && out.front() == out.back();
  if (closed) out.pop_back();
  return true;
}

// Triangulates one surface into `meshes`; adds its outline to `hull` and, for roads, its plan to `plan`.
void Importer::face(const Surface& s, std::map<uint32_t, scene::Mesh>& meshes, std::vector<Vec2>& hull,
                    std::vector<std::vector<std::vector<DVec2>>>* plan) {
  const citygml::Polygon& p = *s.polygon;
  const auto exterior = p.exteriorRing();
  if (!exterior) return skip(kNoExterior);
  CityFace f;
  std::vector<const citygml::LinearRing*> rings;
  std::vector<bool> closed;
  std::vector<DVec3> pts;
  bool c = false;
  if (!ringOf(*exterior, pts, c)) return skip(kBadCoordinate);
  if (pts.size() < 3) return skip(kTooFew);
  f.rings.push_back(pts);
  rings.push_back(exterior.get());
  closed.push_back(c);
  for (const auto& hole : p.interiorRings()) {
    if (!hole || !ringOf(*hole, pts, c) || pts.size() < 3) continue;  // a degenerate hole is dropped
    f.rings.push_back(pts);
    rings.push_back(hole.get());
    closed.push_back(c);
  }
  PolygonTriangulation t;
  DVec3 n(0.0, 0.0, 1.0);
  if (!triangulateCityFace(f, t, &n)) return skip(kNoArea);
  SurfaceClass cls = s.fallback;
  if (s.semantic) {
    cls = *s.semantic;
    ++st_.semantic_surfaces;
  } else if (s.by_normal) {
    cls = classByNormal(p.negNormal() ? -n : n);
    ++st_.inferred_surfaces;
  }
  std::optional<uint32_t> material = textureOf(p, rings, closed, f);
  if (material) {
    ++st_.textured_surfaces;
  } else if ((material = materialOf(p))) {
    ++st_.material_surfaces;
  }
  st_.triangles += appendCityFace(f, t, n, p.negNormal(), meshes[material ? *material : materials_->forClass(cls)]);
  ++st_.surfaces;
  st_.holes += f.rings.size() - 1;
  for (const DVec3& q : f.rings[0]) {
    hull.emplace_back(float(q.x), float(q.y));
    used_min_ = glm::min(used_min_, q + origin_);
    used_max_ = glm::max(used_max_, q + origin_);
  }
  if (plan && std::abs(n.z) > 0.5) {  // road surfaces seen from above (not kerbs or walls of tunnels)
    std::vector<std::vector<DVec2>> rings2;
    for (const auto& ring : f.rings) {
      rings2.emplace_back();
      for (const DVec3& q : ring) rings2.back().emplace_back(q.x, q.y);
    }
    plan->push_back(std::move(rings2));
  }
}

}  // namespace farfield::geodata::citygml_import
