// Road centre lines from road surfaces: a straight road, an L, and a 3 x 3 grid of overlapping road rectangles whose
// centre lines, planarised, must be the grid's lines (checked point by point against them), with the grid's
// junctions, streets and blocks (Euler's formula and the block areas computed by hand).
#include <gtest/gtest.h>

#include <cmath>

#include "farfield/core/polygon2d.h"
#include "farfield/geodata/planarize.h"
#include "farfield/geodata/road_centrelines.h"
#include "geodata/street_graph_checks.h"

using farfield::DVec2;
using farfield::geodata::RoadCentreLineStats;
using farfield::geodata::roadCentreLines;
using farfield::geodata::StreetPolyline;

namespace {

using Polygon = std::vector<std::vector<DVec2>>;

Polygon rect(double x0, double y0, double x1, double y1) { return {{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}}; }

double totalLength(const std::vector<StreetPolyline>& lines) {
  double n = 0.0;
  for (const auto& l : lines)
    for (size_t i = 1; i < l.points.size(); ++i) n += glm::distance(l.points[i - 1], l.points[i]);
  return n;
}

}  // namespace

TEST(RoadCentreLines, StraightRoadAndL) {
  // A 100 x 10 road: its centre line runs at y = 5 from x = 5 to 95 (the skeleton stops half a width from the ends).
  RoadCentreLineStats st;
  const auto straight = roadCentreLines({rect(0, 0, 100, 10)}, &st);
  EXPECT_EQ(st.united, 1u);
  EXPECT_NEAR(totalLength(straight), 90.0, 1e-6);
  for (const auto& l : straight) {
    EXPECT_NEAR(l.width, 10.0f, 1e-4f);
    for (const DVec2& p : l.points) EXPECT_NEAR(p.y, 5.0, 1e-6);
  }
  // An L of two 10 m wide arms given as two overlapping rectangles (one clockwise): one united polygon, centre
  // lines x 5..95 at y = 5 and y 5..95 at x = 5 meeting at (5, 5).
  Polygon arm2 = rect(0, 0, 10, 100);
  std::reverse(arm2[0].begin(), arm2[0].end());
  const auto l = roadCentreLines({rect(0, 0, 100, 10), arm2}, &st);
  EXPECT_EQ(st.united, 1u);
  EXPECT_EQ(st.invalid_polygons, 0u);
  EXPECT_NEAR(totalLength(l), 180.0, 1e-6);
  for (const auto& s : l)
    for (const DVec2& p : s.points) EXPECT_TRUE(std::abs(p.y - 5.0) < 1e-6 || std::abs(p.x - 5.0) < 1e-6);
  // A self-intersecting (bow-tie) polygon is counted and left out.
  const auto none = roadCentreLines({{{{0, 0}, {10, 10}, {10, 0}, {0, 10}}}}, &st);
  EXPECT_TRUE(none.empty());
  EXPECT_EQ(st.invalid_polygons, 1u);
}

TEST(RoadCentreLines, GridOfOverlappingRoadsGivesTheGridsBlocks) {
  // Roads 10 m wide on the lines x, y = 0, 110, 220, each a rectangle from -5 to 225 overlapping the others.
  std::vector<Polygon> roads;
  for (double c : {0.0, 110.0, 220.0}) {
    roads.push_back(rect(c - 5, -5, c + 5, 225));
    roads.push_back(rect(-5, c - 5, 225, c + 5));
  }
  RoadCentreLineStats st;
  const auto lines = roadCentreLines(roads, &st);
  EXPECT_EQ(st.united, 1u);  // one polygon with 4 holes
  // Every centre line point is on a grid line, and together they cover its 6 lines of 220 m.
  for (const auto& l : lines) {
    EXPECT_NEAR(l.width, 10.0f, 1e-3f);
    for (const DVec2& p : l.points) {
      double d = 1e9;
      for (double c : {0.0, 110.0, 220.0}) d = std::min({d, std::abs(p.x - c), std::abs(p.y - c)});
      EXPECT_LT(d, 1e-6) << p.x << ", " << p.y;
    }
  }
  EXPECT_NEAR(totalLength(lines), 6.0 * 220.0, 1e-3);
  const auto g = farfield::geodata::planarizeStreets(lines);
  farfield::test::checkStreetGraph(g);
  ASSERT_EQ(g.blockCount(), 4u);
  for (uint32_t f = 1; f < g.faceCount(); ++f)
    EXPECT_NEAR(std::abs(farfield::signedArea(g.facePolygon(f))), 110.0 * 110.0, 1.0);
  // Junctions of degree 3 or 4 are the grid's 9 crossings minus its 4 corners (degree 2): 5.
  size_t branching = 0;
  for (uint32_t j = 0; j < g.junctionCount(); ++j) branching += g.degree(j) >= 3;
  EXPECT_EQ(branching, 5u);
}

namespace {

// The 3 x 3 grid of the test above, 10 m wide roads on x, y = 0, 110, 220.
std::vector<Polygon> gridRoads() {
  std::vector<Polygon> roads;
  for (double c : {0.0, 110.0, 220.0}) {
    roads.push_back(rect(c - 5, -5, c + 5, 225));
    roads.push_back(rect(-5, c - 5, 225, c + 5));
  }
  return roads;
}

double distanceToGridLine(const DVec2& p) {
  double d = 1e9;
  for (double c : {0.0, 110.0, 220.0}) d = std::min({d, std::abs(p.x - c), std::abs(p.y - c)});
  return d;
}

bool insideAny(const std::vector<Polygon>& rects, const DVec2& p) {
  for (const Polygon& r : rects) {
    double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
    for (const DVec2& q : r[0]) {
      x0 = std::min(x0, q.x), y0 = std::min(y0, q.y), x1 = std::max(x1, q.x), y1 = std::max(y1, q.y);
    }
    if (p.x >= x0 - 1e-9 && p.x <= x1 + 1e-9 && p.y >= y0 - 1e-9 && p.y <= y1 + 1e-9) return true;
  }
  return false;
}

}  // namespace

TEST(RoadCentreLines, UnclosedRingNotchIsCleanedBeforeTheSkeleton) {
  // The shape of a fuzz finding: one road of the grid whose ring ends 1.5 cm away from where it starts, a notch
  // that CGAL's skeleton builder does not survive. The notch's vertex is dropped and the grid's lines come back.
  std::vector<Polygon> roads = gridRoads();
  roads[1][0].push_back({-5.0, -4.985});
  RoadCentreLineStats st;
  const auto lines = roadCentreLines(roads, &st);
  EXPECT_EQ(st.united, 1u);
  EXPECT_GE(st.cleaned_vertices, 1u);
  EXPECT_EQ(st.degenerate_areas, 0u);
  for (const auto& l : lines)
    for (const DVec2& p : l.points) EXPECT_LT(distanceToGridLine(p), 0.05) << p.x << ", " << p.y;
  EXPECT_NEAR(totalLength(lines), 6.0 * 220.0, 0.5);
}

TEST(RoadCentreLines, RoadsTouchingAtCornersGiveLinesInsideTheRoadsOrAreCounted) {
  // A ring of four arms whose left arm touches the bottom and top arms at single corners (0, 10) and (0, 90): the
  // union's borders pass twice through those points, which the skeleton must never be given.
  const std::vector<Polygon> roads = {rect(0, 0, 100, 10), rect(90, 0, 100, 100), rect(0, 90, 100, 100),
                                      rect(-10, 10, 0, 90)};
  RoadCentreLineStats st;
  const auto lines = roadCentreLines(roads, &st);
  for (const auto& l : lines)
    for (const DVec2& p : l.points) EXPECT_TRUE(insideAny(roads, p)) << p.x << ", " << p.y;
  // The union is one area whose hole (x 0..90, y 10..90) shares two vertices with its outer ring: counted, no lines.
  EXPECT_EQ(st.united, 1u);
  EXPECT_EQ(st.degenerate_areas, 1u);
  EXPECT_TRUE(lines.empty());
}
