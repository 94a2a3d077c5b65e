#include "farfield/core/polygon2d.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <random>

using namespace farfield;

namespace {

// Independent point-in-triangle test with barycentric signs (no shared code with the library).
bool inTriangle(Vec2 p, Vec2 a, Vec2 b, Vec2 c) {
  auto side = [](Vec2 u, Vec2 v, Vec2 w) {
    return double(v.x - u.x) * double(w.y - u.y) - double(v.y - u.y) * double(w.x - u.x);
  };
  double s0 = side(a, b, p), s1 = side(b, c, p), s2 = side(c, a, p);
  return (s0 > 0 && s1 > 0 && s2 > 0) || (s0 < 0 && s1 < 0 && s2 < 0);
}

// An "L" shape (counter-clockwise) and the triangles that tile it.
const Polygon2 kL = {{0, 0}, {4, 0}, {4, 1}, {1, 1}, {1, 3}, {0, 3}};
const std::vector<std::array<Vec2, 3>> kLTriangles = {
    {Vec2(0, 0), Vec2(4, 0), Vec2(4, 1)}, {Vec2(0, 0), Vec2(4, 1), Vec2(0, 1)},
    {Vec2(0, 1), Vec2(1, 1), Vec2(1, 3)}, {Vec2(0, 1), Vec2(1, 3), Vec2(0, 3)}};

}  // namespace

TEST(Polygon2d, AreaOfKnownShapes) {
  Polygon2 square = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  EXPECT_DOUBLE_EQ(signedArea(square), 4.0);
  Polygon2 cw(square.rbegin(), square.rend());
  EXPECT_DOUBLE_EQ(signedArea(cw), -4.0);
  EXPECT_TRUE(isCounterClockwise(square));
  EXPECT_FALSE(isCounterClockwise(cw));
  makeCounterClockwise(cw);
  EXPECT_DOUBLE_EQ(signedArea(cw), 4.0);
  EXPECT_DOUBLE_EQ(signedArea(kL), 4.0 + 2.0);  // 4x1 bar plus 1x2 stem
  Polygon2 tri = {{1000, 1000}, {1003, 1000}, {1000, 1004}};
  EXPECT_DOUBLE_EQ(signedArea(tri), 6.0);
  EXPECT_DOUBLE_EQ(signedArea({{0, 0}, {1, 1}}), 0.0);
  // A regular 64-gon of radius 10: area = n/2 r^2 sin(2 pi / n).
  Polygon2 ngon;
  for (int i = 0; i < 64; ++i)
    ngon.push_back(Vec2(10 * std::cos(2 * kPi * i / 64), 10 * std::sin(2 * kPi * i / 64)));
  EXPECT_NEAR(signedArea(ngon), 32.0 * 100.0 * std::sin(2 * kPi / 64), 1e-3);
}

TEST(Polygon2d, CentroidAndBounds) {
  // L shape: bar 4x1 centroid (2, 0.5) area 4; stem 1x2 centroid (0.5, 2) area 2.
  Vec2 c = polygonCentroid(kL);
  EXPECT_NEAR(c.x, (4 * 2.0 + 2 * 0.5) / 6.0, 1e-6);
  EXPECT_NEAR(c.y, (4 * 0.5 + 2 * 2.0) / 6.0, 1e-6);
  // Degenerate: mean of vertices.
  Vec2 m = polygonCentroid({{0, 0}, {2, 0}, {4, 0}});
  EXPECT_FLOAT_EQ(m.x, 2.0f);
  EXPECT_FLOAT_EQ(m.y, 0.0f);
  Box2 b = polygonBounds(kL);
  EXPECT_EQ(b.lo, Vec2(0, 0));
  EXPECT_EQ(b.hi, Vec2(4, 3));
  EXPECT_TRUE(polygonBounds({}).empty());
}

TEST(Polygon2d, PointInPolygonMatchesTriangles) {
  int inside_count = 0;
  for (int iy = 0; iy < 80; ++iy) {
    for (int ix = 0; ix < 100; ++ix) {
      // Offsets keep grid points off the edges (boundary points may go either way).
      Vec2 p(-0.5f + ix * 0.0513f, -0.5f + iy * 0.0517f);
      bool expected = false;
      for (const auto& t : kLTriangles) expected = expected || inTriangle(p, t[0], t[1], t[2]);
      // The shared diagonals of the triangles are inside the polygon; skip grid points on them.
      bool on_diagonal = false;
      for (const auto& t : kLTriangles)
        for (int e = 0; e < 3; ++e)
          if (distancePointSegment(p, t[e], t[(e + 1) % 3]) < 1e-4) on_diagonal = true;
      if (on_diagonal) continue;
      EXPECT_EQ(pointInPolygon(p, kL), expected) << p.x << "," << p.y;
      inside_count += expected;
    }
  }
  EXPECT_GT(inside_count, 100);
  // Reversed orientation gives the same answer.
  Polygon2 rev(kL.rbegin(), kL.rend());
  EXPECT_TRUE(pointInPolygon({0.5f, 2.5f}, rev));
  EXPECT_FALSE(pointInPolygon({2.5f, 2.5f}, rev));
  // A ray through a vertex: (−1, 1) row passes the vertex (1, 1) and (4, 1).
  EXPECT_TRUE(pointInPolygon({0.5f, 1.0f}, kL));
  EXPECT_FALSE(pointInPolygon({-1.0f, 1.0f}, kL));
}

TEST(Polygon2d, Distances) {
  EXPECT_DOUBLE_EQ(distancePointSegment({0, 1}, {-1, 0}, {1, 0}), 1.0);
  EXPECT_DOUBLE_EQ(distancePointSegment({4, 4}, {0, 0}, {1, 0}), 5.0);   // nearest endpoint (1, 0)
  EXPECT_DOUBLE_EQ(distancePointSegment({3, 4}, {0, 0}, {0, 0}), 5.0);   // degenerate segment
  EXPECT_NEAR(distanceToBoundary({2, 0.25f}, kL), 0.25, 1e-7);
  EXPECT_NEAR(distanceToBoundary({0.5f, 2.0f}, kL), 0.5, 1e-7);
  EXPECT_NEAR(distanceToBoundary({3, 3}, kL), 2.0, 1e-6);             // edges y = 1 and x = 1
  EXPECT_NEAR(distanceToBoundary({3, 4}, kL), std::sqrt(5.0), 1e-6);  // nearest point: the corner (1, 3)
}

TEST(Polygon2d, SegmentIntersection) {
  EXPECT_TRUE(segmentsIntersect({0, 0}, {2, 2}, {0, 2}, {2, 0}));
  auto p = segmentIntersection({0, 0}, {2, 2}, {0, 2}, {2, 0});
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->x, 1.0, 1e-6);
  EXPECT_NEAR(p->y, 1.0, 1e-6);
  // T junction: an endpoint touching the other segment.
  EXPECT_TRUE(segmentsIntersect({0, 0}, {2, 0}, {1, 0}, {1, 5}));
  p = segmentIntersection({0, 0}, {2, 0}, {1, 0}, {1, 5});
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->x, 1.0, 1e-6);
  // Disjoint, though their lines cross.
  EXPECT_FALSE(segmentsIntersect({0, 0}, {1, 0}, {2, -1}, {2, 1}));
  EXPECT_FALSE(segmentIntersection({0, 0}, {1, 0}, {2, -1}, {2, 1}).has_value());
  // Parallel apart.
  EXPECT_FALSE(segmentsIntersect({0, 0}, {1, 0}, {0, 1}, {1, 1}));
  // Collinear overlapping: intersect, but not at a single point.
  EXPECT_TRUE(segmentsIntersect({0, 0}, {2, 0}, {1, 0}, {3, 0}));
  EXPECT_FALSE(segmentIntersection({0, 0}, {2, 0}, {1, 0}, {3, 0}).has_value());
  // Collinear disjoint.
  EXPECT_FALSE(segmentsIntersect({0, 0}, {1, 0}, {2, 0}, {3, 0}));
  // Collinear touching end to end: one point.
  p = segmentIntersection({0, 0}, {1, 0}, {1, 0}, {3, 0});
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(*p, Vec2(1, 0));
}

TEST(Polygon2d, SegmentIntersectionRandomAgainstParametric) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-10, 10);
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    Vec2 a(u(rng), u(rng)), b(u(rng), u(rng)), c(u(rng), u(rng)), d(u(rng), u(rng));
    // Independent: sample segment cd densely and look for a sign change of the side of ab along it, then check
    // that the change happens within [a, b] by projecting.
    DVec2 A(a), B(b), C(c), D(d);
    DVec2 r = B - A, s = D - C;
    double den = r.x * s.y - r.y * s.x;
    if (std::abs(den) < 1e-3) continue;
    double t = ((C.x - A.x) * s.y - (C.y - A.y) * s.x) / den;
    double w = ((C.x - A.x) * r.y - (C.y - A.y) * r.x) / den;
    if (std::min({t, 1 - t, w, 1 - w}) > -1e-4 && std::min({t, 1 - t, w, 1 - w}) < 1e-4) continue;  // grazing
    bool expected = t >= 0 && t <= 1 && w >= 0 && w <= 1;
    EXPECT_EQ(segmentsIntersect(a, b, c, d), expected);
    auto p = segmentIntersection(a, b, c, d);
    EXPECT_EQ(p.has_value(), expected);
    if (p && expected) {
      EXPECT_LT(distancePointSegment(*p, a, b), 1e-3);
      EXPECT_LT(distancePointSegment(*p, c, d), 1e-3);
      ++hits;
    }
  }
  EXPECT_GT(hits, 100);
}

TEST(Polygon2d, SimplePolygon) {
  EXPECT_TRUE(isSimplePolygon(kL));
  EXPECT_TRUE(isSimplePolygon({{0, 0}, {1, 0}, {0, 1}}));
  EXPECT_FALSE(isSimplePolygon({{0, 0}, {1, 0}}));
  // Bow tie.
  EXPECT_FALSE(isSimplePolygon({{0, 0}, {2, 2}, {2, 0}, {0, 2}}));
  // Repeated vertex (zero-length edge).
  EXPECT_FALSE(isSimplePolygon({{0, 0}, {1, 0}, {1, 0}, {0, 1}}));
  // A vertex touching a non-adjacent edge.
  EXPECT_FALSE(isSimplePolygon({{0, 0}, {4, 0}, {4, 4}, {2, 0}, {0, 4}}));
  // Spike folding back onto the previous edge.
  EXPECT_FALSE(isSimplePolygon({{0, 0}, {4, 0}, {2, 0}, {2, 3}}));
}

TEST(Polygon2d, ConvexHullAgainstBruteForce) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> u(-50, 50);
  for (int trial = 0; trial < 30; ++trial) {
    std::vector<Vec2> pts;
    int n = 3 + trial * 7;
    for (int i = 0; i < n; ++i) pts.push_back(Vec2(u(rng), u(rng)));
    // Duplicates and collinear points on a hull edge must not break anything.
    pts.push_back(pts[0]);
    Polygon2 hull = convexHull(pts);
    ASSERT_GE(hull.size(), 3u);
    EXPECT_GT(signedArea(hull), 0.0);
    for (size_t i = 0; i < hull.size(); ++i) {
      // Every hull vertex is an input point.
      EXPECT_NE(std::find(pts.begin(), pts.end(), hull[i]), pts.end());
      DVec2 a(hull[i]), b(hull[(i + 1) % hull.size()]), c(hull[(i + 2) % hull.size()]);
      // Strictly convex corners (no collinear vertices kept).
      EXPECT_GT((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x), 0.0);
      // All points on the left of (or on) every hull edge.
      for (const Vec2& p : pts) {
        double side = (b.x - a.x) * (double(p.y) - a.y) - (b.y - a.y) * (double(p.x) - a.x);
        EXPECT_GE(side, -1e-9);
      }
    }
  }
}

TEST(Polygon2d, ConvexHullDegenerate) {
  // Collinear points: the two ends.
  Polygon2 h = convexHull({{0, 0}, {1, 1}, {2, 2}, {3, 3}});
  ASSERT_EQ(h.size(), 2u);
  // Square with points on edges and inside: exactly the 4 corners.
  h = convexHull({{0, 0}, {1, 0}, {2, 0}, {2, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}, {1, 1}});
  ASSERT_EQ(h.size(), 4u);
  EXPECT_DOUBLE_EQ(signedArea(h), 4.0);
  EXPECT_TRUE(convexHull({}).empty());
  EXPECT_EQ(convexHull({{1, 1}, {1, 1}}).size(), 1u);
}

TEST(Polygon2d, InsetRectangleExact) {
  Polygon2 rect = {{0, 0}, {10, 0}, {10, 6}, {0, 6}};
  Polygon2 in = insetPolygon(rect, 1.0f);
  ASSERT_EQ(in.size(), 4u);
  Polygon2 expected = {{1, 1}, {9, 1}, {9, 5}, {1, 5}};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(in[i].x, expected[i].x, 1e-5);
    EXPECT_NEAR(in[i].y, expected[i].y, 1e-5);
  }
  // Per-edge distances: bottom 0.5, right 1, top 2, left 3.
  in = insetPolygon(rect, std::vector<float>{0.5f, 1.0f, 2.0f, 3.0f});
  ASSERT_EQ(in.size(), 4u);
  expected = {{3, 0.5f}, {9, 0.5f}, {9, 4}, {3, 4}};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(in[i].x, expected[i].x, 1e-5);
    EXPECT_NEAR(in[i].y, expected[i].y, 1e-5);
  }
  // Collapse: the rectangle is 6 wide in y.
  EXPECT_TRUE(insetPolygon(rect, 3.5f).empty());
  EXPECT_TRUE(insetPolygon(rect, 3.0f).empty());
  EXPECT_FALSE(insetPolygon(rect, 2.9f).empty());
}

TEST(Polygon2d, InsetLShapeKeepsDistance) {
  Polygon2 in = insetPolygon(kL, 0.25f);
  ASSERT_EQ(in.size(), 6u);
  EXPECT_TRUE(isSimplePolygon(in));
  // Area of the L inset by 0.25: bar 3.5 x 0.5 plus stem 0.5 x (3 - 0.25 - 0.75) = 1.75 + 1.0.
  EXPECT_NEAR(signedArea(in), 1.75 + 1.0, 1e-5);
  for (const Vec2& v : in) {
    EXPECT_TRUE(pointInPolygon(v, kL));
    // Convex corners end 0.25 from both edges; the reflex corner (1, 1) maps to (0.75, 0.75), 0.25 from both edge
    // lines and so 0.25 sqrt(2) from the corner itself.
    bool reflex = glm::length(v - Vec2(0.75f, 0.75f)) < 1e-5f;
    EXPECT_NEAR(distanceToBoundary(v, kL), reflex ? 0.25 * std::sqrt(2.0) : 0.25, 1e-5);
  }
  EXPECT_TRUE(std::any_of(in.begin(), in.end(), [](Vec2 v) { return glm::length(v - Vec2(0.75f, 0.75f)) < 1e-5f; }));
  // The stem is 1 wide: inset 0.5 collapses it, and the short edges go; what remains must still be inside.
  Polygon2 thin = insetPolygon(kL, 0.45f);
  for (const Vec2& v : thin) EXPECT_TRUE(pointInPolygon(v, kL));
}

TEST(Polygon2d, InsetTriangleAndMitreLimit) {
  // Right isosceles triangle legs 10: inradius r = 10 (2 - sqrt 2) / 2.
  Polygon2 tri = {{0, 0}, {10, 0}, {0, 10}};
  double r = 10.0 * (2.0 - std::sqrt(2.0)) / 2.0;
  Polygon2 in = insetPolygon(tri, 1.0f);
  ASSERT_EQ(in.size(), 3u);
  // Similar triangle scaled by (r - 1) / r about the incentre.
  double k = (r - 1.0) / r;
  EXPECT_NEAR(signedArea(in), 50.0 * k * k, 1e-4);
  EXPECT_TRUE(insetPolygon(tri, float(r + 0.1)).empty());
  // A needle triangle: the mitre at the sharp tip would run far away; it stays within 4 x distance of the tip.
  Polygon2 needle = {{0, 0}, {100, 1}, {0, 2}};
  Polygon2 n_in = insetPolygon(needle, 0.1f);
  ASSERT_EQ(n_in.size(), 3u);
  EXPECT_LE(glm::length(n_in[1] - Vec2(100, 1)), 0.4f + 1e-4f);
  EXPECT_TRUE(insetPolygon(tri, std::vector<float>{1.0f}).empty());  // wrong number of distances
}

TEST(Polygon2d, CleanPolygon) {
  Polygon2 p = {{0, 0}, {0, 0}, {1, 0}, {2, 0}, {2, 2}, {2, 2.00001f}, {0, 2}, {0, 0.000001f}};
  Polygon2 c = cleanPolygon(p);
  ASSERT_EQ(c.size(), 4u);
  EXPECT_DOUBLE_EQ(signedArea(c), 4.0);
  for (const Vec2& v : c) EXPECT_TRUE(v.x == 0 || v.x == 2);
  // A spike that doubles back is removed.
  c = cleanPolygon({{0, 0}, {4, 0}, {6, 0}, {4, 0}, {4, 4}, {0, 4}});
  EXPECT_EQ(c.size(), 4u);
  EXPECT_DOUBLE_EQ(signedArea(c), 16.0);
  EXPECT_TRUE(isSimplePolygon(c));
  // A clean polygon is unchanged.
  EXPECT_EQ(cleanPolygon(kL), kL);
}

TEST(Polygon2d, InsetDropsSwallowedEdge) {
  // A rectangle with a tiny chamfer at one corner: inset by 1 the chamfer edge comes out reversed, so it is
  // dropped and the result is the plain inset rectangle.
  Polygon2 chamfered = {{0, 0}, {10, 0}, {10, 3.9f}, {9.9f, 4}, {0, 4}};
  Polygon2 in = insetPolygon(chamfered, 1.0f);
  ASSERT_EQ(in.size(), 4u);
  EXPECT_NEAR(signedArea(in), 8.0 * 2.0, 1e-4);
  Box2 b = polygonBounds(in);
  EXPECT_NEAR(b.lo.x, 1.0, 1e-5);
  EXPECT_NEAR(b.lo.y, 1.0, 1e-5);
  EXPECT_NEAR(b.hi.x, 9.0, 1e-5);
  EXPECT_NEAR(b.hi.y, 3.0, 1e-5);
  // A small inset keeps the chamfer.
  EXPECT_EQ(insetPolygon(chamfered, 0.01f).size(), 5u);
}
