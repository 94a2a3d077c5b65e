// Polygon triangulation with holes (2D footprints, 3D faces): covered area, orientation and index ranges against
// hand-computed areas.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "farfield/geodata/triangulate.h"

using farfield::DVec2;
using farfield::DVec3;
using farfield::geodata::PolygonTriangulation;
using farfield::geodata::triangulateFace3;
using farfield::geodata::triangulatePolygon2;

namespace {

std::vector<DVec3> vertexList(const std::vector<std::vector<DVec3>>& rings, const PolygonTriangulation& t) {
  std::vector<DVec3> all;
  for (const auto& r : rings) all.insert(all.end(), r.begin(), r.end());
  all.insert(all.end(), t.extra.begin(), t.extra.end());
  return all;
}

std::vector<std::vector<DVec3>> lift(const std::vector<std::vector<DVec2>>& rings) {
  std::vector<std::vector<DVec3>> out;
  for (const auto& r : rings) {
    out.emplace_back();
    for (const DVec2& p : r) out.back().emplace_back(p, 0.0);
  }
  return out;
}

// Sum of triangle areas and signed areas projected on `normal`.
void areas(const std::vector<DVec3>& v, const PolygonTriangulation& t, const DVec3& normal, double& area,
           double& signed_area) {
  area = signed_area = 0.0;
  for (size_t i = 0; i + 2 < t.indices.size(); i += 3) {
    ASSERT_LT(t.indices[i], v.size());
    ASSERT_LT(t.indices[i + 1], v.size());
    ASSERT_LT(t.indices[i + 2], v.size());
    const DVec3 c = glm::cross(v[t.indices[i + 1]] - v[t.indices[i]], v[t.indices[i + 2]] - v[t.indices[i]]);
    area += 0.5 * glm::length(c);
    signed_area += 0.5 * glm::dot(c, normal);
  }
}

}  // namespace

TEST(Triangulate, SquareWithHole) {
  // 10 x 10 square with a 4 x 2 hole: 100 - 8 = 92 m^2. The hole given counter-clockwise too.
  const std::vector<std::vector<DVec2>> rings = {{{0, 0}, {10, 0}, {10, 10}, {0, 10}},
                                                 {{3, 3}, {7, 3}, {7, 5}, {3, 5}}};
  PolygonTriangulation t;
  ASSERT_TRUE(triangulatePolygon2(rings, t));
  EXPECT_TRUE(t.extra.empty());
  EXPECT_EQ(t.indices.size() % 3, 0u);
  double area = 0, signed_area = 0;
  areas(vertexList(lift(rings), t), t, DVec3(0, 0, 1), area, signed_area);
  EXPECT_NEAR(area, 92.0, 1e-9);
  EXPECT_NEAR(signed_area, 92.0, 1e-9);  // all counter-clockwise
  // No triangle has its centroid inside the hole.
  const auto v = vertexList(lift(rings), t);
  for (size_t i = 0; i < t.indices.size(); i += 3) {
    const DVec3 c = (v[t.indices[i]] + v[t.indices[i + 1]] + v[t.indices[i + 2]]) / 3.0;
    EXPECT_FALSE(c.x > 3 && c.x < 7 && c.y > 3 && c.y < 5);
  }
}

TEST(Triangulate, ClockwiseConcaveOuter) {
  // An L shape given clockwise: area 3 unit squares.
  const std::vector<std::vector<DVec2>> rings = {{{0, 0}, {0, 2}, {1, 2}, {1, 1}, {2, 1}, {2, 0}}};
  PolygonTriangulation t;
  ASSERT_TRUE(triangulatePolygon2(rings, t));
  double area = 0, signed_area = 0;
  areas(vertexList(lift(rings), t), t, DVec3(0, 0, 1), area, signed_area);
  EXPECT_NEAR(area, 3.0, 1e-12);
  EXPECT_NEAR(signed_area, 3.0, 1e-12);
  EXPECT_EQ(t.indices.size(), 3u * 4u);  // n - 2 triangles
}

TEST(Triangulate, SelfIntersectingRingStillCovered) {
  // A bow tie: two triangles of area 1 each, meeting at (1, 1); an extra vertex appears at the crossing.
  const std::vector<std::vector<DVec2>> rings = {{{0, 0}, {2, 2}, {2, 0}, {0, 2}}};
  PolygonTriangulation t;
  ASSERT_TRUE(triangulatePolygon2(rings, t));
  ASSERT_EQ(t.extra.size(), 1u);
  EXPECT_NEAR(t.extra[0].x, 1.0, 1e-12);
  EXPECT_NEAR(t.extra[0].y, 1.0, 1e-12);
  double area = 0, signed_area = 0;
  areas(vertexList(lift(rings), t), t, DVec3(0, 0, 1), area, signed_area);
  EXPECT_NEAR(area, 2.0, 1e-9);
}

TEST(Triangulate, DegenerateInputsFail) {
  PolygonTriangulation t;
  EXPECT_FALSE(triangulatePolygon2({{{0, 0}, {1, 1}, {2, 2}}}, t));  // collinear
  EXPECT_FALSE(triangulatePolygon2({{{0, 0}, {1, 0}}}, t));
  EXPECT_FALSE(triangulatePolygon2({}, t));
  EXPECT_FALSE(triangulatePolygon2({{{0, 0}, {1, 0}, {std::nan(""), 1}}}, t));
  EXPECT_FALSE(triangulateFace3({{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}}, t));
  EXPECT_TRUE(t.indices.empty());
}

TEST(Triangulate, TiltedFaceWithHoleAtLargeCoordinates) {
  // A 20 x 10 rectangle with a 4 x 4 hole in a plane tilted 30 degrees about x, placed at RD-like coordinates.
  const DVec3 origin(85000.0, 445000.0, 3.0);
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  auto P = [&](double u, double v) { return origin + DVec3(u, v * c, v * s); };
  std::vector<std::vector<DVec3>> rings = {{P(0, 0), P(20, 0), P(20, 10), P(0, 10)},
                                           {P(8, 3), P(8, 7), P(12, 7), P(12, 3)}};
  PolygonTriangulation t;
  DVec3 n;
  ASSERT_TRUE(triangulateFace3(rings, t, &n));
  EXPECT_NEAR(glm::length(n), 1.0, 1e-12);
  EXPECT_NEAR(n.x, 0.0, 1e-9);
  EXPECT_NEAR(n.y, -s, 1e-9);
  EXPECT_NEAR(n.z, c, 1e-9);
  double area = 0, signed_area = 0;
  areas(vertexList(rings, t), t, n, area, signed_area);
  EXPECT_NEAR(area, 200.0 - 16.0, 1e-6);
  EXPECT_NEAR(signed_area, 184.0, 1e-6);  // oriented like the outer ring
  // Reversing the outer ring flips the normal and the triangles.
  std::reverse(rings[0].begin(), rings[0].end());
  ASSERT_TRUE(triangulateFace3(rings, t, &n));
  EXPECT_NEAR(n.z, -c, 1e-9);
  areas(vertexList(rings, t), t, n, area, signed_area);
  EXPECT_NEAR(signed_area, 184.0, 1e-6);
}

TEST(Triangulate, RandomStarPolygonsMatchShoelace) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> radius(1.0, 5.0);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 5 + trial % 20;
    std::vector<DVec2> ring;
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * i / n;
      const double r = radius(rng);
      ring.emplace_back(r * std::cos(a), r * std::sin(a));
    }
    double shoelace = 0;
    for (int i = 0; i < n; ++i) shoelace += farfield::cross2(ring[i], ring[(i + 1) % n]);
    shoelace *= 0.5;
    PolygonTriangulation t;
    ASSERT_TRUE(triangulatePolygon2({ring}, t));
    EXPECT_EQ(t.indices.size(), size_t(3 * (n - 2)));
    double area = 0, signed_area = 0;
    areas(vertexList(lift({ring}), t), t, DVec3(0, 0, 1), area, signed_area);
    EXPECT_NEAR(signed_area, shoelace, 1e-9);
  }
}
