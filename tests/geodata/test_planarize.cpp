// Street planarisation: hand-made configurations with known junction/street/block counts, and random line sets
// checked by brute force (no two streets cross, every input segment is still covered, Euler's formula).
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>

#include "farfield/core/error.h"
#include "farfield/geodata/planarize.h"
#include "geodata/street_graph_checks.h"

using farfield::DVec2;
using farfield::Vec2;
using farfield::geodata::planarizeStreets;
using farfield::geodata::PlanarizeOptions;
using farfield::geodata::PlanarizeStats;
using farfield::geodata::StreetPolyline;
using farfield::urban::StreetGraph;

namespace {

StreetPolyline line(std::vector<DVec2> pts, float width = 10.0f) {
  StreetPolyline l;
  l.points = std::move(pts);
  l.width = width;
  return l;
}

// Distance from p to the nearest street of g (brute force).
double distanceToGraph(const StreetGraph& g, const DVec2& p) {
  double best = 1e300;
  for (const auto& s : g.streets()) {
    const DVec2 a(g.position(s.a)), b(g.position(s.b));
    const DVec2 ab = b - a;
    const double t = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
    best = std::min(best, glm::length(p - (a + t * ab)));
  }
  return best;
}

}  // namespace

TEST(Planarize, CrossingLinesGetAJunction) {
  PlanarizeStats st;
  const StreetGraph g = planarizeStreets({line({{-10, 0}, {10, 0}}), line({{0, -10}, {0, 10}})}, {}, &st);
  EXPECT_EQ(g.junctionCount(), 5u);
  EXPECT_EQ(g.streetCount(), 4u);
  EXPECT_EQ(g.blockCount(), 0u);
  EXPECT_EQ(st.crossings, 1u);
  // The new junction is at the origin.
  bool found = false;
  for (const Vec2& p : g.junctions()) found |= glm::length(p) < 1e-6f;
  EXPECT_TRUE(found);
  farfield::test::checkStreetGraph(g);
}

TEST(Planarize, HashGridOfLinesWithoutSharedNodes) {
  // 4 horizontal and 4 vertical lines overhanging each other: 16 crossings, 9 blocks, 16 dead ends.
  std::vector<StreetPolyline> lines;
  for (int i = 0; i < 4; ++i) {
    lines.push_back(line({{-10, 50.0 * i}, {160, 50.0 * i}}));
    lines.push_back(line({{50.0 * i, -10}, {50.0 * i, 160}}));
  }
  PlanarizeStats st;
  const StreetGraph g = planarizeStreets(lines, {}, &st);
  EXPECT_EQ(g.junctionCount(), 16u + 16u);
  EXPECT_EQ(g.streetCount(), 4u * (3 + 2) * 2);
  EXPECT_EQ(g.blockCount(), 9u);
  EXPECT_EQ(st.crossings, 16u);
  for (uint32_t f = 1; f < g.faceCount(); ++f) EXPECT_NEAR(farfield::signedArea(g.facePolygon(f)), 2500.0, 1e-2);
  farfield::test::checkStreetGraph(g);
}

TEST(Planarize, NearbyNodesMergeAndNearMissesConnect) {
  PlanarizeOptions options;
  options.merge_tolerance = 0.5;
  // A square whose closing node misses the start by 0.14 m (the same 0.5 m pixel), and a dead end stopping 0.2 m
  // short of the bottom side (its pixel's centre lies on the bottom side).
  std::vector<StreetPolyline> lines = {line({{0, 0}, {100, 0}, {100, 100}, {0, 100}, {0.1, 0.1}}),
                                       line({{50, 50}, {50, 0.2}})};
  PlanarizeStats st;
  const StreetGraph g = planarizeStreets(lines, options, &st);
  EXPECT_EQ(st.merged_points, 1u);
  EXPECT_GE(st.snapped_to_junction, 1u);
  // The dead end now splits the bottom side: junctions (0,0) (100,0) (100,100) (0,100) (50,50) (50,0.2).
  EXPECT_EQ(g.junctionCount(), 6u);
  EXPECT_EQ(g.streetCount(), 6u);
  EXPECT_EQ(g.blockCount(), 1u);
  farfield::test::checkStreetGraph(g);
  // With a pixel of 0.1 m nothing merges: the square stays open at its corner.
  options.merge_tolerance = 0.1;
  const StreetGraph open = planarizeStreets(lines, options, &st);
  EXPECT_EQ(open.blockCount(), 0u);
  farfield::test::checkStreetGraph(open);
}

TEST(Planarize, DuplicatesAndCollinearOverlapsMerge) {
  // The same street twice (reversed), and a street running along half of another.
  std::vector<StreetPolyline> lines = {line({{0, 0}, {100, 0}}, 8.0f), line({{100, 0}, {0, 0}}, 12.0f),
                                       line({{0, 0}, {50, 0}}), line({{50, 0}, {50, 50}})};
  PlanarizeStats st;
  const StreetGraph g = planarizeStreets(lines, {}, &st);
  EXPECT_EQ(g.junctionCount(), 4u);  // (0,0) (50,0) (100,0) (50,50)
  EXPECT_EQ(g.streetCount(), 3u);
  EXPECT_EQ(st.duplicates, 1u);
  // The wider of the duplicates wins.
  for (const auto& s : g.streets())
    if (g.position(s.a).y == 0.0f && g.position(s.b).y == 0.0f) {
      EXPECT_EQ(s.width, 12.0f);
    }
  farfield::test::checkStreetGraph(g);
}

TEST(Planarize, BadInputThrows) {
  EXPECT_THROW(planarizeStreets({line({{0, 0}, {std::nan(""), 1}})}, {}, nullptr, "t"), farfield::Error);
  PlanarizeOptions bad;
  bad.merge_tolerance = 0.0;
  EXPECT_THROW(planarizeStreets({line({{0, 0}, {1, 1}})}, bad, nullptr, "t"), farfield::Error);
  // Nothing at all is an empty graph, not an error.
  const StreetGraph empty = planarizeStreets({}, {});
  EXPECT_EQ(empty.streetCount(), 0u);
}

TEST(Planarize, RandomLinesArePlanarAndCovered) {
  // Random polylines in a 400 m square, many crossings, some nearly parallel and nearly touching.
  for (uint32_t seed : {1u, 2u, 3u}) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> coord(0.0, 400.0), step(-60.0, 60.0);
    std::vector<StreetPolyline> lines;
    for (int l = 0; l < 60; ++l) {
      std::vector<DVec2> pts{{coord(rng), coord(rng)}};
      const int n = 2 + l % 5;
      for (int k = 1; k < n; ++k) pts.push_back(pts.back() + DVec2(step(rng), step(rng)));
      lines.push_back(line(pts));
    }
    // A few exact repeats of existing points and near-collinear copies.
    lines.push_back(line({lines[0].points[0], lines[1].points[0]}));
    lines.push_back(line({lines[2].points[0] + DVec2(0.01, 0.0), lines[2].points[1] + DVec2(0.0, 0.01)}));
    PlanarizeOptions options;
    PlanarizeStats st;
    const StreetGraph g = planarizeStreets(lines, options, &st);
    EXPECT_EQ(st.unresolved, 0u);
    farfield::test::checkStreetGraph(g);
    // Every input point of every segment still lies on (within the tolerance plus a float ulp of) the graph:
    // check 5 points per input segment.
    for (const StreetPolyline& l : lines)
      for (size_t k = 0; k + 1 < l.points.size(); ++k)
        for (double t : {0.0, 0.25, 0.5, 0.75, 1.0}) {
          const DVec2 p = l.points[k] + t * (l.points[k + 1] - l.points[k]);
          // Routing through junctions moves a street by at most the tolerance per round it is bent; a few rounds
          // at most on this input.
          EXPECT_LT(distanceToGraph(g, p), 3.0 * options.merge_tolerance) << "seed " << seed;
        }
  }
}

TEST(Planarize, DegenerateStress) {
  // Many streets through nearly the same points, nearly collinear streets and streets along each other: the
  // cases where rounding matters. The result must pass StreetGraph::build's checks (it is built by it) and ours.
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    std::vector<StreetPolyline> lines;
    const DVec2 hubs[3] = {{1000.3, 2000.7}, {1003.1, 2001.2}, {1000.9, 2010.0}};
    for (int l = 0; l < 40; ++l) {
      const DVec2 hub = hubs[l % 3] + DVec2(unit(rng), unit(rng)) * 0.3;
      const double a = unit(rng) * M_PI;
      const DVec2 d(std::cos(a), std::sin(a));
      lines.push_back(line({hub - d * (20.0 + 10 * unit(rng)), hub + d * (20.0 + 10 * unit(rng))}));
    }
    // Nearly collinear chains along y = 2005.
    for (int l = 0; l < 10; ++l)
      lines.push_back(line({{980.0 + l * 3.0, 2005.0 + 1e-4 * unit(rng)}, {1030.0 - l * 2.0, 2005.0 + 1e-4 * unit(rng)}}));
    PlanarizeStats st;
    const StreetGraph g = planarizeStreets(lines, {}, &st);
    EXPECT_EQ(st.unresolved, 0u) << "seed " << seed;
    farfield::test::checkStreetGraph(g);
  }
}

TEST(Planarize, LongDiagonalCrossesEveryShortStreet) {
  // A 2.5 km diagonal over 20 short vertical streets (x = 50, 150, ..., 1950): 20 crossings on the diagonal at
  // y = 0.75 x, each within half a pixel of the exact point.
  std::vector<StreetPolyline> lines = {line({{0, 0}, {2000, 1500}})};
  for (int i = 0; i < 20; ++i) {
    const double x = 50.0 + 100.0 * i;
    lines.push_back(line({{x, 0.75 * x - 20.0}, {x, 0.75 * x + 20.0}}));
  }
  PlanarizeStats st;
  const StreetGraph g = planarizeStreets(lines, {}, &st);
  EXPECT_EQ(st.crossings, 20u);
  EXPECT_EQ(g.streetCount(), 21u + 2u * 20u);
  EXPECT_EQ(g.componentCount(), 1u);
  for (int i = 0; i < 20; ++i) {
    const double x = 50.0 + 100.0 * i;
    bool found = false;
    for (const Vec2& p : g.junctions())
      found |= std::abs(p.x - x) < 0.36 && std::abs(p.y - 0.75 * x) < 0.36 && g.degree(uint32_t(&p - &g.junctions()[0])) == 4;
    EXPECT_TRUE(found) << x;
  }
  farfield::test::checkStreetGraph(g);
}
