#include "farfield/core/polygon2d.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

namespace farfield {

namespace {

// Vertices are stored as float, but every predicate below works on doubles: the difference of two floats of
// similar magnitude is exact in double, so orientation tests on footprint coordinates do not flip sign from
// rounding the way float arithmetic would.
DVec2 d2(const Vec2& v) { return DVec2(v.x, v.y); }
Vec2 f2(const DVec2& v) { return Vec2(float(v.x), float(v.y)); }

double orient(const DVec2& a, const DVec2& b, const DVec2& c) { return cross2(b - a, c - a); }

int sign(double v) { return (v > 0.0) - (v < 0.0); }

// c lies in the bounding box of [a, b]; with orient(a, b, c) == 0 this means c is on the segment.
bool onSegmentBox(const DVec2& a, const DVec2& b, const DVec2& c) {
  return std::min(a.x, b.x) <= c.x && c.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= c.y &&
         c.y <= std::max(a.y, b.y);
}

double distPointSegment(const DVec2& p, const DVec2& a, const DVec2& b) {
  DVec2 ab = b - a;
  double len2 = glm::dot(ab, ab);
  double t = len2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return glm::length(p - (a + t * ab));
}

}  // namespace

double signedArea(const Polygon2& polygon) {
  const size_t n = polygon.size();
  if (n < 3) return 0.0;
  // Relative to the first vertex: keeps the products small for footprints far from the origin.
  const DVec2 o = d2(polygon[0]);
  double twice = 0.0;
  for (size_t i = 1; i + 1 < n; ++i) twice += cross2(d2(polygon[i]) - o, d2(polygon[i + 1]) - o);
  return 0.5 * twice;
}

Vec2 polygonCentroid(const Polygon2& polygon) {
  const size_t n = polygon.size();
  if (n == 0) return Vec2(0.0f);
  const DVec2 o = d2(polygon[0]);
  double twice_area = 0.0;
  DVec2 acc(0.0);
  // Fan of triangles from the first vertex; each contributes its centroid weighted by its signed area.
  for (size_t i = 1; i + 1 < n; ++i) {
    DVec2 a = d2(polygon[i]) - o, b = d2(polygon[i + 1]) - o;
    double w = cross2(a, b);
    twice_area += w;
    acc += w * (a + b) / 3.0;
  }
  // Degenerate when the area is negligible against the polygon's size.
  Box2 box = polygonBounds(polygon);
  DVec2 ext = d2(box.extent());
  double scale = std::max(ext.x, ext.y);
  if (std::abs(twice_area) <= 1e-12 * scale * scale || twice_area == 0.0) {
    DVec2 mean(0.0);
    for (const Vec2& v : polygon) mean += d2(v);
    return f2(mean / double(n));
  }
  return f2(o + acc / twice_area);
}

bool isCounterClockwise(const Polygon2& polygon) { return signedArea(polygon) > 0.0; }

void makeCounterClockwise(Polygon2& polygon) {
  if (signedArea(polygon) < 0.0) std::reverse(polygon.begin(), polygon.end());
}

Box2 polygonBounds(const Polygon2& polygon) {
  Box2 box;
  for (const Vec2& v : polygon) box.expand(v);
  return box;
}

bool pointInPolygon(const Vec2& point, const Polygon2& polygon) {
  const size_t n = polygon.size();
  if (n < 3) return false;
  const DVec2 p = d2(point);
  bool inside = false;
  // Crossing number: count edges crossing the horizontal ray to +x. The half-open rule on y (one endpoint
  // strictly above, the other not) counts a vertex on the ray exactly once.
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    DVec2 a = d2(polygon[j]), b = d2(polygon[i]);
    if ((a.y > p.y) != (b.y > p.y)) {
      double x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
      if (p.x < x) inside = !inside;
    }
  }
  return inside;
}

double distancePointSegment(const Vec2& p, const Vec2& a, const Vec2& b) {
  return distPointSegment(d2(p), d2(a), d2(b));
}

double distancePointSegmentD(const DVec2& p, const DVec2& a, const DVec2& b) { return distPointSegment(p, a, b); }

double distanceToBoundary(const Vec2& point, const Polygon2& polygon) {
  const size_t n = polygon.size();
  if (n == 0) return std::numeric_limits<double>::infinity();
  if (n == 1) return glm::length(d2(point) - d2(polygon[0]));
  const DVec2 p = d2(point);
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < n; ++i) best = std::min(best, distPointSegment(p, d2(polygon[i]), d2(polygon[(i + 1) % n])));
  return best;
}

bool segmentsIntersect(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  return segmentsIntersectD(d2(a), d2(b), d2(c), d2(d));
}

bool segmentsIntersectD(const DVec2& a, const DVec2& b, const DVec2& c, const DVec2& d) {
  int o1 = sign(orient(a, b, c)), o2 = sign(orient(a, b, d));
  int o3 = sign(orient(c, d, a)), o4 = sign(orient(c, d, b));
  // Each segment's endpoints on different sides of (or one on) the other's line: a single crossing point.
  if (o1 != o2 && o3 != o4) return true;
  // Otherwise they can only meet when an endpoint lies on the other segment (collinear cases included).
  if (o1 == 0 && onSegmentBox(a, b, c)) return true;
  if (o2 == 0 && onSegmentBox(a, b, d)) return true;
  if (o3 == 0 && onSegmentBox(c, d, a)) return true;
  if (o4 == 0 && onSegmentBox(c, d, b)) return true;
  return false;
}

std::optional<Vec2> segmentIntersection(const Vec2& a_in, const Vec2& b_in, const Vec2& c_in, const Vec2& d_in) {
  const DVec2 a = d2(a_in), b = d2(b_in), c = d2(c_in), d = d2(d_in);
  const DVec2 r = b - a, s = d - c;
  const double denom = cross2(r, s);
  if (denom == 0.0) {
    // Parallel. Collinear segments meet at a single point only when they touch end to end.
    if (orient(a, b, c) != 0.0) return std::nullopt;
    if (!segmentsIntersect(a_in, b_in, c_in, d_in)) return std::nullopt;
    const DVec2 ends_ab[2] = {a, b};
    const DVec2 ends_cd[2] = {c, d};
    int shared = -1, count = 0;
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        if (ends_ab[i] == ends_cd[j]) shared = i, ++count;
    if (count != 1) return std::nullopt;
    // Touching end to end: the other endpoints lie on opposite sides of the shared one.
    DVec2 other_ab = ends_ab[1 - shared];
    DVec2 p = ends_ab[shared];
    DVec2 other_cd = (c == p) ? d : c;
    if (glm::dot(other_ab - p, other_cd - p) > 0.0) return std::nullopt;  // overlap along a stretch
    return f2(p);
  }
  const DVec2 ac = c - a;
  const double t = cross2(ac, s) / denom;
  const double u = cross2(ac, r) / denom;
  if (t < 0.0 || t > 1.0 || u < 0.0 || u > 1.0) return std::nullopt;
  return f2(a + t * r);
}

bool isSimplePolygon(const Polygon2& polygon) {
  const size_t n = polygon.size();
  if (n < 3) return false;
  for (size_t i = 0; i < n; ++i)
    if (polygon[i] == polygon[(i + 1) % n]) return false;
  for (size_t i = 0; i < n; ++i) {
    const Vec2& a = polygon[i];
    const Vec2& b = polygon[(i + 1) % n];
    // Adjacent edges share a vertex; they only violate simplicity when they fold back onto each other.
    const Vec2& c = polygon[(i + 2) % n];
    DVec2 ab = d2(b) - d2(a), bc = d2(c) - d2(b);
    if (cross2(ab, bc) == 0.0 && glm::dot(ab, bc) < 0.0) return false;
    for (size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // edge n-1 is adjacent to edge 0
      if (segmentsIntersect(a, b, polygon[j], polygon[(j + 1) % n])) return false;
    }
  }
  return true;
}

Polygon2 convexHull(std::vector<Vec2> points) {
  std::sort(points.begin(), points.end(),
            [](const Vec2& p, const Vec2& q) { return p.x < q.x || (p.x == q.x && p.y < q.y); });
  points.erase(std::unique(points.begin(), points.end()), points.end());
  const size_t n = points.size();
  if (n < 3) return points;
  // Lower hull left to right, then upper hull right to left; popping on orient <= 0 drops collinear points
  // so the hull keeps only its corners.
  Polygon2 hull(2 * n);
  size_t k = 0;
  for (size_t i = 0; i < n; ++i) {
    while (k >= 2 && orient(d2(hull[k - 2]), d2(hull[k - 1]), d2(points[i])) <= 0.0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = n - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && orient(d2(hull[k - 2]), d2(hull[k - 1]), d2(points[i])) <= 0.0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);  // the last point repeats the first
  return hull;
}

Polygon2 insetPolygon(const Polygon2& polygon, float distance) {
  return insetPolygon(polygon, std::vector<float>(polygon.size(), distance));
}

// Each edge becomes a line moved inward (to its left, the polygon being counter-clockwise) by its distance;
// consecutive lines meet at the new vertices. When an offset edge comes out reversed or with zero length the
// inset has swallowed it (a short edge next to reflex corners, a thin part): that edge is dropped and its
// neighbours' lines are intersected directly, which approximates the straight skeleton well for the small
// footprints Farfield insets. When fewer than three edges survive, or what is left is not a simple
// counter-clockwise polygon, the inset has collapsed and the result is empty.
Polygon2 insetPolygon(const Polygon2& polygon, const std::vector<float>& distances) {
  const size_t n = polygon.size();
  if (n < 3 || distances.size() != n) return {};

  struct Line {
    DVec2 point;  // a point on the offset line
    DVec2 dir;    // unit direction of the original edge
    double dist;
    size_t edge;
  };
  std::vector<Line> lines;
  lines.reserve(n);
  double scale = 0.0;
  for (size_t i = 0; i < n; ++i) {
    DVec2 a = d2(polygon[i]), b = d2(polygon[(i + 1) % n]);
    DVec2 e = b - a;
    double len = glm::length(e);
    scale = std::max(scale, len);
    if (len == 0.0) continue;  // repeated vertex: no edge
    DVec2 dir = e / len;
    DVec2 inward(-dir.y, dir.x);
    lines.push_back({a + inward * double(distances[i]), dir, double(distances[i]), i});
  }
  const double eps = 1e-9 * std::max(scale, 1.0);

  // Intersection of the offset lines of active edges p and q (q follows p). Returns false when they are
  // anti-parallel (no meeting point: the polygon has collapsed between them).
  auto meet = [&](const Line& p, const Line& q, DVec2& out) {
    double denom = cross2(p.dir, q.dir);
    if (std::abs(denom) <= 1e-12) {
      if (glm::dot(p.dir, q.dir) < 0.0) return false;
      // Collinear edges: their offset lines are parallel; take the point between both offsets at the joint.
      DVec2 joint = d2(polygon[q.edge]);
      DVec2 inward(-q.dir.y, q.dir.x);
      out = joint + inward * (0.5 * (p.dist + q.dist));
      return true;
    }
    double t = cross2(q.point - p.point, q.dir) / denom;
    out = p.point + t * p.dir;
    return true;
  };

  std::vector<DVec2> verts;  // verts[k] = start of active line k = meeting of line k-1 and line k
  while (true) {
    const size_t m = lines.size();
    if (m < 3) return {};
    verts.assign(m, DVec2(0.0));
    for (size_t k = 0; k < m; ++k)
      if (!meet(lines[(k + m - 1) % m], lines[k], verts[k])) return {};
    // Find the most reversed edge: its offset length measured along the original direction.
    double worst = 0.0;
    size_t worst_k = m;
    for (size_t k = 0; k < m; ++k) {
      double len = glm::dot(verts[(k + 1) % m] - verts[k], lines[k].dir);
      if (len <= eps && (worst_k == m || len < worst)) worst = len, worst_k = k;
    }
    if (worst_k == m) break;
    lines.erase(lines.begin() + std::ptrdiff_t(worst_k));
  }

  // Mitre limit: a sharp corner's meeting point runs far from the corner; clamp it towards the corner so it
  // stays within 4x the offset distance. Only corners between originally adjacent edges have a corner to
  // clamp towards.
  const size_t m = lines.size();
  Polygon2 out(m);
  for (size_t k = 0; k < m; ++k) {
    const Line& prev = lines[(k + m - 1) % m];
    const Line& cur = lines[k];
    DVec2 v = verts[k];
    if ((prev.edge + 1) % n == cur.edge) {
      DVec2 corner = d2(polygon[cur.edge]);
      double limit = 4.0 * std::max(std::abs(prev.dist), std::abs(cur.dist));
      DVec2 off = v - corner;
      double len = glm::length(off);
      if (len > limit && len > 0.0) v = corner + off * (limit / len);
    }
    out[k] = f2(v);
  }
  if (signedArea(out) <= 0.0 || !isSimplePolygon(out)) return {};
  return out;
}

Polygon2 cleanPolygon(const Polygon2& polygon, float eps) {
  Polygon2 out;
  out.reserve(polygon.size());
  const double eps_d = eps;
  for (const Vec2& v : polygon)
    if (out.empty() || glm::length(d2(v) - d2(out.back())) >= eps_d) out.push_back(v);
  while (out.size() > 1 && glm::length(d2(out.front()) - d2(out.back())) < eps_d) out.pop_back();

  // Drop collinear vertices (including spikes that double back) until none is left; each removal can make a
  // neighbour collinear, so repeat.
  const double min_area = eps_d * eps_d;
  bool changed = true;
  while (changed && out.size() >= 3) {
    changed = false;
    for (size_t i = 0; i < out.size() && out.size() >= 3;) {
      size_t m = out.size();
      DVec2 a = d2(out[(i + m - 1) % m]), b = d2(out[i]), c = d2(out[(i + 1) % m]);
      double area = 0.5 * std::abs(cross2(b - a, c - a));
      if (area < min_area) {
        out.erase(out.begin() + std::ptrdiff_t(i));
        changed = true;
      } else {
        ++i;
      }
    }
  }
  return out;
}

}  // namespace farfield
