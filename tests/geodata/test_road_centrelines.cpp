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
