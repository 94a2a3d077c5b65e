// Extruded buildings. Walls are one quad per ring edge (texture repetition does the floors and bays, as in the
// procedural city at detail 0); the roof is a constrained Delaunay triangulation of the footprint with its holes
// (triangulate.h), so courtyards stay open.
#include "farfield/geodata/extrude.h"

#include <algorithm>
#include <cmath>

#include "farfield/geodata/triangulate.h"

namespace farfield::geodata {

namespace {

constexpr float kRoofTile = 4.0f;  // metres per roof texture repeat (gen/building_parts.h)
constexpr Vec3 kUp{0.0f, 0.0f, 1.0f};

void tri(scene::Mesh& m, uint32_t a, uint32_t b, uint32_t c) { m.indices.insert(m.indices.end(), {a, b, c}); }

uint32_t vertex(scene::Mesh& m, const Vec3& p, const Vec3& n, const Vec2& uv) {
  m.positions.push_back(p);
  m.normals.push_back(n);
  m.uvs.push_back(uv);
  return uint32_t(m.positions.size() - 1);
}

// A planar polygon in 3D, fanned from its first vertex (convex only), facing along its Newell normal flipped up.
void addRoofTriangle(scene::Mesh& m, const Vec3& a, const Vec3& b, const Vec3& c) {
  Vec3 n = glm::cross(b - a, c - a);
  const float len = glm::length(n);
  if (!(len > 0.0f)) return;
  n /= len;
  const bool flip = n.z < 0.0f;
  if (flip) n = -n;
  auto uv = [](const Vec3& p) { return Vec2(p.x / kRoofTile, -p.y / kRoofTile); };
  const uint32_t i0 = vertex(m, a, n, uv(a)), i1 = vertex(m, b, n, uv(b)), i2 = vertex(m, c, n, uv(c));
  if (flip) tri(m, i0, i2, i1);
  else tri(m, i0, i1, i2);
}

void addRoofQuad(scene::Mesh& m, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  addRoofTriangle(m, a, b, c);
  addRoofTriangle(m, a, c, d);
}

// Wall quad from p0 to p1 (outside on the right of p0 -> p1) between z0 and z1; v counts floors down from v_top.
void addWall(scene::Mesh& m, const Vec2& p0, const Vec2& p1, float z0, float z1, float u0, float v_top,
             const ExtrusionShape& s) {
  const Vec2 d = p1 - p0;
  const float len = glm::length(d);
  if (!(len > 0.0f)) return;
  const Vec3 n(d.y / len, -d.x / len, 0.0f);
  const float u1 = u0 + len / s.bay_width;
  auto v = [&](float z) { return (v_top - z) / s.floor_height; };
  const uint32_t a = vertex(m, Vec3(p0, z0), n, Vec2(u0, v(z0)));
  const uint32_t b = vertex(m, Vec3(p1, z0), n, Vec2(u1, v(z0)));
  const uint32_t c = vertex(m, Vec3(p1, z1), n, Vec2(u1, v(z1)));
  const uint32_t e = vertex(m, Vec3(p0, z1), n, Vec2(u0, v(z1)));
  tri(m, a, b, c);
  tri(m, a, c, e);
}

// Triangle on a wall plane (gable end) with facade uvs.
void addGable(scene::Mesh& m, const Vec2& p0, const Vec2& p1, float eave, const Vec3& apex, float top,
              const ExtrusionShape& s) {
  const Vec2 d = p1 - p0;
  const float len = glm::length(d);
  if (!(len > 0.0f)) return;
  const Vec3 n(d.y / len, -d.x / len, 0.0f);
  auto uv = [&](const Vec3& p) {
    return Vec2(glm::dot(Vec2(p) - p0, d / len) / s.bay_width, (top - p.z) / s.floor_height);
  };
  const Vec3 a(p0, eave), b(p1, eave);
  const uint32_t i0 = vertex(m, a, n, uv(a)), i1 = vertex(m, b, n, uv(b)), i2 = vertex(m, apex, n, uv(apex));
  tri(m, i0, i1, i2);
}

bool isConvex(const Polygon2& p) {
  const size_t n = p.size();
  if (n < 3) return false;
  for (size_t i = 0; i < n; ++i) {
    const Vec2 a = p[i], b = p[(i + 1) % n], c = p[(i + 2) % n];
    if (cross2(DVec2(b - a), DVec2(c - b)) < 0.0) return false;
  }
  return true;
}

}  // namespace

RoofKind feasibleRoof(const FootprintPolygon& polygon, const ExtrusionShape& shape) {
  if (shape.roof == RoofKind::Flat || !polygon.holes.empty()) return RoofKind::Flat;
  if (!(shape.roof_height > 0.0f) || !(shape.top - shape.roof_height > shape.base)) return RoofKind::Flat;
  Polygon2 outer = polygon.outer;
  makeCounterClockwise(outer);
  if (!isConvex(outer)) return RoofKind::Flat;
  if (shape.roof == RoofKind::Gabled && outer.size() != 4) return RoofKind::Pyramidal;
  return shape.roof;
}

bool extrudeBuilding(const FootprintPolygon& polygon_in, const ExtrusionShape& shape, scene::Mesh& facades,
                     scene::Mesh& roofs) {
  if (polygon_in.outer.size() < 3) return false;
  FootprintPolygon polygon = polygon_in;
  makeCounterClockwise(polygon.outer);
  for (Polygon2& h : polygon.holes) {
    makeCounterClockwise(h);
    std::reverse(h.begin(), h.end());
  }
  const RoofKind roof = feasibleRoof(polygon, shape);
  const float top = shape.top;
  const float eave = roof == RoofKind::Flat ? top : top - shape.roof_height;
  const size_t facade_mark = facades.positions.size(), facade_index_mark = facades.indices.size();
  const size_t roof_mark = roofs.positions.size(), roof_index_mark = roofs.indices.size();

  // Flat roof first: if it cannot be triangulated nothing is appended.
  if (roof == RoofKind::Flat) {
    std::vector<std::vector<DVec2>> rings;
    std::vector<Vec2> all;
    rings.emplace_back();
    for (const Vec2& p : polygon.outer) rings.back().emplace_back(p.x, p.y), all.push_back(p);
    for (const Polygon2& h : polygon.holes) {
      rings.emplace_back();
      for (const Vec2& p : h) rings.back().emplace_back(p.x, p.y), all.push_back(p);
    }
    PolygonTriangulation t;
    if (!triangulatePolygon2(rings, t)) return false;
    for (const DVec3& e : t.extra) all.emplace_back(float(e.x), float(e.y));
    const uint32_t first = uint32_t(roofs.positions.size());
    for (const Vec2& p : all) vertex(roofs, Vec3(p, top), kUp, Vec2(p.x / kRoofTile, -p.y / kRoofTile));
    for (size_t i = 0; i + 2 < t.indices.size(); i += 3)
      tri(roofs, first + t.indices[i], first + t.indices[i + 1], first + t.indices[i + 2]);
    if (shape.base > 0.01f) {
      // The underside of a raised part (a bridge between buildings, an overhang): the roof turned down.
      const uint32_t below = uint32_t(roofs.positions.size());
      for (const Vec2& p : all) vertex(roofs, Vec3(p, shape.base), -kUp, Vec2(p.x / kRoofTile, -p.y / kRoofTile));
      for (size_t i = 0; i + 2 < t.indices.size(); i += 3)
        tri(roofs, below + t.indices[i], below + t.indices[i + 2], below + t.indices[i + 1]);
    }
  } else {
    const Polygon2& p = polygon.outer;
    const size_t n = p.size();
    if (roof == RoofKind::Gabled) {
      // Gable ends on the two shorter opposite edges, the ridge between their midpoints.
      const float l0 = glm::length(p[1] - p[0]) + glm::length(p[3] - p[2]);
      const float l1 = glm::length(p[2] - p[1]) + glm::length(p[0] - p[3]);
      const size_t k = l0 <= l1 ? 0 : 1;
      const Vec2 a0 = p[k], a1 = p[k + 1], b0 = p[k + 2], b1 = p[(k + 3) % 4];
      const Vec3 ma((a0 + a1) * 0.5f, top), mb((b0 + b1) * 0.5f, top);
      addGable(facades, a0, a1, eave, ma, top, shape);
      addGable(facades, b0, b1, eave, mb, top, shape);
      addRoofQuad(roofs, Vec3(a1, eave), Vec3(b0, eave), mb, ma);
      addRoofQuad(roofs, Vec3(b1, eave), Vec3(a0, eave), ma, mb);
    } else {
      const Vec3 apex(polygonCentroid(p), top);
      for (size_t i = 0; i < n; ++i) addRoofTriangle(roofs, Vec3(p[i], eave), Vec3(p[(i + 1) % n], eave), apex);
    }
    if (shape.base > 0.01f) {
      for (size_t i = 1; i + 1 < n; ++i) {
        const Vec3 a(p[0], shape.base), b(p[i + 1], shape.base), c(p[i], shape.base);
        const uint32_t i0 = vertex(roofs, a, -kUp, Vec2(a) / kRoofTile), i1 = vertex(roofs, b, -kUp, Vec2(b) / kRoofTile),
                       i2 = vertex(roofs, c, -kUp, Vec2(c) / kRoofTile);
        tri(roofs, i0, i1, i2);
      }
    }
  }
  if (roofs.indices.size() == roof_index_mark) {
    roofs.positions.resize(roof_mark);
    roofs.normals.resize(roof_mark);
    roofs.uvs.resize(roof_mark);
    facades.positions.resize(facade_mark);
    facades.normals.resize(facade_mark);
    facades.uvs.resize(facade_mark);
    facades.indices.resize(facade_index_mark);
    return false;
  }

  // Walls of every ring; u runs on around the ring so the bays continue across corners.
  auto walls = [&](const Polygon2& ring) {
    float u = 0.0f;
    for (size_t i = 0; i < ring.size(); ++i) {
      const Vec2 a = ring[i], b = ring[(i + 1) % ring.size()];
      addWall(facades, a, b, shape.base, eave, u, top, shape);
      u += glm::length(b - a) / shape.bay_width;
      u -= std::floor(u);
    }
  };
  walls(polygon.outer);
  for (const Polygon2& h : polygon.holes) walls(h);
  return true;
}

}  // namespace farfield::geodata
