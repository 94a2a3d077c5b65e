// Constrained Delaunay triangulation of the impostor (Sillion et al. 1997, section 4.2, "Triangulation and 3D
// reprojection") with CGAL. This is the only translation unit that includes CGAL: it compiles slowly, so its
// interface (triangulation.h) is plain Farfield types.
//
// Why Exact_predicates_tag: the simplified contour and the discrepancy polylines are built independently and
// may cross (a discrepancy line running to the contour, two parallel chains one pixel apart after simplification).
// With this tag CGAL splits crossing constraints at their intersection points instead of refusing them, and it is
// the tag for a kernel with exact predicates and inexact constructions (CGAL's Itag documentation): an intersection
// point computed in doubles that falls outside the two triangles beside the crossed edge is recomputed almost
// exactly and otherwise snapped to an end of that edge. Exact_intersections_tag, used before, is for exact number
// types; with this kernel it has no such check, and a rounded intersection point outside those triangles corrupted
// the triangulation: a SIGSEGV in CGAL's find_intersected_faces while baking a depth mesh of the 100,000-block city
// at detail 1 (`farfield bake ... --pipeline pvs,near-far,single --layer-mesh depth-mesh`, its 21st cell).
//
// Why inside is decided by even-odd over the loops and not by flood-filling across constrained edges: discrepancy
// constraints are constrained edges too but do not bound the inside. Every loop segment is a union of triangulation
// edges, so a face lies entirely on one side of every loop and its centroid decides.
#include "farfield/impostor/triangulation.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_triangulation_face_base_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_data_structure_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <utility>

#include "farfield/core/error.h"

namespace farfield::impostor {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<uint32_t, K>;
using Fb = CGAL::Constrained_triangulation_face_base_2<K>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag>;
using Point = Cdt::Point;

Point toPoint(const DVec2& p, const char* what) {
  if (!std::isfinite(p.x) || !std::isfinite(p.y))
    throw Error("impostor triangulation", std::string(what) + " has a non-finite coordinate");
  return Point(p.x, p.y);
}

void insertSegment(Cdt& cdt, const DVec2& a, const DVec2& b, const char* what) {
  if (a == b) return;
  cdt.insert_constraint(toPoint(a, what), toPoint(b, what));
}

}  // namespace

size_t Triangulation::insideCount() const { return size_t(std::count(inside.begin(), inside.end(), uint8_t(1))); }

LoopClassifier::LoopClassifier(const std::vector<std::vector<DVec2>>& loops) {
  double lo = 0.0, hi = 0.0;
  bool any = false;
  for (const auto& loop : loops)
    for (const DVec2& p : loop) {
      lo = any ? std::min(lo, p.y) : p.y;
      hi = any ? std::max(hi, p.y) : p.y;
      any = true;
    }
  if (!any) return;
  row0_ = int(std::floor(lo));
  rows_.resize(size_t(int(std::floor(hi)) - row0_ + 1));
  for (const auto& loop : loops)
    for (size_t i = 0; i < loop.size(); ++i) {
      const DVec2 a = loop[i], b = loop[(i + 1) % loop.size()];
      if (a.y == b.y) continue;  // a horizontal edge never crosses a horizontal ray in the even-odd rule below
      const int r0 = int(std::floor(std::min(a.y, b.y))) - row0_;
      const int r1 = int(std::floor(std::max(a.y, b.y))) - row0_;
      for (int r = r0; r <= r1; ++r) rows_[size_t(r)].push_back({a, b});
    }
}

bool LoopClassifier::inside(const DVec2& p) const {
  const int r = int(std::floor(p.y)) - row0_;
  if (r < 0 || size_t(r) >= rows_.size()) return false;
  bool in = false;
  for (const Segment& s : rows_[size_t(r)]) {
    if ((s.a.y > p.y) == (s.b.y > p.y)) continue;
    const double x = s.a.x + (p.y - s.a.y) * (s.b.x - s.a.x) / (s.b.y - s.a.y);
    if (x > p.x) in = !in;
  }
  return in;
}

Triangulation triangulate(const TriangulationInput& input, const Refinement* refinement) {
  Cdt cdt;
  std::set<std::pair<double, double>> distinct;
  auto note = [&](const DVec2& p) { distinct.insert({p.x, p.y}); };

  // Free points first, in one batch (CGAL sorts them spatially).
  std::vector<Point> points;
  points.reserve(input.points.size());
  for (const DVec2& p : input.points) {
    points.push_back(toPoint(p, "grid point"));
    note(p);
  }
  cdt.insert(points.begin(), points.end());
  for (const auto& loop : input.loops)
    for (size_t i = 0; i < loop.size(); ++i) {
      note(loop[i]);
      insertSegment(cdt, loop[i], loop[(i + 1) % loop.size()], "contour loop");
    }
  for (const auto& line : input.polylines) {
    for (const DVec2& p : line) note(p);
    if (line.size() == 1) cdt.insert(toPoint(line[0], "discrepancy polyline"));
    for (size_t i = 0; i + 1 < line.size(); ++i) insertSegment(cdt, line[i], line[i + 1], "discrepancy polyline");
  }

  Triangulation out;
  out.input_vertices = distinct.size();
  const size_t before_refinement = cdt.number_of_vertices();
  out.steiner_vertices = before_refinement > distinct.size() ? before_refinement - distinct.size() : 0;

  const LoopClassifier classifier(input.loops);
  auto centroid = [](Cdt::Face_handle f) {
    const Point& a = f->vertex(0)->point();
    const Point& b = f->vertex(1)->point();
    const Point& c = f->vertex(2)->point();
    return DVec2((a.x() + b.x() + c.x()) / 3.0, (a.y() + b.y() + c.y()) / 3.0);
  };
  auto toVec = [](const Point& p) { return DVec2(p.x(), p.y()); };

  if (refinement && refinement->split_point && refinement->max_points > 0) {
    size_t inserted = 0;
    for (int round = 0; round < refinement->max_rounds && inserted < refinement->max_points; ++round) {
      std::vector<Point> extra;
      for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
        if (!classifier.inside(centroid(f))) continue;
        const auto p = refinement->split_point(toVec(f->vertex(0)->point()), toVec(f->vertex(1)->point()),
                                               toVec(f->vertex(2)->point()));
        if (p && std::isfinite(p->x) && std::isfinite(p->y)) extra.push_back(Point(p->x, p->y));
        if (inserted + extra.size() >= refinement->max_points) break;
      }
      if (extra.empty()) break;
      const size_t n0 = cdt.number_of_vertices();
      for (const Point& p : extra) cdt.insert(p);
      const size_t added = cdt.number_of_vertices() - n0;
      inserted += extra.size();
      if (added == 0) break;  // all of them already present: nothing more to gain
    }
    out.refinement_vertices = cdt.number_of_vertices() - before_refinement;
  }

  uint32_t next = 0;
  out.vertices.reserve(cdt.number_of_vertices());
  for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v) {
    v->info() = next++;
    out.vertices.push_back(toVec(v->point()));
  }
  out.triangles.reserve(cdt.number_of_faces());
  out.inside.reserve(cdt.number_of_faces());
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    out.triangles.push_back({f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()});
    out.inside.push_back(classifier.inside(centroid(f)) ? 1 : 0);
  }
  for (auto e = cdt.finite_edges_begin(); e != cdt.finite_edges_end(); ++e)
    if (cdt.is_constrained(*e)) ++out.constrained_edges;
  return out;
}

}  // namespace farfield::impostor
