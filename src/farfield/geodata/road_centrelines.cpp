// Road centre lines from the chordal axis of the united road surfaces (see road_centrelines.h). The union is
// computed with exact constructions (overlapping rectangles of crossing roads share edges and corners, which
// inexact arithmetic turns into slivers); the triangulation with exact predicates and inexact constructions.
// GCC 12 with the sanitizers warns that CGAL's Epic_converter (used by the triangulation's constraint
// intersections) returns a std::pair before setting it: a false positive (both members are set on every path) whose
// location is <utility>, so the pragma covers the whole file.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include "farfield/geodata/road_centrelines.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include "farfield/core/douglas_peucker.h"
#include "farfield/core/polygon2d.h"

#include <CGAL/Boolean_set_operations_2.h>
#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_set_2.h>
#include <CGAL/Polygon_with_holes_2.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

namespace farfield::geodata {

namespace {

using Ek = CGAL::Exact_predicates_exact_constructions_kernel;
using Ik = CGAL::Exact_predicates_inexact_constructions_kernel;
using EPolygon = CGAL::Polygon_2<Ek>;
using EPolygonWithHoles = CGAL::Polygon_with_holes_2<Ek>;
using IPolygon = CGAL::Polygon_2<Ik>;
using IPolygonWithHoles = CGAL::Polygon_with_holes_2<Ik>;

// A ring as a simple CGAL polygon of the wanted orientation; false when it is not simple or has no area.
bool toPolygon(const std::vector<DVec2>& ring, bool counter_clockwise, EPolygon& out) {
  out.clear();
  for (const DVec2& p : ring) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return false;
    const Ek::Point_2 q(p.x, p.y);
    if (out.size() > 0 && (q == *(out.vertices_end() - 1) || q == *out.vertices_begin())) continue;
    out.push_back(q);
  }
  if (out.size() < 3 || !out.is_simple() || out.orientation() == CGAL::COLLINEAR) return false;
  if ((out.orientation() == CGAL::COUNTERCLOCKWISE) != counter_clockwise) out.reverse_orientation();
  return true;
}

IPolygon toInexact(const EPolygon& p) {
  IPolygon out;
  for (auto v = p.vertices_begin(); v != p.vertices_end(); ++v)
    out.push_back(Ik::Point_2(CGAL::to_double(v->x()), CGAL::to_double(v->y())));
  return out;
}

// Vertices closer than this (metres) to the line through their neighbours, or to their predecessor, are dropped
// before triangulating: they would only make slivers of triangles, and they change the centre lines by less than a
// road marking is wide.
constexpr double kCleanTolerance = 0.05;

DVec2 toDVec2(const Ik::Point_2& p) { return DVec2(p.x(), p.y()); }

double distanceToSegment(const Ik::Point_2& p, const Ik::Point_2& a, const Ik::Point_2& b) {
  return distancePointSegmentD(toDVec2(p), toDVec2(a), toDVec2(b));
}

// Distance from p to the line through a and b (to a when they coincide).
double pointLineDistance(const DVec2& p, const DVec2& a, const DVec2& b) {
  const DVec2 d = b - a, q = p - a;
  const double len = glm::length(d);
  return len > 0.0 ? std::abs(d.x * q.y - d.y * q.x) / len : glm::length(q);
}

// Drops near-duplicate and near-collinear vertices until none is left; returns how many were dropped.
size_t cleanRing(IPolygon& ring) {
  size_t dropped = 0;
  for (bool changed = true; changed && ring.size() >= 3;) {
    changed = false;
    for (size_t i = 0; i < ring.size() && ring.size() >= 3; ++i) {
      const size_t n = ring.size();
      const Ik::Point_2& prev = ring[(i + n - 1) % n];
      const Ik::Point_2& next = ring[(i + 1) % n];
      if (distanceToSegment(ring[i], prev, next) < kCleanTolerance ||
          distanceToSegment(ring[i], prev, prev) < kCleanTolerance) {
        ring.erase(ring.vertices_begin() + std::ptrdiff_t(i));
        ++dropped;
        changed = true;
      }
    }
  }
  return dropped;
}

// Border edges are split until each is no longer than the road is wide across it, but not below this (metres), nor
// below the spacing that would give the borders more than kMaxSamples points (so the triangulation stays bounded).
constexpr double kMinSpacing = 0.5;
constexpr double kMaxSamples = 100000.0;
// An edge whose opposite corner is closer than this (metres) borders a sliver or a corner, not a road's width: it is
// left whole (splitting slivers would cost a cascade of flips per sample and give no street).
constexpr double kMinRoadWidth = 1.0;
constexpr int kMaxRefinements = 8;
// Polyline vertices closer than this share of the minimum spacing to the simplified line are dropped: chord
// midpoints between borders that are not parallel zig-zag by up to about half a spacing.
constexpr double kSimplifyShare = 0.25;

struct FaceInfo {
  int nesting = -1;  // rings crossed from the unbounded face: odd inside a road area
};
using Vb = CGAL::Triangulation_vertex_base_with_info_2<uint32_t, Ik>;
using Fb = CGAL::Constrained_triangulation_face_base_2<Ik, CGAL::Triangulation_face_base_with_info_2<FaceInfo, Ik>>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Ik, CGAL::Triangulation_data_structure_2<Vb, Fb>,
                                                       CGAL::Exact_predicates_tag>;

// Nesting depth of every face: a flood fill from the unbounded face that crosses one constrained edge per level.
void markNesting(Cdt& cdt) {
  for (Cdt::Face_handle f : cdt.all_face_handles()) f->info().nesting = -1;
  std::vector<std::pair<Cdt::Face_handle, int>> seeds = {{cdt.infinite_face(), 0}};
  std::vector<Cdt::Face_handle> stack;
  for (size_t next = 0; next < seeds.size(); ++next) {
    const auto [seed, level] = seeds[next];
    if (seed->info().nesting != -1) continue;
    stack = {seed};
    seed->info().nesting = level;
    while (!stack.empty()) {
      const Cdt::Face_handle f = stack.back();
      stack.pop_back();
      for (int i = 0; i < 3; ++i) {
        const Cdt::Face_handle n = f->neighbor(i);
        if (n->info().nesting != -1) continue;
        if (cdt.is_constrained({f, i})) {
          seeds.emplace_back(n, level + 1);
        } else {
          n->info().nesting = level;
          stack.push_back(n);
        }
      }
    }
  }
}

// The chordal axis as a graph: nodes at chord midpoints and junction centres, edges with the road's width.
class AxisGraph {
 public:
  struct Edge {
    uint32_t a = 0, b = 0;
    double width = 0.0;
    bool removed = false;
  };

  uint32_t addNode(const DVec2& p, bool junction) {
    pos_.push_back(p);
    junction_.push_back(junction);
    incident_.emplace_back();
    return uint32_t(pos_.size() - 1);
  }
  void addEdge(uint32_t a, uint32_t b, double width) {
    edges_.push_back({a, b, width, false});
    incident_[a].push_back(uint32_t(edges_.size() - 1));
    incident_[b].push_back(uint32_t(edges_.size() - 1));
  }

  size_t degree(uint32_t n) const {
    size_t d = 0;
    for (uint32_t e : incident_[n]) d += !edges_[e].removed;
    return d;
  }
  uint32_t other(uint32_t e, uint32_t n) const { return edges_[e].a == n ? edges_[e].b : edges_[e].a; }
  double length(uint32_t e) const { return glm::distance(pos_[edges_[e].a], pos_[edges_[e].b]); }
  double widthAt(uint32_t n) const {
    double w = 0.0;
    for (uint32_t e : incident_[n])
      if (!edges_[e].removed) w = std::max(w, edges_[e].width);
    return w;
  }

  // The chain from `start` through `first` and on through nodes of degree 2, to the first node of another degree
  // (or back to `start` on a loop).
  struct Chain {
    std::vector<uint32_t> nodes;  // start ... end
    std::vector<uint32_t> edges;
    double length = 0.0;
  };
  Chain walk(uint32_t start, uint32_t first) const {
    Chain c{{start}, {}, 0.0};
    uint32_t node = start, e = first;
    for (;;) {
      c.edges.push_back(e);
      c.length += length(e);
      node = other(e, node);
      c.nodes.push_back(node);
      if (node == start || degree(node) != 2) return c;
      uint32_t next = e;
      for (uint32_t f : incident_[node])
        if (!edges_[f].removed && f != e) next = f;
      if (next == e) return c;
      e = next;
    }
  }

  // Junction triangles joined by chains shorter than the road is wide are one junction, at their centres' mean.
  size_t mergeJunctions() {
    std::vector<uint32_t> parent(pos_.size());
    for (uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
    auto find = [&](uint32_t i) {
      while (parent[i] != i) i = parent[i] = parent[parent[i]];
      return i;
    };
    std::vector<uint32_t> inside;  // edges of the chains inside a merged junction
    for (uint32_t j = 0; j < pos_.size(); ++j) {
      if (!junction_[j]) continue;
      for (uint32_t e : incident_[j]) {
        const Chain c = walk(j, e);
        const uint32_t k = c.nodes.back();
        if (k == j || !junction_[k] || c.length >= std::min(widthAt(j), widthAt(k))) continue;
        parent[find(k)] = find(j);
        inside.insert(inside.end(), c.edges.begin(), c.edges.end());
      }
    }
    for (uint32_t e : inside) edges_[e].removed = true;
    std::map<uint32_t, std::pair<DVec2, int>> centre;  // root -> sum of members' centres, count
    for (uint32_t j = 0; j < pos_.size(); ++j)
      if (junction_[j]) {
        auto& [sum, count] = centre[find(j)];
        sum += pos_[j];
        ++count;
      }
    for (const auto& [root, sc] : centre) pos_[root] = sc.first / double(sc.second);
    for (auto& list : incident_) list.clear();
    for (uint32_t e = 0; e < edges_.size(); ++e) {
      Edge& ed = edges_[e];
      if (ed.removed) continue;
      if (junction_[ed.a]) ed.a = find(ed.a);
      if (junction_[ed.b]) ed.b = find(ed.b);
      if (ed.a == ed.b) {
        ed.removed = true;
        continue;
      }
      incident_[ed.a].push_back(e);
      incident_[ed.b].push_back(e);
    }
    return centre.size();
  }

  // Drops every dead-end chain shorter than the road is wide where it joins the rest; returns how many.
  size_t pruneSpurs() {
    std::vector<uint32_t> spur_edges;
    size_t spurs = 0;
    for (uint32_t n = 0; n < pos_.size(); ++n) {
      if (degree(n) != 1) continue;
      uint32_t first = 0;
      for (uint32_t e : incident_[n])
        if (!edges_[e].removed) first = e;
      const Chain c = walk(n, first);
      const uint32_t end = c.nodes.back();
      if (degree(end) < 3 || c.length >= widthAt(end)) continue;
      spur_edges.insert(spur_edges.end(), c.edges.begin(), c.edges.end());
      ++spurs;
    }
    for (uint32_t e : spur_edges) edges_[e].removed = true;
    return spurs;
  }

  // Moves every junction left onto the centre lines leading to it: the least-squares meeting point of the lines
  // through each chain's first node and its node a road's width further on (the chord midpoints there lie midway
  // between parallel borders; a triangle's centre does not). A junction left with one chain (a road's end) moves
  // onto that chain's line; one whose lines are parallel moves across them only.
  void placeJunctions() {
    std::vector<std::pair<uint32_t, DVec2>> moves;
    for (uint32_t j = 0; j < pos_.size(); ++j) {
      if (!junction_[j] || degree(j) == 0) continue;
      const double reach = widthAt(j);
      glm::dmat2 a(0.0);
      DVec2 b(0.0);
      for (uint32_t e : incident_[j]) {
        if (edges_[e].removed) continue;
        const Chain c = walk(j, e);
        if (c.nodes.size() < 3) continue;  // straight to another junction or end: no line of its own
        const DVec2 p = pos_[c.nodes[1]];
        DVec2 q = p;
        for (size_t k = 2; k < c.nodes.size() && glm::distance(q, p) < reach; ++k) q = pos_[c.nodes[k]];
        const double len = glm::distance(p, q);
        if (!(len > 0.0)) continue;
        const DVec2 n(-(q - p).y / len, (q - p).x / len);
        const glm::dmat2 nn = glm::outerProduct(n, n);
        a += nn;
        b += nn * p;
      }
      // A small pull towards the current position fixes the directions the lines leave free.
      const double eps = 1e-7 * std::max(a[0][0] + a[1][1], 1e-9);
      a += glm::dmat2(eps);
      b += eps * pos_[j];
      const DVec2 x = glm::inverse(a) * b;
      if (std::isfinite(x.x) && std::isfinite(x.y) && glm::distance(x, pos_[j]) < reach) moves.emplace_back(j, x);
    }
    for (const auto& [j, x] : moves) pos_[j] = x;
  }

  // The chains between nodes of degree other than 2, then the loops left, as polylines.
  std::vector<StreetPolyline> polylines(float min_width, double tolerance) const {
    std::vector<StreetPolyline> out;
    std::vector<bool> used(edges_.size(), false);
    auto emit = [&](const Chain& c) {
      std::vector<double> widths;
      for (uint32_t e : c.edges) {
        used[e] = true;
        widths.push_back(edges_[e].width);
      }
      std::nth_element(widths.begin(), widths.begin() + std::ptrdiff_t(widths.size() / 2), widths.end());
      StreetPolyline line;
      for (uint32_t n : c.nodes) line.points.push_back(pos_[n]);
      line.points = simplifyPolyline(line.points, tolerance);
      line.width = std::max(min_width, float(widths[widths.size() / 2]));
      out.push_back(std::move(line));
    };
    for (int pass = 0; pass < 2; ++pass)  // ends and junctions first, then loops
      for (uint32_t n = 0; n < pos_.size(); ++n) {
        if (pass == 0 && degree(n) == 2) continue;
        for (uint32_t e : incident_[n])
          if (!edges_[e].removed && !used[e]) emit(walk(n, e));
      }
    return out;
  }

 private:
  std::vector<DVec2> pos_;
  std::vector<bool> junction_;
  std::vector<std::vector<uint32_t>> incident_;
  std::vector<Edge> edges_;
};

constexpr uint32_t kNoSample = std::numeric_limits<uint32_t>::max();

// Splits every border edge longer than the road is wide across it (the distance from the edge to the opposite corner
// of its triangle inside the road) into equal pieces that are not, nor shorter than `min_spacing`, until no edge
// needs it (a few rounds: splitting changes the triangles) or kMaxSamples samples are in. A chord of a triangle then
// joins the two borders of the road, and its midpoint lies between them.
void refineBorders(Cdt& cdt, double min_spacing) {
  double budget = kMaxSamples;  // samples left to insert
  struct Split {
    Cdt::Vertex_handle u, w;
    double pieces;
  };
  for (int round = 0; round < kMaxRefinements; ++round) {
    markNesting(cdt);
    std::vector<Split> splits;
    for (Cdt::Face_handle f : cdt.finite_face_handles()) {
      if (f->info().nesting % 2 != 1) continue;
      for (int i = 0; i < 3; ++i) {
        if (!cdt.is_constrained({f, i})) continue;
        const Cdt::Vertex_handle u = f->vertex(Cdt::cw(i)), w = f->vertex(Cdt::ccw(i));
        const DVec2 a = toDVec2(u->point()), b = toDVec2(w->point());
        const double across = pointLineDistance(toDVec2(f->vertex(i)->point()), a, b);
        if (!(across >= kMinRoadWidth)) continue;
        const double pieces = std::min(std::ceil(glm::distance(a, b) / std::max(across, min_spacing)), kMaxSamples);
        if (pieces > 1.0) splits.push_back({u, w, pieces});
      }
    }
    if (splits.empty()) return;
    // The constraints to split go first, then every sample of the round at once (CGAL sorts them spatially; one at a
    // time along a long edge, each insertion walked the fan of thin triangles from afar), then the pieces.
    std::vector<std::pair<Ik::Point_2, uint32_t>> samples;
    std::vector<std::pair<size_t, size_t>> ranges;  // per split: its samples in `samples`
    std::vector<const Split*> done;
    for (const Split& s : splits) {
      Cdt::Face_handle f;
      int i = 0;
      if (!cdt.is_edge(s.u, s.w, f, i) || !cdt.is_constrained({f, i})) continue;
      if ((budget -= s.pieces) < 0.0) break;
      cdt.remove_constrained_edge(f, i);
      const DVec2 a = toDVec2(s.u->point()), b = toDVec2(s.w->point());
      const size_t first = samples.size();
      for (double k = 1.0; k < s.pieces; ++k) {
        const DVec2 p = a + (b - a) * (k / s.pieces);
        samples.emplace_back(Ik::Point_2(p.x, p.y), uint32_t(samples.size()));
      }
      ranges.emplace_back(first, samples.size());
      done.push_back(&s);
    }
    for (Cdt::Vertex_handle v : cdt.finite_vertex_handles()) v->info() = kNoSample;
    cdt.insert(samples.begin(), samples.end());
    std::vector<Cdt::Vertex_handle> sample_vertex(samples.size());
    for (Cdt::Vertex_handle v : cdt.finite_vertex_handles())
      if (v->info() != kNoSample) sample_vertex[v->info()] = v;
    for (size_t k = 0; k < done.size(); ++k) {
      Cdt::Vertex_handle prev = done[k]->u;
      for (size_t j = ranges[k].first; j <= ranges[k].second; ++j) {
        const Cdt::Vertex_handle v = j < ranges[k].second ? sample_vertex[j] : done[k]->w;
        if (v == Cdt::Vertex_handle() || v == prev) continue;  // the sample fell on an existing corner
        cdt.insert_constraint(prev, v);
        prev = v;
      }
    }
    if (budget < 0.0) break;
  }
  markNesting(cdt);
}

// The chordal axis of the triangulated road areas.
AxisGraph chordalAxis(const Cdt& cdt, size_t& triangles) {
  AxisGraph g;
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> chord_node;  // chord (vertex ids) -> node at its midpoint
  auto point = [](Cdt::Vertex_handle v) { return toDVec2(v->point()); };
  auto chord = [&](Cdt::Face_handle f, int i) {
    const Cdt::Vertex_handle a = f->vertex(Cdt::cw(i)), b = f->vertex(Cdt::ccw(i));
    const auto key = std::minmax(a->info(), b->info());
    const auto [it, added] = chord_node.try_emplace({key.first, key.second}, 0);
    if (added) it->second = g.addNode(0.5 * (point(a) + point(b)), false);
    return it->second;
  };
  for (Cdt::Face_handle f : cdt.finite_face_handles()) {
    if (f->info().nesting % 2 != 1) continue;
    ++triangles;
    std::vector<int> inner;
    int border = -1;
    for (int i = 0; i < 3; ++i) {
      if (cdt.is_constrained({f, i}))
        border = i;
      else
        inner.push_back(i);
    }
    if (inner.size() == 2) {
      // A sleeve: the road's width is the distance from the apex to the border edge's line.
      const double width = pointLineDistance(point(f->vertex(border)), point(f->vertex(Cdt::cw(border))),
                                             point(f->vertex(Cdt::ccw(border))));
      g.addEdge(chord(f, inner[0]), chord(f, inner[1]), width);
    } else if (inner.size() == 3) {
      const DVec2 centre = (point(f->vertex(0)) + point(f->vertex(1)) + point(f->vertex(2))) / 3.0;
      const uint32_t j = g.addNode(centre, true);
      for (int i : inner)
        g.addEdge(j, chord(f, i), glm::distance(point(f->vertex(Cdt::cw(i))), point(f->vertex(Cdt::ccw(i)))));
    }
  }
  return g;
}

}  // namespace

std::vector<StreetPolyline> roadCentreLines(const std::vector<std::vector<std::vector<DVec2>>>& polygons,
                                            RoadCentreLineStats* stats, float min_width) {
  RoadCentreLineStats local;
  RoadCentreLineStats& st = stats ? *stats : local;
  st = RoadCentreLineStats();
  st.polygons = polygons.size();

  CGAL::Polygon_set_2<Ek> united;
  {
    std::vector<EPolygonWithHoles> pieces;
    for (const auto& rings : polygons) {
      EPolygon outer;
      if (rings.empty() || !toPolygon(rings[0], true, outer)) {
        ++st.invalid_polygons;
        continue;
      }
      EPolygonWithHoles pwh(outer);
      for (size_t h = 1; h < rings.size(); ++h) {
        EPolygon hole;
        if (toPolygon(rings[h], false, hole)) pwh.add_hole(hole);
      }
      pieces.push_back(std::move(pwh));
    }
    if (pieces.empty()) return {};
    try {
      united.join(pieces.begin(), pieces.end());
    } catch (const std::exception&) {
      // Holes that are not inside their outer ring (malformed input) break CGAL's preconditions: unite the outer
      // rings alone.
      CGAL::Polygon_set_2<Ek> outers;
      std::vector<EPolygon> rings;
      for (const auto& p : pieces) rings.push_back(p.outer_boundary());
      outers.join(rings.begin(), rings.end());
      united = outers;
    }
  }
  std::vector<EPolygonWithHoles> areas;
  united.polygons_with_holes(std::back_inserter(areas));
  st.united = areas.size();

  std::vector<IPolygonWithHoles> cleaned;
  double perimeter = 0.0;
  for (const EPolygonWithHoles& area : areas) {
    if (area.is_unbounded()) continue;
    IPolygon outer = toInexact(area.outer_boundary());
    st.cleaned_vertices += cleanRing(outer);
    if (outer.size() < 3) {
      ++st.degenerate_areas;
      continue;
    }
    IPolygonWithHoles ip(outer);
    for (auto h = area.holes_begin(); h != area.holes_end(); ++h) {
      IPolygon hole = toInexact(*h);
      st.cleaned_vertices += cleanRing(hole);
      if (hole.size() >= 3) ip.add_hole(hole);
    }
    auto addPerimeter = [&](const IPolygon& ring) {
      for (auto e = ring.edges_begin(); e != ring.edges_end(); ++e) perimeter += std::sqrt(e->squared_length());
    };
    addPerimeter(ip.outer_boundary());
    for (auto h = ip.holes_begin(); h != ip.holes_end(); ++h) addPerimeter(*h);
    cleaned.push_back(std::move(ip));
  }
  if (!std::isfinite(perimeter)) {  // coordinates near the double range: no triangulation can hold them
    st.degenerate_areas += cleaned.size();
    return {};
  }
  if (cleaned.empty()) return {};

  // All corners at once, spatially sorted by CGAL, then the ring edges as constraints between them (inserting each
  // ring in order would walk the triangulation from afar for every corner); then the borders are refined.
  const double min_spacing = std::max(kMinSpacing, perimeter / kMaxSamples);
  std::vector<Ik::Point_2> corners;
  std::vector<std::pair<size_t, size_t>> constraints;
  auto addRing = [&](const IPolygon& ring) {
    const size_t first = corners.size();
    corners.insert(corners.end(), ring.vertices_begin(), ring.vertices_end());
    for (size_t k = 0; k < ring.size(); ++k) constraints.emplace_back(first + k, first + (k + 1) % ring.size());
  };
  for (const IPolygonWithHoles& area : cleaned) {
    addRing(area.outer_boundary());
    for (auto h = area.holes_begin(); h != area.holes_end(); ++h) addRing(*h);
  }
  Cdt cdt;
  cdt.insert_constraints(corners.begin(), corners.end(), constraints.begin(), constraints.end());
  refineBorders(cdt, min_spacing);
  uint32_t id = 0;
  for (Cdt::Vertex_handle v : cdt.finite_vertex_handles()) v->info() = id++;

  AxisGraph axis = chordalAxis(cdt, st.triangles);
  st.junctions = axis.mergeJunctions();
  for (int pass = 0; pass < 2; ++pass) st.spurs += axis.pruneSpurs();
  axis.placeJunctions();
  return axis.polylines(min_width, kSimplifyShare * min_spacing);
}

}  // namespace farfield::geodata
