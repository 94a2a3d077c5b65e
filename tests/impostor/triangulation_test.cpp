#include "farfield/impostor/triangulation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>

#include "farfield/core/error.h"
#include "farfield/impostor/contour.h"
#include "support/test_support.h"

namespace farfield::impostor {
namespace {

double triangleArea(const Triangulation& t, size_t i) {
  const DVec2 a = t.vertices[t.triangles[i][0]], b = t.vertices[t.triangles[i][1]], c = t.vertices[t.triangles[i][2]];
  return 0.5 * cross2(b - a, c - a);
}

double insideArea(const Triangulation& t) {
  double area = 0.0;
  for (size_t i = 0; i < t.triangles.size(); ++i)
    if (t.inside[i]) area += triangleArea(t, i);
  return area;
}

// Independent of CGAL: the segment [a, b] is a union of triangulation edges when the vertices lying on it, sorted
// along it, start at a, end at b, and each consecutive pair is an edge of some triangle.
::testing::AssertionResult segmentIsUnionOfEdges(const Triangulation& t, const DVec2& a, const DVec2& b) {
  std::set<std::pair<uint32_t, uint32_t>> edges;
  for (const auto& tri : t.triangles)
    for (int k = 0; k < 3; ++k) {
      const uint32_t u = tri[size_t(k)], v = tri[size_t((k + 1) % 3)];
      edges.insert({std::min(u, v), std::max(u, v)});
    }
  const DVec2 ab = b - a;
  const double len = glm::length(ab);
  std::vector<std::pair<double, uint32_t>> on;
  for (uint32_t i = 0; i < t.vertices.size(); ++i) {
    const DVec2 p = t.vertices[i];
    const double s = glm::dot(p - a, ab) / (len * len);
    const double off = std::abs(cross2(ab, p - a)) / len;
    if (off <= 1e-7 * std::max(1.0, len) && s >= -1e-9 && s <= 1.0 + 1e-9) on.push_back({s, i});
  }
  std::sort(on.begin(), on.end());
  if (on.size() < 2 || glm::length(t.vertices[on.front().second] - a) > 1e-9 ||
      glm::length(t.vertices[on.back().second] - b) > 1e-9)
    return ::testing::AssertionFailure() << "segment end points are not vertices";
  for (size_t i = 0; i + 1 < on.size(); ++i) {
    const uint32_t u = on[i].second, v = on[i + 1].second;
    if (!edges.count({std::min(u, v), std::max(u, v)}))
      return ::testing::AssertionFailure() << "gap between (" << t.vertices[u].x << ", " << t.vertices[u].y
                                           << ") and (" << t.vertices[v].x << ", " << t.vertices[v].y << ")";
  }
  return ::testing::AssertionSuccess();
}

std::vector<DVec2> square(double lo, double hi) { return {{lo, lo}, {hi, lo}, {hi, hi}, {lo, hi}}; }

TEST(TriangulationTest, ConstraintsAreEdgesAndInsideIsTheSquare) {
  TriangulationInput input;
  input.loops.push_back(square(0, 10));
  input.polylines.push_back({{2, 5}, {5, 6.5}, {8, 5}});
  input.polylines.push_back({{1, 1}, {9, 9}});  // crosses the first polyline
  for (int i = 1; i < 10; i += 3)
    for (int j = 1; j < 10; j += 3) input.points.push_back(DVec2(i + 0.5, j + 0.25));
  input.points.push_back(DVec2(20, 20));  // outside the loop: a vertex, but its triangles are outside
  const Triangulation t = triangulate(input);
  EXPECT_GE(t.steiner_vertices, 1u);  // the crossing
  for (const auto& loop : input.loops)
    for (size_t i = 0; i < loop.size(); ++i)
      EXPECT_TRUE(segmentIsUnionOfEdges(t, loop[i], loop[(i + 1) % loop.size()]));
  for (const auto& line : input.polylines)
    for (size_t i = 0; i + 1 < line.size(); ++i) EXPECT_TRUE(segmentIsUnionOfEdges(t, line[i], line[i + 1]));
  EXPECT_NEAR(insideArea(t), 100.0, 1e-9);
  for (size_t i = 0; i < t.triangles.size(); ++i) {
    EXPECT_GT(triangleArea(t, i), 0.0);  // counter-clockwise in (x, y)
    const DVec2 c = (t.vertices[t.triangles[i][0]] + t.vertices[t.triangles[i][1]] + t.vertices[t.triangles[i][2]]) / 3.0;
    const bool in_square = c.x > 0 && c.x < 10 && c.y > 0 && c.y < 10;
    EXPECT_EQ(bool(t.inside[i]), in_square);
  }
}

TEST(TriangulationTest, ConstraintCrossingTheContourAndAHole) {
  TriangulationInput input;
  input.loops.push_back(square(0, 20));
  std::vector<DVec2> hole = square(5, 15);
  std::reverse(hole.begin(), hole.end());
  input.loops.push_back(hole);
  input.polylines.push_back({{-3, 2.5}, {23, 3.5}});  // crosses the outer loop twice
  const Triangulation t = triangulate(input);
  EXPECT_GE(t.steiner_vertices, 2u);
  EXPECT_NEAR(insideArea(t), 400.0 - 100.0, 1e-6);
  for (const auto& loop : input.loops)
    for (size_t i = 0; i < loop.size(); ++i)
      EXPECT_TRUE(segmentIsUnionOfEdges(t, loop[i], loop[(i + 1) % loop.size()]));
}

TEST(TriangulationTest, DiscContourTriangulatesToItsArea) {
  image::Image<uint8_t> mask(64, 64, 0);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) mask.at(x, y) = std::hypot(x + 0.5 - 30, y + 0.5 - 33) < 25 ? 1 : 0;
  const Contours contours = extractContours(mask);
  TriangulationInput input;
  double area = 0.0;
  for (const ContourLoop& loop : contours.loops) {
    input.loops.push_back(loop.points);
    area += signedArea(loop.points);
  }
  for (int y = 4; y < 64; y += 8)
    for (int x = 4; x < 64; x += 8)
      if (mask.at(x, y)) input.points.push_back(DVec2(x + 0.5, y + 0.5));
  const Triangulation t = triangulate(input);
  EXPECT_NEAR(insideArea(t), area, 1e-6);
  for (const auto& loop : input.loops)
    for (size_t i = 0; i < loop.size(); ++i)
      EXPECT_TRUE(segmentIsUnionOfEdges(t, loop[i], loop[(i + 1) % loop.size()]));
}

TEST(TriangulationTest, RefinementSplitsUntilThePredicateHolds) {
  TriangulationInput input;
  input.loops.push_back(square(0, 16));
  Refinement refinement;
  refinement.max_points = 10000;
  refinement.split_point = [](const DVec2& a, const DVec2& b, const DVec2& c) -> std::optional<DVec2> {
    if (0.5 * cross2(b - a, c - a) <= 2.0) return std::nullopt;
    return (a + b + c) / 3.0;
  };
  refinement.max_rounds = 64;
  const Triangulation t = triangulate(input, &refinement);
  EXPECT_GT(t.refinement_vertices, 0u);
  EXPECT_NEAR(insideArea(t), 256.0, 1e-6);
  for (size_t i = 0; i < t.triangles.size(); ++i)
    if (t.inside[i]) {
      EXPECT_LE(triangleArea(t, i), 2.0 + 1e-9);
    }
}

// Many constraints crossing at shallow angles, at coordinates off the pixel grid: every run finishes with the
// square's area inside, whatever CGAL did with the crossings inside it (the recorded input below is the one that
// actually crashed the old intersection tag; these random ones did not).
TEST(TriangulationTest, ManyShallowCrossingsTriangulateWithoutCrashing) {
  uint64_t state = 12345;
  auto uniform = [&state](double lo, double hi) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * double(state >> 11) / double(uint64_t(1) << 53);
  };
  size_t steiner = 0;
  for (int run = 0; run < 300; ++run) {
    TriangulationInput input;
    input.loops.push_back(square(0, 64));
    const double slope = uniform(-0.2, 0.2);
    for (int k = 0; k < 30; ++k) {
      // Nearly parallel chains, a fraction of a pixel apart, each bending a little.
      std::vector<DVec2> line;
      const double y0 = uniform(1.0, 63.0), s = slope + uniform(-0.01, 0.01);
      for (double x = uniform(0.5, 8.0); x < 63.5; x += uniform(4.0, 20.0))
        line.push_back({x, std::clamp(y0 + s * x + uniform(-0.3, 0.3), 0.25, 63.75)});
      input.polylines.push_back(std::move(line));
    }
    const Triangulation t = triangulate(input);
    EXPECT_NEAR(insideArea(t), 64.0 * 64.0, 1e-6) << "run " << run;
    steiner += t.steiner_vertices;
  }
  EXPECT_GT(steiner, 300u);  // the chains did cross
}

// The input (contour loop, discrepancy polylines, grid points) whose triangulation crashed CGAL inside
// find_intersected_faces while baking a depth mesh of the 100,000-block city at detail 1, with the intersection tag
// for exact number types. Its polylines double back on themselves along a line and cross the contour and each other.
TriangulationInput readTriangulationInput(const std::filesystem::path& file) {
  std::ifstream in(file);
  TriangulationInput input;
  auto readLines = [&in](const char* what, std::vector<std::vector<DVec2>>& out) {
    std::string word;
    size_t count = 0;
    in >> word >> count;
    if (word != what) throw std::runtime_error("expected " + std::string(what));
    out.resize(count);
    for (auto& line : out) {
      size_t n = 0;
      in >> n;
      line.resize(n);
      for (DVec2& p : line) in >> p.x >> p.y;
    }
  };
  readLines("loops", input.loops);
  readLines("polylines", input.polylines);
  std::string word;
  size_t count = 0;
  in >> word >> count;
  input.points.resize(count);
  for (DVec2& p : input.points) in >> p.x >> p.y;
  if (!in) throw std::runtime_error("cannot read " + file.string());
  return input;
}

TEST(TriangulationTest, TheInputThatCrashedABigCityBakeTriangulates) {
  const TriangulationInput input =
      readTriangulationInput(test::testDataDir() / "impostor" / "triangulation_bigcity_crash.txt");
  ASSERT_EQ(input.loops.size(), 1u);
  ASSERT_EQ(input.polylines.size(), 14u);
  const Triangulation t = triangulate(input);
  // The inside is the loop's area (shoelace formula, independent of the triangulation).
  double area = 0.0;
  const auto& loop = input.loops[0];
  for (size_t i = 0; i < loop.size(); ++i) area += cross2(loop[i], loop[(i + 1) % loop.size()]);
  EXPECT_NEAR(insideArea(t), std::abs(0.5 * area), 1e-6 * std::abs(area));
  EXPECT_GT(t.steiner_vertices, 0u);
}

TEST(TriangulationTest, EmptyAndBadInput) {
  const Triangulation empty = triangulate({});
  EXPECT_TRUE(empty.triangles.empty());
  EXPECT_EQ(empty.insideCount(), 0u);
  TriangulationInput bad;
  bad.loops.push_back({{0, 0}, {1, std::numeric_limits<double>::quiet_NaN()}, {0, 1}});
  EXPECT_THROW(triangulate(bad), Error);
}

}  // namespace
}  // namespace farfield::impostor
