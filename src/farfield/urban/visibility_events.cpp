// Decoret et al. 1999, "Multi-layered impostors for accelerated rendering", section 4.1: visibility-event weights.
#include "farfield/urban/visibility_events.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "farfield/core/check.h"
#include "farfield/core/error.h"

namespace farfield::urban {

namespace {

DVec2 d2(const Vec2& v) { return DVec2(v.x, v.y); }

// A point expressed in the cell's frame: s along [PQ] from P (metres), d its signed distance to the line (PQ)
// (positive to the left of P -> Q).
struct CellPoint {
  double s = 0.0;
  double d = 0.0;
};

// The cell's frame: origin P, x along P -> Q. A point cell (P == Q) gets the x axis of the world; any direction
// works there since [PQ] has a single point.
struct CellFrame {
  DVec2 origin{0.0};
  DVec2 u{1.0, 0.0};
  double length = 0.0;

  explicit CellFrame(const DVec2& p, const DVec2& q) : origin(p) {
    length = glm::length(q - p);
    if (length > 0.0) u = (q - p) / length;
  }
  CellPoint toCell(const DVec2& x) const {
    const DVec2 r = x - origin;
    return {glm::dot(r, u), cross2(u, r)};
  }
  DVec2 pointAt(double s) const { return origin + u * s; }
};

// Result of the extremal search in the cell frame: the along-segment abscissae s of the extremal points.
struct Extremes {
  double min_angle = 0.0, max_angle = 0.0;
  double s_min = 0.0, s_max = 0.0;
  AngleCase angle_case = AngleCase::General;
  double variation() const { return max_angle - min_angle; }
};

// Below this distance (relative to the size of the configuration) a point counts as lying on the line (PQ). The
// inputs are floats (about 1e-7 relative), so a real off-line point is many orders of magnitude above it.
constexpr double kOnLineRelative = 1e-12;
// |1 - y_B| below this selects the paper's parallel configuration. The general formulas stay accurate much closer
// to 1 than this (see below), so the switch only needs to catch configurations built parallel, where y_B comes
// out as 1 up to the rounding of the frame change.
constexpr double kParallelEps = 1e-12;

// Angle AMB in the normalised frame of Figure 3: A = (0, 1), B = (x_B, y_B), M = (x, 0). AM = (x, -1) and
// BM = (x - x_B, -y_B), so equation 2's numerator is their dot product and the sine comes from their cross product;
// atan2 of the two is accurate over the whole [0, pi] range, where acos of equation 2 loses digits near 0 and pi.
double normalisedAngle(double x, double xb, double yb) {
  const double dot = x * (x - xb) + yb;
  const double crs = x * (-yb) - (-1.0) * (x - xb);
  return std::atan2(std::abs(crs), dot);
}

// The paper's section 4.1 for one pair of points. Steps:
//  1. Take as A the point farther from (PQ) (the angle AMB is symmetric in A and B), so that |y_B| <= 1 and the
//     normalisation below never divides by a tiny distance while the other point is far.
//  2. Degenerate cases: both points on (PQ) (constant angle) or one of them on [PQ] (undefined angle).
//  3. Change to Figure 3's frame: x along (PQ), A at (0, 1) — a similarity (translation, rotation, possibly a
//     mirror, uniform scaling by 1 / dist(A, (PQ))), which preserves angles.
//  4. y_B == 1: (AB) parallel to (PQ); the candidates are P, Q and H = (x_B / 2, 0), the foot of [AB]'s
//     perpendicular bisector. Otherwise the candidates are P, Q and equations 3-5's M1, M2, M3 where they exist
//     and lie on [PQ].
//  5. The angle is continuous on [PQ] (neither point on it), so its extrema are among the candidates: evaluate
//     the angle there and keep the largest and smallest.
Extremes extremesInCell(double length, CellPoint a, CellPoint b) {
  if (std::abs(a.d) < std::abs(b.d)) std::swap(a, b);
  Extremes out;
  const double scale = 1.0 + length + std::abs(a.s) + std::abs(b.s) + std::abs(a.d);
  const double on_line = kOnLineRelative * scale;
  auto onSegment = [&](const CellPoint& c) { return std::abs(c.d) <= on_line && c.s >= 0.0 && c.s <= length; };
  if (onSegment(a) || onSegment(b)) {
    // The viewer walks through the point: seen from M on either side of it, its direction flips by pi.
    out.angle_case = AngleCase::OnCell;
    out.min_angle = 0.0;
    out.max_angle = kPi;
    out.s_min = out.s_max = onSegment(b) ? b.s : a.s;
    return out;
  }
  if (std::abs(a.d) <= on_line) {
    // Both on (PQ), both off [PQ]: from every M they lie straight ahead or behind.
    out.angle_case = AngleCase::Collinear;
    const bool same_side = (a.s < 0.0) == (b.s < 0.0);
    out.min_angle = out.max_angle = same_side ? 0.0 : kPi;
    out.s_min = out.s_max = 0.0;
    return out;
  }

  const double k = 1.0 / std::abs(a.d);
  const double sigma = a.d > 0.0 ? 1.0 : -1.0;
  const double xb = (b.s - a.s) * k;
  const double yb = b.d * sigma * k;
  const double xp = -a.s * k;
  const double xq = (length - a.s) * k;

  std::array<double, 5> candidates{};
  size_t count = 0;
  candidates[count++] = xp;
  candidates[count++] = xq;
  auto addIfOnCell = [&](double x) {
    if (std::isfinite(x) && x >= xp && x <= xq) candidates[count++] = x;
  };

  // Minimum over `min_count` first candidates, maximum over all: the parallel case takes its minimum at P or Q
  // only (the angle rises to H and falls after it), the general case over every candidate.
  size_t min_count = 0;
  if (std::abs(1.0 - yb) <= kParallelEps) {
    out.angle_case = AngleCase::Parallel;
    min_count = 2;
    addIfOnCell(0.5 * xb);  // H: A = (0, 1), B = (x_B, 1), the median of [AB] is x = x_B / 2
  } else {
    out.angle_case = AngleCase::General;
    const double a_coef = 1.0 - yb;  // > 0: |y_B| <= 1 and the parallel case is excluded
    addIfOnCell(xb / a_coef);        // equation 3: M1, where (AB) meets (PQ) (angle 0 or pi)
    const double disc = yb * (a_coef * a_coef + xb * xb);
    if (disc >= 0.0) {
      // Equations 4 and 5, x = (x_B +- sqrt(disc)) / (1 - y_B), are the roots of
      // (1 - y_B) x^2 - 2 x_B x + (x_B^2 - y_B (1 - y_B)) = 0. As y_B -> 1 one of them is a difference of nearly
      // equal numbers divided by a small one; Vieta's product r1 * r2 = c / a gives that root without the
      // cancellation (and it tends to x_B / 2, the parallel case's H). Same roots, stable arithmetic.
      const double root = std::sqrt(disc);
      const double qq = xb + (xb >= 0.0 ? root : -root);
      const double r1 = qq / a_coef;
      const double c_coef = xb * xb - yb * a_coef;
      const double r2 = qq != 0.0 ? c_coef / qq : r1;
      addIfOnCell(r1);
      addIfOnCell(r2);
    }
    min_count = count;
  }

  double best_min = std::numeric_limits<double>::infinity(), best_max = -1.0;
  double x_min = xp, x_max = xp;
  for (size_t c = 0; c < count; ++c) {
    const double angle = normalisedAngle(candidates[c], xb, yb);
    if (c < min_count && angle < best_min) {
      best_min = angle;
      x_min = candidates[c];
    }
    if (angle > best_max) {
      best_max = angle;
      x_max = candidates[c];
    }
  }
  out.min_angle = best_min;
  out.max_angle = best_max;
  // Back to the cell frame: x is in units of dist(A, (PQ)) from A's foot.
  out.s_min = a.s + x_min / k;
  out.s_max = a.s + x_max / k;
  return out;
}

struct PreparedObject {
  std::vector<CellPoint> points;  // representative points in the cell frame
  Polygon2 zone;                  // critical zone
  Box2 box;                       // footprint bounds
  Box2 zone_box;
  bool on_cell = false;           // the footprint meets [PQ]
};

bool finite(const Vec2& v) { return std::isfinite(v.x) && std::isfinite(v.y); }

// The polygon's edges as segments; a single point is one zero-length edge, two points one edge.
template <class Visit>
void forEachEdge(const Polygon2& poly, Visit&& visit) {
  const size_t n = poly.size();
  if (n == 0) return;
  if (n == 1) {
    visit(poly[0], poly[0]);
    return;
  }
  if (n == 2) {
    visit(poly[0], poly[1]);
    return;
  }
  for (size_t i = 0; i < n; ++i) visit(poly[i], poly[(i + 1) % n]);
}

// p inside or on a counter-clockwise convex polygon with >= 3 vertices.
bool inConvex(const Vec2& p_in, const Polygon2& zone) {
  const DVec2 p = d2(p_in);
  for (size_t i = 0, n = zone.size(); i < n; ++i) {
    const DVec2 a = d2(zone[i]), b = d2(zone[(i + 1) % n]);
    if (cross2(b - a, p - a) < 0.0) return false;
  }
  return true;
}

double segmentDistance(const DVec2& a, const DVec2& b, const DVec2& c, const DVec2& d) {
  auto pointSeg = [](const DVec2& p, const DVec2& s0, const DVec2& s1) {
    const DVec2 e = s1 - s0;
    const double len2 = glm::dot(e, e);
    const double t = len2 > 0.0 ? std::clamp(glm::dot(p - s0, e) / len2, 0.0, 1.0) : 0.0;
    return glm::length(p - (s0 + t * e));
  };
  return std::min({pointSeg(a, c, d), pointSeg(b, c, d), pointSeg(c, a, b), pointSeg(d, a, b)});
}

}  // namespace

ExtremalAngles extremalAngles(const DVec2& p, const DVec2& q, const DVec2& a, const DVec2& b) {
  FF_CHECK(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(q.x) && std::isfinite(q.y));
  FF_CHECK(std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(b.x) && std::isfinite(b.y));
  const CellFrame frame(p, q);
  const Extremes e = extremesInCell(frame.length, frame.toCell(a), frame.toCell(b));
  ExtremalAngles out;
  out.min_angle = e.min_angle;
  out.max_angle = e.max_angle;
  out.argmin = frame.pointAt(std::clamp(e.s_min, 0.0, frame.length));
  out.argmax = frame.pointAt(std::clamp(e.s_max, 0.0, frame.length));
  out.angle_case = e.angle_case;
  return out;
}

double EventGraph::weight(uint32_t i, uint32_t j) const {
  FF_CHECK(i < adjacency_.size() && j < adjacency_.size());
  const auto& edges = adjacency_[i];
  auto it = std::lower_bound(edges.begin(), edges.end(), j,
                             [](const WeightEdge& e, uint32_t to) { return e.to < to; });
  return it != edges.end() && it->to == j ? it->weight : 0.0;
}

void EventGraph::setWeight(uint32_t i, uint32_t j, double weight) {
  FF_CHECK(i < adjacency_.size() && j < adjacency_.size());
  if (!(weight > 0.0) || i == j) return;
  auto put = [&](uint32_t from, uint32_t to) {
    auto& edges = adjacency_[from];
    auto it = std::lower_bound(edges.begin(), edges.end(), to,
                               [](const WeightEdge& e, uint32_t t) { return e.to < t; });
    if (it != edges.end() && it->to == to) {
      it->weight = std::max(it->weight, weight);
      return false;
    }
    edges.insert(it, WeightEdge{to, weight});
    return true;
  };
  const bool added = put(i, j);
  put(j, i);
  if (added) ++edge_count_;
  max_weight_ = std::max(max_weight_, weight);
}

Polygon2 criticalZone(const Polygon2& footprint, const CellSegment& cell) {
  std::vector<Vec2> points(footprint.begin(), footprint.end());
  points.push_back(cell.p);
  points.push_back(cell.q);
  return convexHull(std::move(points));
}

bool intersectsConvex(const Polygon2& object, const Polygon2& zone) {
  if (object.empty() || zone.empty()) return false;
  // A vertex of the object inside the zone, a vertex of the zone inside the object, or two crossing edges: for
  // two closed polygons one of the three holds exactly when they meet.
  if (zone.size() >= 3)
    for (const Vec2& v : object)
      if (inConvex(v, zone)) return true;
  if (object.size() >= 3)
    for (const Vec2& v : zone)
      if (pointInPolygon(v, object)) return true;
  bool hit = false;
  forEachEdge(object, [&](const Vec2& a, const Vec2& b) {
    if (hit) return;
    forEachEdge(zone, [&](const Vec2& c, const Vec2& d) {
      if (!hit && segmentsIntersect(a, b, c, d)) hit = true;
    });
  });
  return hit;
}

double distanceToCell(const Polygon2& footprint, const CellSegment& cell) {
  if (footprint.empty()) return std::numeric_limits<double>::infinity();
  const Polygon2 segment{cell.p, cell.q};
  if (intersectsConvex(footprint, cell.p == cell.q ? Polygon2{cell.p} : segment)) return 0.0;
  double best = std::numeric_limits<double>::infinity();
  forEachEdge(footprint, [&](const Vec2& a, const Vec2& b) {
    best = std::min(best, segmentDistance(d2(a), d2(b), d2(cell.p), d2(cell.q)));
  });
  return best;
}

// Representative points. Seen from a point M of the ground plane, an extruded footprint's outline in the image is
// bounded left and right by the vertical edges through two of its footprint vertices (the tangent points of the
// footprint's cone from M), and the inner silhouette edges of a non-convex block (a courtyard opening, an L
// corner) are vertical edges through footprint vertices as well. A visibility event between two blocks, one
// covering or uncovering the other, is one such vertical silhouette edge crossing another in the image, and its
// horizontal image position is the direction of that vertex from M. So the variation of AMB over vertex pairs
// measures directly the relative image motion of the edges that cause de-occlusion. Top corners add nothing: the
// paper's criterion works on orthogonal projections onto the ground, where a top corner is its footprint vertex.
// Points inside edges are not needed: an edge's interior is never a silhouette from a point off its line.
// HullVertices keeps only the outer silhouettes (the angular extent of a footprint equals its hull's); it drops
// the inner ones of non-convex blocks, for fewer pairs.
EventGraph computeEventGraph(std::span<const EventObject> objects, const CellSegment& cell,
                             const VisibilityEventOptions& options) {
  if (!finite(cell.p) || !finite(cell.q)) throw Error("viewing cell", "segment end point is not finite");
  if (!(options.landmark_boost >= 1.0) || !std::isfinite(options.landmark_boost))
    throw Error("visibility event options", "landmark_boost must be a finite number >= 1");
  const CellFrame frame(d2(cell.p), d2(cell.q));

  std::vector<PreparedObject> prepared(objects.size());
  for (size_t i = 0; i < objects.size(); ++i) {
    const Polygon2& footprint = objects[i].footprint;
    if (footprint.empty()) throw Error("object " + std::to_string(i), "empty footprint, expected >= 1 vertex");
    for (size_t v = 0; v < footprint.size(); ++v)
      if (!finite(footprint[v]))
        throw Error("object " + std::to_string(i), "footprint vertex " + std::to_string(v) + " is not finite");
    PreparedObject& po = prepared[i];
    po.box = polygonBounds(footprint);
    po.zone = criticalZone(footprint, cell);
    po.zone_box = polygonBounds(po.zone);
    po.on_cell = distanceToCell(footprint, cell) == 0.0;
    const Polygon2 points =
        options.points == RepresentativePoints::HullVertices ? convexHull(footprint) : footprint;
    po.points.reserve(points.size());
    for (const Vec2& v : points) po.points.push_back(frame.toCell(d2(v)));
  }

  EventGraph graph(objects.size());
  for (uint32_t i = 0; i < objects.size(); ++i) {
    const PreparedObject& oi = prepared[i];
    for (uint32_t j = i + 1; j < objects.size(); ++j) {
      const PreparedObject& oj = prepared[j];
      ++graph.object_pairs;
      // The paper's test in both directions: when a ray from M meets both objects, the nearer one lies inside the
      // farther one's critical zone (the segment from M to the farther point lies in that hull), so either may be
      // the one inside; the relation is symmetric.
      const bool i_in_j = oi.box.overlaps(oj.zone_box) && intersectsConvex(objects[i].footprint, oj.zone);
      const bool j_in_i = !i_in_j && oj.box.overlaps(oi.zone_box) && intersectsConvex(objects[j].footprint, oi.zone);
      if (!i_in_j && !j_in_i) continue;
      ++graph.zone_pairs;
      double w = 0.0;
      if (oi.on_cell || oj.on_cell) {
        // The viewer walks through one of the two: seen from either side of it, anything can flip by pi.
        w = kPi;
        ++graph.on_cell;
      } else {
        for (const CellPoint& a : oi.points)
          for (const CellPoint& b : oj.points) w = std::max(w, extremesInCell(frame.length, a, b).variation());
        graph.point_pairs += oi.points.size() * oj.points.size();
      }
      if (objects[i].landmark || objects[j].landmark) w *= options.landmark_boost;
      graph.setWeight(i, j, w);
    }
  }
  return graph;
}

}  // namespace farfield::urban
