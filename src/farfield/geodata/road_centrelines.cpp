// Road centre lines from the straight skeleton of the united road surfaces (see road_centrelines.h). The union is
// computed with exact constructions (overlapping rectangles of crossing roads share edges and corners, which
// inexact arithmetic turns into slivers); the skeleton with the inexact kernel CGAL recommends for it.
#include "farfield/geodata/road_centrelines.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include <CGAL/Arr_segment_traits_2.h>
#include <CGAL/Boolean_set_operations_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_set_2.h>
#include <CGAL/Polygon_with_holes_2.h>
#include <CGAL/Surface_sweep_2_algorithms.h>
#include <CGAL/create_straight_skeleton_from_polygon_with_holes_2.h>
#include <set>

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
// before the skeleton: an unclosed ring's 1.5 cm notch left CGAL's skeleton builder reading freed memory (a fuzz
// finding), and such vertices change the centre lines by less than a road marking is wide.
constexpr double kCleanTolerance = 0.05;

double distanceToSegment(const Ik::Point_2& p, const Ik::Point_2& a, const Ik::Point_2& b) {
  const DVec2 pa(p.x() - a.x(), p.y() - a.y()), ba(b.x() - a.x(), b.y() - a.y());
  const double len2 = glm::dot(ba, ba);
  const double t = len2 > 0.0 ? std::clamp(glm::dot(pa, ba) / len2, 0.0, 1.0) : 0.0;
  return glm::length(pa - t * ba);
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

// True when the rings' edges meet only at the shared ends of neighbouring edges: no crossing, no touching, no
// overlap, no vertex used twice. CGAL's straight skeleton requires this of its input and does not check it.
bool ringsAreDisjointAndSimple(const IPolygonWithHoles& p) {
  using Traits = CGAL::Arr_segment_traits_2<Ek>;
  std::vector<Traits::Curve_2> edges;
  std::set<std::pair<double, double>> vertices;
  size_t vertex_count = 0;
  auto add = [&](const IPolygon& ring) {
    for (auto e = ring.edges_begin(); e != ring.edges_end(); ++e)
      edges.emplace_back(Ek::Point_2(e->source().x(), e->source().y()), Ek::Point_2(e->target().x(), e->target().y()));
    for (auto v = ring.vertices_begin(); v != ring.vertices_end(); ++v) vertices.emplace(v->x(), v->y());
    vertex_count += ring.size();
  };
  add(p.outer_boundary());
  for (auto h = p.holes_begin(); h != p.holes_end(); ++h) add(*h);
  return vertices.size() == vertex_count && !CGAL::do_curves_intersect(edges.begin(), edges.end());
}

// The skeleton wants the outer ring counter-clockwise and the holes clockwise; cleaning can flip a sliver.
bool orientationsHold(const IPolygonWithHoles& p) {
  if (p.outer_boundary().orientation() != CGAL::COUNTERCLOCKWISE) return false;
  for (auto h = p.holes_begin(); h != p.holes_end(); ++h)
    if (h->orientation() != CGAL::CLOCKWISE) return false;
  return true;
}

struct Segment {
  DVec2 a, b;
  double ta = 0.0, tb = 0.0;  // distance of each end to the border
  int na = -1, nb = -1;       // skeleton node ids of the ends
};

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

  std::vector<Segment> segments;
  std::map<int, int> degree;  // per skeleton node (ids made unique across areas), inner-bisector degree
  int node_base = 0;
  for (const EPolygonWithHoles& area : areas) {
    if (area.is_unbounded()) continue;
    IPolygon outer = toInexact(area.outer_boundary());
    st.cleaned_vertices += cleanRing(outer);
    IPolygonWithHoles ip(outer);
    for (auto h = area.holes_begin(); h != area.holes_end(); ++h) {
      IPolygon hole = toInexact(*h);
      st.cleaned_vertices += cleanRing(hole);
      if (hole.size() >= 3) ip.add_hole(hole);
    }
    if (outer.size() < 3 || !ringsAreDisjointAndSimple(ip) || !orientationsHold(ip)) {
      ++st.degenerate_areas;
      continue;
    }
    auto skeleton = decltype(CGAL::create_interior_straight_skeleton_2(ip, Ik()))();
    try {
      skeleton = CGAL::create_interior_straight_skeleton_2(ip, Ik());
    } catch (const std::exception&) {
      skeleton.reset();
    }
    if (!skeleton) continue;
    int max_id = 0;
    for (auto v = skeleton->vertices_begin(); v != skeleton->vertices_end(); ++v) max_id = std::max(max_id, int(v->id()));
    for (auto h = skeleton->halfedges_begin(); h != skeleton->halfedges_end(); ++h) {
      if (!h->is_inner_bisector() || h->id() > h->opposite()->id()) continue;  // each edge once
      const auto& a = h->opposite()->vertex();
      const auto& b = h->vertex();
      Segment s;
      s.a = DVec2(a->point().x(), a->point().y());
      s.b = DVec2(b->point().x(), b->point().y());
      s.ta = a->time();
      s.tb = b->time();
      s.na = node_base + int(a->id());
      s.nb = node_base + int(b->id());
      if (!(glm::distance(s.a, s.b) > 0.0)) continue;
      ++degree[s.na];
      ++degree[s.nb];
      segments.push_back(s);
    }
    node_base += max_id + 1;
  }
  st.skeleton_edges = segments.size();

  std::vector<StreetPolyline> out;
  out.reserve(segments.size());
  for (const Segment& s : segments) {
    // A dead-end branch shorter than the road is wide is the trace of a corner of the border, not a street.
    const bool dead_end = degree[s.na] == 1 || degree[s.nb] == 1;
    const bool connected = degree[s.na] > 1 || degree[s.nb] > 1;
    if (dead_end && connected && glm::distance(s.a, s.b) < 2.0 * std::max(s.ta, s.tb)) {
      ++st.spurs;
      continue;
    }
    StreetPolyline line;
    line.points = {s.a, s.b};
    line.width = std::max(min_width, float(s.ta + s.tb));
    out.push_back(std::move(line));
  }
  return out;
}

}  // namespace farfield::geodata
