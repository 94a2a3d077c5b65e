// Street graph: half-edge invariants, faces, queries against brute force, JSON round trip and malformed input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <set>

#include <nlohmann/json.hpp>

#include "farfield/core/error.h"
#include "farfield/core/polygon2d.h"
#include "farfield/urban/street_graph.h"
#include "support/test_support.h"

using farfield::Error;
using farfield::Polygon2;
using farfield::Vec2;
using farfield::urban::kNone;
using farfield::urban::Street;
using farfield::urban::StreetGraph;

namespace {

// A cols x rows grid of cells with a little jitter; spacing 50 m.
StreetGraph jitteredGrid(int cols, int rows, uint64_t seed) {
  std::mt19937_64 rng(seed);
  auto jitter = [&] { return float(double(rng() % 2001) / 1000.0 - 1.0) * 5.0f; };
  std::vector<Vec2> pos;
  for (int k = 0; k <= rows; ++k)
    for (int i = 0; i <= cols; ++i) pos.emplace_back(50.0f * i + jitter(), 50.0f * k + jitter());
  std::vector<Street> streets;
  auto id = [&](int i, int k) { return uint32_t(k * (cols + 1) + i); };
  for (int k = 0; k <= rows; ++k)
    for (int i = 0; i < cols; ++i) streets.push_back({id(i, k), id(i + 1, k), k % 2 ? 12.0f : 20.0f, k % 2});
  for (int i = 0; i <= cols; ++i)
    for (int k = 0; k < rows; ++k) streets.push_back({id(i, k), id(i, k + 1), 8.0f, 2});
  return StreetGraph::build(pos, streets, "grid");
}

void checkHalfEdgeInvariants(const StreetGraph& g) {
  const uint32_t n = uint32_t(g.halfEdgeCount());
  ASSERT_EQ(n, 2 * g.streetCount());
  for (uint32_t e = 0; e < n; ++e) {
    EXPECT_EQ(StreetGraph::twin(StreetGraph::twin(e)), e);
    EXPECT_NE(StreetGraph::twin(e), e);
    EXPECT_EQ(g.next(g.prev(e)), e);
    EXPECT_EQ(g.prev(g.next(e)), e);
    EXPECT_EQ(g.destination(e), g.origin(g.next(e)));  // the boundary is connected
    EXPECT_EQ(g.origin(StreetGraph::twin(e)), g.destination(e));
    ASSERT_LT(g.face(e), g.faceCount());
  }
  // Every face's boundary is a closed cycle whose half-edges all carry that face; every half-edge is on exactly
  // one face cycle (the outer face may have several cycles in a disconnected graph).
  std::vector<int> seen(n, 0);
  for (uint32_t f = 0; f < g.faceCount(); ++f) {
    const auto edges = g.edgesOfFace(f);
    if (!g.isOuter(f)) {
      ASSERT_GE(edges.size(), 2u);
    }
    for (size_t i = 0; i < edges.size(); ++i) {
      EXPECT_EQ(g.face(edges[i]), f);
      EXPECT_EQ(g.next(edges[i]), edges[(i + 1) % edges.size()]);
      ++seen[edges[i]];
    }
    if (!g.isOuter(f)) {
      EXPECT_GT(farfield::signedArea(g.facePolygon(f)), 0.0) << "block " << f;
    }
  }
  for (uint32_t e = 0; e < n; ++e) EXPECT_LE(seen[e], 1);
}

std::string writeFile(const std::string& dir_name, const std::string& name, const std::string& text) {
  const auto dir = farfield::test::scratchDir(dir_name);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST(StreetGraph, SquareWithDiagonalHandComputed) {
  // (0,0) (10,0) (10,10) (0,10), the four sides and the diagonal 0-2: two triangles and the outer face.
  const std::vector<Vec2> pos{{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  const std::vector<Street> streets{{0, 1, 10, 1}, {1, 2, 10, 1}, {2, 3, 10, 1}, {3, 0, 10, 1}, {0, 2, 20, 0}};
  const StreetGraph g = StreetGraph::build(pos, streets, "square");
  EXPECT_EQ(g.junctionCount(), 4u);
  EXPECT_EQ(g.streetCount(), 5u);
  EXPECT_EQ(g.halfEdgeCount(), 10u);
  EXPECT_EQ(g.faceCount(), 3u);
  EXPECT_EQ(g.blockCount(), 2u);
  EXPECT_TRUE(g.isOuter(0));
  checkHalfEdgeInvariants(g);
  // Half-edge 0 runs 0 -> 1 (along the bottom), its left face is the lower-right triangle {0, 1, 2}.
  EXPECT_EQ(g.origin(0), 0u);
  EXPECT_EQ(g.destination(0), 1u);
  const uint32_t lower = g.face(0);
  EXPECT_FALSE(g.isOuter(lower));
  auto loop = g.faceBoundary(lower);
  std::sort(loop.begin(), loop.end());
  EXPECT_EQ(loop, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_NEAR(farfield::signedArea(g.facePolygon(lower)), 50.0, 1e-9);
  // Its twin (1 -> 0) has the outer face on its left.
  EXPECT_EQ(g.face(1), 0u);
  // The diagonal (street 4, half-edge 8 = 0 -> 2) separates the two triangles: the upper-left one {0, 2, 3} is
  // on its left, the lower-right one on its right.
  EXPECT_EQ(g.face(9), lower);
  const uint32_t upper = g.face(8);
  auto upper_loop = g.faceBoundary(upper);
  std::sort(upper_loop.begin(), upper_loop.end());
  EXPECT_EQ(upper_loop, (std::vector<uint32_t>{0, 2, 3}));
  EXPECT_NE(upper, lower);
  EXPECT_FALSE(g.isOuter(upper));
  auto both = g.blocksOfEdge(8);
  std::sort(both.begin(), both.end());
  EXPECT_EQ(both, (std::vector<uint32_t>{std::min(lower, upper), std::max(lower, upper)}));
  EXPECT_EQ(g.blocksOfEdge(0), std::vector<uint32_t>{lower});
  EXPECT_EQ(g.blocksOfEdge(0, true).size(), 2u);
  EXPECT_EQ(g.blocksAtJunction(0).size(), 2u);
  EXPECT_EQ(g.blocksAtJunction(1).size(), 1u);
  EXPECT_EQ(g.blocksAtJunction(1, true).size(), 2u);
  EXPECT_EQ(g.degree(0), 3u);
  EXPECT_EQ(g.degree(1), 2u);
  EXPECT_FLOAT_EQ(g.length(8), std::sqrt(200.0f));
  EXPECT_FLOAT_EQ(g.width(9), 20.0f);
  EXPECT_EQ(g.streetClass(9), 0);
}

TEST(StreetGraph, OutgoingEdgesAreCounterClockwise) {
  // A star: junction 0 in the middle, six spokes given in scrambled order.
  const std::vector<float> angles_deg{200, 10, 135, 300, 80, 250};
  std::vector<Vec2> pos{{0, 0}};
  std::vector<Street> streets;
  for (float a : angles_deg) {
    pos.emplace_back(30.0f * std::cos(a * 3.14159265f / 180.0f), 30.0f * std::sin(a * 3.14159265f / 180.0f));
    streets.push_back({0, uint32_t(pos.size() - 1), 10, 1});
  }
  const StreetGraph g = StreetGraph::build(pos, streets, "star");
  const auto out = g.outgoing(0);
  ASSERT_EQ(out.size(), 6u);
  // Sorted spoke angles, rotated to start where outgoing() starts, must match in order.
  std::vector<float> sorted = angles_deg;
  std::sort(sorted.begin(), sorted.end());
  std::vector<float> got;
  for (uint32_t e : out) {
    Vec2 d = g.destinationPosition(e) - g.originPosition(e);
    float a = std::atan2(d.y, d.x) * 180.0f / 3.14159265f;
    got.push_back(a < 0 ? a + 360.0f : a);
  }
  auto start = std::find_if(sorted.begin(), sorted.end(), [&](float a) { return std::abs(a - got[0]) < 0.01f; });
  ASSERT_NE(start, sorted.end());
  std::rotate(sorted.begin(), start, sorted.end());
  for (size_t i = 0; i < 6; ++i) EXPECT_NEAR(got[i], sorted[i], 0.01f);
  // A tree: only the outer face; V - E + F = 2.
  EXPECT_EQ(g.faceCount(), 1u);
  EXPECT_EQ(int(g.junctionCount()) - int(g.streetCount()) + int(g.faceCount()), 2);
  checkHalfEdgeInvariants(g);
}

TEST(StreetGraph, GridEulerAndInvariants) {
  for (uint64_t seed : {1u, 2u}) {
    const StreetGraph g = jitteredGrid(7, 5, seed);
    EXPECT_EQ(g.junctionCount(), 48u);
    EXPECT_EQ(g.streetCount(), 7u * 6 + 8u * 5);
    EXPECT_EQ(g.blockCount(), 35u);
    EXPECT_EQ(g.componentCount(), 1u);
    EXPECT_EQ(int(g.junctionCount()) - int(g.streetCount()) + int(g.faceCount()), 2);
    checkHalfEdgeInvariants(g);
    // Interior junctions have degree 4, corners 2.
    EXPECT_EQ(g.degree(0), 2u);
    EXPECT_EQ(g.degree(9), 4u);
    // Each block is a quadrilateral of about 50 x 50 m.
    for (uint32_t f = 1; f < g.faceCount(); ++f) {
      EXPECT_EQ(g.faceBoundary(f).size(), 4u);
      EXPECT_NEAR(farfield::signedArea(g.facePolygon(f)), 2500.0, 1100.0);  // corners move by up to 5 m
    }
  }
}

TEST(StreetGraph, DeadEndDisconnectedNested) {
  // Square plus a dangling street: V=5, E=5, F=2 (the dead end lies on the outer face's boundary twice).
  {
    const StreetGraph g = StreetGraph::build({{0, 0}, {10, 0}, {10, 10}, {0, 10}, {20, 0}},
                                             {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {1, 4}}, "deadend");
    EXPECT_EQ(g.faceCount(), 2u);
    EXPECT_EQ(g.face(8), g.face(9));
    EXPECT_EQ(g.degree(4), 1u);
    checkHalfEdgeInvariants(g);
  }
  // Two separate squares: two components, V - E + F = 1 + C = 3.
  {
    const StreetGraph g = StreetGraph::build(
        {{0, 0}, {10, 0}, {10, 10}, {0, 10}, {50, 0}, {60, 0}, {60, 10}, {50, 10}},
        {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}}, "two");
    EXPECT_EQ(g.componentCount(), 2u);
    EXPECT_EQ(g.blockCount(), 2u);
    EXPECT_EQ(int(g.junctionCount()) - int(g.streetCount()) + int(g.faceCount()), 3);
    checkHalfEdgeInvariants(g);
  }
  // A square inside another one: both are blocks; the inner one's outside belongs to the outer face (documented:
  // no holes), so the big block's boundary is its own square only.
  {
    const StreetGraph g = StreetGraph::build(
        {{0, 0}, {100, 0}, {100, 100}, {0, 100}, {40, 40}, {60, 40}, {60, 60}, {40, 60}},
        {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}}, "nested");
    EXPECT_EQ(g.componentCount(), 2u);
    EXPECT_EQ(g.blockCount(), 2u);
    EXPECT_FALSE(g.isOuter(g.face(8)));  // half-edge 8 runs 4 -> 5 with the inner square on its left
    EXPECT_TRUE(g.isOuter(g.face(9)));
    EXPECT_EQ(g.faceBoundary(g.face(0)).size(), 4u);
    checkHalfEdgeInvariants(g);
  }
}

TEST(StreetGraph, NearestOrientedEdgeMatchesBruteForce) {
  const StreetGraph g = jitteredGrid(12, 9, 5);
  std::mt19937_64 rng(11);
  auto uni = [&](double lo, double hi) { return lo + (hi - lo) * double(rng() % 100001) / 100000.0; };
  for (int i = 0; i < 400; ++i) {
    // Some points well outside the city too.
    const Vec2 p(float(uni(-200, 800)), float(uni(-200, 650)));
    const double ang = uni(0, 6.283185);
    const Vec2 h(float(std::cos(ang)), float(std::sin(ang)));
    const uint32_t e = g.nearestOrientedEdge(p, h);
    ASSERT_NE(e, kNone);
    double best = 1e30;
    for (uint32_t k = 0; k < g.halfEdgeCount(); ++k) {
      const Vec2 d = g.destinationPosition(k) - g.originPosition(k);
      if (glm::dot(d, h) <= 0.0f) continue;
      best = std::min(best, double(farfield::distancePointSegment(p, g.originPosition(k), g.destinationPosition(k))));
    }
    const Vec2 d = g.destinationPosition(e) - g.originPosition(e);
    EXPECT_GT(glm::dot(d, h), 0.0f);
    EXPECT_NEAR(farfield::distancePointSegment(p, g.originPosition(e), g.destinationPosition(e)), best, 0.011)
        << "point " << p.x << "," << p.y;
    // nearestStreet agrees with brute force over the streets.
    const uint32_t s = g.nearestStreet(p);
    double best_s = 1e30;
    for (const Street& st : g.streets())
      best_s = std::min(best_s, farfield::distancePointSegment(p, g.position(st.a), g.position(st.b)));
    EXPECT_NEAR(g.distanceToEdge(p, 2 * s), best_s, 1e-4);
  }
  // Heading along +x on the bottom street picks the half-edge running +x there.
  const Vec2 q = 0.5f * (g.position(0) + g.position(1));
  const uint32_t e = g.nearestOrientedEdge(q + Vec2(0, 0.5f), Vec2(1, 0));
  EXPECT_EQ(StreetGraph::streetOf(e), 0u);
  EXPECT_EQ(g.origin(e), 0u);
  const uint32_t back = g.nearestOrientedEdge(q + Vec2(0, 0.5f), Vec2(-1, 0));
  EXPECT_EQ(back, StreetGraph::twin(e));
  // Zero heading falls back to the nearest half-edge.
  EXPECT_EQ(StreetGraph::streetOf(g.nearestOrientedEdge(q, Vec2(0, 0))), 0u);
}

TEST(StreetGraph, JsonRoundTrip) {
  const StreetGraph g = jitteredGrid(5, 4, 3);
  const auto dir = farfield::test::scratchDir("street_graph_json");
  const std::string path = (dir / "city.streets.json").string();
  g.save(path);
  const StreetGraph h = StreetGraph::load(path);
  ASSERT_EQ(h.junctionCount(), g.junctionCount());
  ASSERT_EQ(h.streetCount(), g.streetCount());
  EXPECT_EQ(h.faceCount(), g.faceCount());
  for (uint32_t j = 0; j < g.junctionCount(); ++j) EXPECT_EQ(h.position(j), g.position(j));
  for (uint32_t s = 0; s < g.streetCount(); ++s) {
    EXPECT_EQ(h.streets()[s].a, g.streets()[s].a);
    EXPECT_EQ(h.streets()[s].b, g.streets()[s].b);
    EXPECT_EQ(h.streets()[s].width, g.streets()[s].width);
    EXPECT_EQ(h.streets()[s].street_class, g.streets()[s].street_class);
  }
  for (uint32_t e = 0; e < g.halfEdgeCount(); ++e) EXPECT_EQ(h.face(e), g.face(e));
  // The derived faces are written for information: one entry per face, the outer one marked.
  std::ifstream in(path);
  const auto j = nlohmann::json::parse(in);
  ASSERT_EQ(j["faces"].size(), g.faceCount());
  EXPECT_TRUE(j["faces"][0]["outer"].get<bool>());
  EXPECT_EQ(j["faces"][1]["junctions"].size(), 4u);
}

TEST(StreetGraph, BadFilesNameTheFileAndElement) {
  struct Case {
    std::string name;
    std::string text;
    std::string expect;
  };
  const std::string ok_junctions = R"("junctions": [[0,0],[10,0],[10,10],[0,10]])";
  const std::vector<Case> cases{
      {"notjson.json", "{ this is not json", "not valid JSON"},
      {"array.json", "[1, 2]", "expected a JSON object"},
      {"nojunctions.json", R"({"streets": []})", "junctions"},
      {"badjunction.json", R"({"junctions": [[0,0],[1,null]], "streets": []})", "junction 1"},
      {"hugejunction.json", R"({"junctions": [[0,0],[1e300,0]], "streets": []})", "junction 1: non-finite"},
      {"range.json", R"({"junctions": [[0,0],[10,0]], "streets": [{"a":0,"b":7}]})", "street 0"},
      {"negative.json", R"({"junctions": [[0,0],[10,0]], "streets": [{"a":-1,"b":1}]})", "street 0"},
      {"zero.json", R"({"junctions": [[0,0],[10,0],[10,0]], "streets": [{"a":0,"b":1},{"a":1,"b":2}]})",
       "street 1: zero length"},
      {"self.json", R"({"junctions": [[0,0],[10,0]], "streets": [{"a":1,"b":1}]})", "street 0: zero length"},
      {"width.json", R"({"junctions": [[0,0],[10,0]], "streets": [{"a":0,"b":1,"width":-3}]})", "street 0: width"},
      {"dup.json", R"({"junctions": [[0,0],[10,0]], "streets": [{"a":0,"b":1},{"a":1,"b":0}]})",
       "street 1: duplicates street 0"},
      {"cross.json",
       "{" + ok_junctions + R"(, "streets": [{"a":0,"b":2},{"a":1,"b":3}]})", "cross"},
      {"tjunction.json", R"({"junctions": [[0,0],[10,0],[5,0],[5,5]], "streets": [{"a":0,"b":1},{"a":2,"b":3}]})",
       "streets 0 and 1 cross"},
      {"overlap.json", R"({"junctions": [[0,0],[10,0],[20,0]], "streets": [{"a":0,"b":1},{"a":0,"b":2}]})",
       "overlap"},
      {"version.json", R"({"version": 9, "junctions": [], "streets": []})", "version"},
  };
  for (const Case& c : cases) {
    const std::string path = writeFile("street_graph_bad", c.name, c.text);
    try {
      StreetGraph::load(path);
      ADD_FAILURE() << c.name << ": no error";
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path), std::string::npos) << what;
      EXPECT_NE(what.find(c.expect), std::string::npos) << c.name << ": " << what;
    }
  }
  try {
    StreetGraph::load("/nonexistent/dir/none.streets.json");
    ADD_FAILURE() << "missing file: no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("none.streets.json"), std::string::npos);
  }
}
