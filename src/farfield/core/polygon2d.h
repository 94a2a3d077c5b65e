// 2D geometry on the ground plane (x, y in metres): segments, simple polygons, convex hull. Computations run in
// double precision. A polygon is a vertex list without a repeated closing vertex.
#pragma once

#include <optional>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/math.h"

namespace farfield {

using Polygon2 = std::vector<Vec2>;

// Shoelace area: positive for counter-clockwise polygons.
double signedArea(const Polygon2& polygon);
// Area centroid; for a degenerate (zero-area) polygon, the mean of its vertices.
Vec2 polygonCentroid(const Polygon2& polygon);
bool isCounterClockwise(const Polygon2& polygon);
void makeCounterClockwise(Polygon2& polygon);
Box2 polygonBounds(const Polygon2& polygon);

// Even-odd rule; points exactly on the boundary may go either way.
bool pointInPolygon(const Vec2& p, const Polygon2& polygon);
// Distance from p to the polygon's boundary.
double distanceToBoundary(const Vec2& p, const Polygon2& polygon);
double distancePointSegment(const Vec2& p, const Vec2& a, const Vec2& b);
double distancePointSegmentD(const DVec2& p, const DVec2& a, const DVec2& b);

// Closed segments [a, b] and [c, d] intersect (touching counts).
bool segmentsIntersect(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d);
// Same predicates on double-precision points (street graphs keep their geometry in double).
bool segmentsIntersectD(const DVec2& a, const DVec2& b, const DVec2& c, const DVec2& d);
// Intersection point of two segments when they cross at a single point.
std::optional<Vec2> segmentIntersection(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d);

// No two non-adjacent edges intersect and no edge has zero length (O(n^2); footprints are small).
bool isSimplePolygon(const Polygon2& polygon);

// Convex hull of a point set, counter-clockwise, without collinear points (Andrew's monotone chain).
Polygon2 convexHull(std::vector<Vec2> points);

// Offsets every edge of a counter-clockwise simple polygon inward by `distance` (per-edge distances when
// `distances` is given, one per edge i = (v[i], v[i+1])) and intersects consecutive offset lines (mitre joins,
// limited to 4x the distance). Returns an empty polygon when the result collapses or turns inside out.
Polygon2 insetPolygon(const Polygon2& polygon, float distance);
Polygon2 insetPolygon(const Polygon2& polygon, const std::vector<float>& distances);

// Removes repeated vertices (closer than eps) and collinear vertices (area below eps^2).
Polygon2 cleanPolygon(const Polygon2& polygon, float eps = 1e-4f);

}  // namespace farfield
