// Constrained Delaunay triangulation of polygons with holes (CGAL). All CGAL use of the geodata module is in this
// file: its headers are slow to compile.
//
// Every ring edge is a constraint; the triangles inside are found by walking the faces from the infinite face and
// counting the constraints crossed (even-odd nesting), which handles holes and islands without knowing which ring
// is which. Constraints that cross (malformed rings) are split by CGAL at an approximate intersection point
// (Exact_predicates_tag), so a bad face still triangulates instead of failing.
#include "farfield/geodata/triangulate.h"

#include <cmath>
#include <deque>
#include <limits>

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

namespace farfield::geodata {

namespace {

constexpr uint32_t kNoIndex = std::numeric_limits<uint32_t>::max();

struct VertexInfo {
  uint32_t index = kNoIndex;
};
struct FaceInfo {
  int nesting = -1;
};

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<VertexInfo, K>;
using Fbi = CGAL::Triangulation_face_base_with_info_2<FaceInfo, K>;
using Fb = CGAL::Constrained_triangulation_face_base_2<K, Fbi>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag>;
using Point = K::Point_2;

// Nesting level of every face: 0 outside, +1 across each constraint. Breadth-first from the infinite face.
void markNesting(Cdt& cdt) {
  for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) f->info().nesting = -1;
  std::deque<std::pair<Cdt::Face_handle, int>> border;
  border.emplace_back(cdt.infinite_face(), 0);
  while (!border.empty()) {
    auto [start, level] = border.front();
    border.pop_front();
    if (start->info().nesting != -1) continue;
    // Flood the region of equal nesting reachable without crossing constraints.
    std::deque<Cdt::Face_handle> queue{start};
    start->info().nesting = level;
    while (!queue.empty()) {
      Cdt::Face_handle f = queue.front();
      queue.pop_front();
      for (int i = 0; i < 3; ++i) {
        Cdt::Face_handle n = f->neighbor(i);
        if (n->info().nesting != -1) continue;
        if (cdt.is_constrained(Cdt::Edge(f, i))) {
          border.emplace_back(n, level + 1);
        } else {
          n->info().nesting = level;
          queue.push_back(n);
        }
      }
    }
  }
}

// Triangulates 2D rings; added vertices get positions through `lift`.
template <class Lift>
bool triangulate2(const std::vector<std::vector<DVec2>>& rings, PolygonTriangulation& out, Lift&& lift) {
  out.indices.clear();
  out.extra.clear();
  Cdt cdt;
  uint32_t base = 0;
  size_t constraints = 0;
  for (const auto& ring : rings) {
    for (const DVec2& p : ring)
      if (!std::isfinite(p.x) || !std::isfinite(p.y)) return false;
    const uint32_t n = uint32_t(ring.size());
    std::vector<Cdt::Vertex_handle> handles(n);
    for (uint32_t i = 0; i < n; ++i) {
      handles[i] = cdt.insert(Point(ring[i].x, ring[i].y));
      if (handles[i]->info().index == kNoIndex) handles[i]->info().index = base + i;
    }
    if (n >= 3) {
      for (uint32_t i = 0; i < n; ++i) {
        Cdt::Vertex_handle a = handles[i], b = handles[(i + 1) % n];
        if (a == b) continue;
        cdt.insert_constraint(a, b);
        ++constraints;
      }
    }
    base += n;
  }
  if (constraints < 3 || cdt.dimension() < 2) return false;
  markNesting(cdt);
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (f->info().nesting % 2 != 1) continue;
    uint32_t tri[3];
    for (int k = 0; k < 3; ++k) {
      Cdt::Vertex_handle v = f->vertex(k);
      if (v->info().index == kNoIndex) {
        v->info().index = base + uint32_t(out.extra.size());
        out.extra.push_back(lift(DVec2(v->point().x(), v->point().y())));
      }
      tri[k] = v->info().index;
    }
    // Skip slivers of zero area (collinear points joined by constraints).
    const Point& p0 = f->vertex(0)->point();
    const Point& p1 = f->vertex(1)->point();
    const Point& p2 = f->vertex(2)->point();
    if (CGAL::orientation(p0, p1, p2) != CGAL::LEFT_TURN) continue;
    out.indices.insert(out.indices.end(), {tri[0], tri[1], tri[2]});
  }
  return !out.indices.empty();
}

}  // namespace

DVec3 newellNormal(const std::vector<DVec3>& ring) {
  DVec3 n(0.0);
  if (ring.empty()) return n;
  const DVec3 o = ring[0];  // relative to the first point: large world coordinates lose no precision
  for (size_t i = 0; i < ring.size(); ++i) {
    const DVec3 a = ring[i] - o, b = ring[(i + 1) % ring.size()] - o;
    n.x += (a.y - b.y) * (a.z + b.z);
    n.y += (a.z - b.z) * (a.x + b.x);
    n.z += (a.x - b.x) * (a.y + b.y);
  }
  return n;
}

bool triangulatePolygon2(const std::vector<std::vector<DVec2>>& rings, PolygonTriangulation& out) {
  return triangulate2(rings, out, [](const DVec2& p) { return DVec3(p, 0.0); });
}

bool triangulateFace3(const std::vector<std::vector<DVec3>>& rings, PolygonTriangulation& out, DVec3* normal) {
  out.indices.clear();
  out.extra.clear();
  if (rings.empty() || rings[0].size() < 3) return false;
  for (const auto& ring : rings)
    for (const DVec3& p : ring)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
  DVec3 n = newellNormal(rings[0]);
  const double len = glm::length(n);
  if (!(len > 0.0) || !std::isfinite(len)) return false;
  n /= len;
  // Orthonormal basis (u, v, n), right-handed: the outer ring is counter-clockwise in (u, v).
  const DVec3 helper = std::abs(n.x) < 0.9 ? DVec3(1, 0, 0) : DVec3(0, 1, 0);
  const DVec3 u = glm::normalize(glm::cross(helper, n));
  const DVec3 v = glm::cross(n, u);
  const DVec3 o = rings[0][0];
  std::vector<std::vector<DVec2>> flat(rings.size());
  double offset = 0.0;  // mean distance of the outer ring from the plane through o
  for (const DVec3& p : rings[0]) offset += glm::dot(p - o, n);
  offset /= double(rings[0].size());
  for (size_t r = 0; r < rings.size(); ++r) {
    flat[r].reserve(rings[r].size());
    for (const DVec3& p : rings[r]) flat[r].emplace_back(glm::dot(p - o, u), glm::dot(p - o, v));
  }
  if (normal) *normal = n;
  return triangulate2(flat, out, [&](const DVec2& q) { return o + u * q.x + v * q.y + n * offset; });
}

}  // namespace farfield::geodata
