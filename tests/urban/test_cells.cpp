// Cells (oriented street edges) and their local/distant models, against an independent construction: objects are
// placed in known blocks, the blocks beside an edge and around a junction are found by point-in-polygon probes
// next to the edge and around the junction, and the cell lookup is compared with a brute-force search.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include <nlohmann/json.hpp>

#include "farfield/core/error.h"
#include "farfield/core/polygon2d.h"
#include "farfield/urban/cells.h"

namespace farfield::urban {
namespace {

// cols x rows blocks, 60 m spacing, jittered junctions.
StreetGraph jitteredGrid(int cols, int rows, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> jitter(-6.0f, 6.0f);
  std::vector<Vec2> pos;
  for (int k = 0; k <= rows; ++k)
    for (int i = 0; i <= cols; ++i) pos.emplace_back(60.0f * float(i) + jitter(rng), 60.0f * float(k) + jitter(rng));
  std::vector<Street> streets;
  auto id = [&](int i, int k) { return uint32_t(k * (cols + 1) + i); };
  for (int k = 0; k <= rows; ++k)
    for (int i = 0; i < cols; ++i) streets.push_back({id(i, k), id(i + 1, k), 12.0f, kStreet});
  for (int i = 0; i <= cols; ++i)
    for (int k = 0; k < rows; ++k) streets.push_back({id(i, k), id(i, k + 1), 10.0f, kStreet});
  return StreetGraph::build(pos, streets, "test grid");
}

Polygon2 square(const Vec2& c, float half) {
  return {c + Vec2(-half, -half), c + Vec2(half, -half), c + Vec2(half, half), c + Vec2(-half, half)};
}

// A scene whose objects stand in known blocks; truth[id - 1] is the block (kNone for the shared ones).
struct TestCity {
  StreetGraph graph;
  scene::Scene scene;
  std::vector<uint32_t> truth;
};

TestCity makeCity(int cols, int rows, uint64_t seed) {
  TestCity city;
  city.graph = jitteredGrid(cols, rows, seed);
  std::mt19937_64 rng(seed + 7);
  auto add = [&](Polygon2 footprint, uint32_t block) {
    scene::Object o;
    o.footprint = std::move(footprint);
    city.scene.addObject(o);
    city.truth.push_back(block);
  };
  // Object 1: a ground covering the whole city (its centroid lies in a central block).
  const Box2 b = city.graph.bounds();
  add({b.lo - Vec2(20.0f), Vec2(b.hi.x + 20.0f, b.lo.y - 20.0f), b.hi + Vec2(20.0f), Vec2(b.lo.x - 20.0f, b.hi.y + 20.0f)},
      kNone);
  for (uint32_t f = 1; f < city.graph.faceCount(); ++f) {
    const Polygon2 poly = city.graph.facePolygon(f);
    const Box2 pb = polygonBounds(poly);
    std::uniform_real_distribution<float> ux(pb.lo.x, pb.hi.x), uy(pb.lo.y, pb.hi.y);
    const int count = 1 + int(rng() % 3);
    for (int n = 0; n < count;) {
      const Vec2 p(ux(rng), uy(rng));
      if (!pointInPolygon(p, poly) || distanceToBoundary(p, poly) < 6.0) continue;
      add(square(p, 4.0f), f);
      ++n;
    }
  }
  add({}, kNone);                                            // no footprint
  add(square(b.hi + Vec2(200.0f), 5.0f), kNone);            // outside every block
  scene::Object grouped;                                     // footprint centroid in a block, but spanning four
  grouped.footprint = square(b.center(), 70.0f);
  city.scene.addObject(grouped);
  city.truth.push_back(kNone);
  return city;
}

// Faces (bounded) containing p, by brute force over all face polygons.
std::set<uint32_t> facesAt(const StreetGraph& g, const Vec2& p) {
  std::set<uint32_t> out;
  for (uint32_t f = 0; f < g.faceCount(); ++f)
    if (!g.isOuter(f) && pointInPolygon(p, g.facePolygon(f))) out.insert(f);
  return out;
}

// Blocks beside a half-edge: probe points 0.5 m to either side of points along it.
std::set<uint32_t> blocksBesideEdge(const StreetGraph& g, uint32_t e) {
  const Vec2 a = g.originPosition(e), b = g.destinationPosition(e);
  const Vec2 d = glm::normalize(b - a), n(-d.y, d.x);
  std::set<uint32_t> out;
  for (float t : {0.3f, 0.5f, 0.7f})
    for (float s : {-0.5f, 0.5f})
      for (uint32_t f : facesAt(g, a + t * (b - a) + s * n)) out.insert(f);
  return out;
}

// Blocks around a junction: probe points on a 1 m circle.
std::set<uint32_t> blocksAroundJunction(const StreetGraph& g, uint32_t j) {
  std::set<uint32_t> out;
  for (int k = 0; k < 32; ++k) {
    const double angle = (k + 0.5) * 2.0 * kPi / 32.0;
    for (uint32_t f : facesAt(g, g.position(j) + Vec2(float(std::cos(angle)), float(std::sin(angle)))))
      out.insert(f);
  }
  return out;
}

std::set<uint32_t> expectedLocal(const TestCity& city, const std::set<uint32_t>& blocks) {
  std::set<uint32_t> ids;
  for (size_t i = 0; i < city.truth.size(); ++i)
    if (city.truth[i] == kNone || blocks.count(city.truth[i])) ids.insert(uint32_t(i + 1));
  return ids;
}

TEST(CellsTest, ObjectsGoToTheBlockTheyStandIn) {
  const TestCity city = makeCity(4, 3, 11);
  const BlockAssignment a = assignObjectsToBlocks(city.scene, city.graph);
  ASSERT_EQ(a.object_face.size(), city.truth.size());
  for (size_t i = 0; i < city.truth.size(); ++i) EXPECT_EQ(a.object_face[i], city.truth[i]) << "object " << i + 1;
  EXPECT_EQ(a.without_footprint, 1u);
  EXPECT_EQ(a.outside_blocks, 1u);
  EXPECT_EQ(a.too_large, 2u);  // the ground and the object spanning four blocks
  EXPECT_EQ(a.shared.size(), 4u);
  EXPECT_EQ(a.shared.front(), 1u);  // the ground
}

TEST(CellsTest, LocalModelOfAnEdgeIsTheObjectsOfExactlyItsTwoBlocks) {
  const TestCity city = makeCity(5, 4, 3);
  const CellMap cells(city.graph, city.scene);
  ASSERT_EQ(cells.cellCount(), city.graph.halfEdgeCount());
  size_t boundary_edges = 0;
  for (uint32_t e = 0; e < cells.cellCount(); ++e) {
    const std::set<uint32_t> blocks = blocksBesideEdge(city.graph, e);
    ASSERT_LE(blocks.size(), 2u);
    boundary_edges += blocks.size() == 1 ? 1 : 0;
    const std::vector<uint32_t> local_blocks = cells.localBlocks(e);
    EXPECT_EQ(std::set<uint32_t>(local_blocks.begin(), local_blocks.end()), blocks) << "cell " << e;
    const std::vector<uint32_t> local = cells.localObjects(e);
    EXPECT_TRUE(std::is_sorted(local.begin(), local.end()));
    EXPECT_EQ(std::set<uint32_t>(local.begin(), local.end()), expectedLocal(city, blocks)) << "cell " << e;
    // The distant model is exactly the rest.
    const std::vector<uint32_t> distant = cells.distantObjects(e);
    std::vector<uint32_t> all = local;
    all.insert(all.end(), distant.begin(), distant.end());
    std::sort(all.begin(), all.end());
    ASSERT_EQ(all.size(), city.scene.objects.size()) << "cell " << e;
    for (size_t i = 0; i < all.size(); ++i) EXPECT_EQ(all[i], i + 1);
  }
  EXPECT_EQ(boundary_edges, 2u * 2u * (5u + 4u));  // the outer streets, both directions, one block each
}

TEST(CellsTest, JunctionOptionAddsTheBlocksAroundBothEndJunctions) {
  const TestCity city = makeCity(5, 4, 5);
  CellOptions options;
  options.local = LocalModel::Junction;
  const CellMap cells(city.graph, city.scene, options);
  size_t grew = 0;
  for (uint32_t e = 0; e < cells.cellCount(); ++e) {
    std::set<uint32_t> blocks = blocksBesideEdge(city.graph, e);
    const size_t beside = blocks.size();
    for (uint32_t j : {city.graph.origin(e), city.graph.destination(e)})
      for (uint32_t f : blocksAroundJunction(city.graph, j)) blocks.insert(f);
    grew += blocks.size() > beside ? 1 : 0;
    const std::vector<uint32_t> local_blocks = cells.localBlocks(e);
    EXPECT_EQ(std::set<uint32_t>(local_blocks.begin(), local_blocks.end()), blocks) << "cell " << e;
    const std::vector<uint32_t> local = cells.localObjects(e);
    EXPECT_EQ(std::set<uint32_t>(local.begin(), local.end()), expectedLocal(city, blocks)) << "cell " << e;
  }
  // An inner street of a grid has 6 blocks around its two junctions, 2 beside it.
  EXPECT_GT(grew, cells.cellCount() / 2);
}

TEST(CellsTest, NearestLookupAgreesWithBruteForceNearestOrientedEdge) {
  const TestCity city = makeCity(4, 4, 9);
  CellOptions options;
  options.lookup = CellLookup::Nearest;
  const CellMap cells(city.graph, city.scene, options);
  std::mt19937 rng(2);
  const Box2 b = city.graph.bounds();
  std::uniform_real_distribution<float> ux(b.lo.x - 10.0f, b.hi.x + 10.0f), uy(b.lo.y - 10.0f, b.hi.y + 10.0f);
  std::uniform_real_distribution<float> angle(0.0f, 2.0f * float(kPi));
  for (int i = 0; i < 400; ++i) {
    const Vec3 eye(ux(rng), uy(rng), 1.7f);
    const float a = angle(rng);
    const Vec3 view(std::cos(a), std::sin(a), -0.1f);
    const uint32_t cell = cells.lookup(eye, view);
    ASSERT_NE(cell, kNone);
    // Brute force: nearest segment among half-edges pointing the way the viewer looks.
    double best = 1e30;
    for (uint32_t e = 0; e < city.graph.halfEdgeCount(); ++e) {
      const Vec2 d = city.graph.destinationPosition(e) - city.graph.originPosition(e);
      if (d.x * view.x + d.y * view.y <= 0.0f) continue;
      best = std::min(best, distancePointSegment(Vec2(eye), city.graph.originPosition(e),
                                                 city.graph.destinationPosition(e)));
    }
    const Vec2 d = city.graph.destinationPosition(cell) - city.graph.originPosition(cell);
    EXPECT_GT(d.x * view.x + d.y * view.y, 0.0f) << "cell " << cell << " points away from the view";
    EXPECT_NEAR(distancePointSegment(Vec2(eye), city.graph.originPosition(cell), city.graph.destinationPosition(cell)),
                best, 0.011)
        << "sample " << i;
  }
}

TEST(CellsTest, StreetLookupAgreesWithBruteForceOfItsRule) {
  const TestCity city = makeCity(4, 4, 13);
  const CellMap cells(city.graph, city.scene);  // CellLookup::Street by default
  const StreetGraph& g = city.graph;
  std::mt19937 rng(8);
  const Box2 b = g.bounds();
  std::uniform_real_distribution<float> ux(b.lo.x - 10.0f, b.hi.x + 10.0f), uy(b.lo.y - 10.0f, b.hi.y + 10.0f);
  std::uniform_real_distribution<float> angle(0.0f, 2.0f * float(kPi));
  size_t on_street = 0;
  for (int i = 0; i < 2000; ++i) {
    // Half the samples near a junction, where the rules differ.
    Vec2 p(ux(rng), uy(rng));
    if (i % 2) p = g.position(uint32_t(rng() % g.junctionCount())) + Vec2(ux(rng) - b.lo.x, uy(rng) - b.lo.y) * 0.05f;
    const float a = angle(rng);
    const Vec3 eye(p, 1.5f), view(std::cos(a), std::sin(a), 0.2f);
    // Brute force: every half-edge that agrees with the view and that the viewer stands on (within the half width,
    // at least 3 m, of the centreline, projecting onto the segment); the best aligned wins.
    double best_align = -1.0;
    for (uint32_t e = 0; e < g.halfEdgeCount(); ++e) {
      const Vec2 o = g.originPosition(e), d = g.destinationPosition(e) - o;
      const double len = glm::length(d);
      const double align = (d.x * view.x + d.y * view.y) / len / glm::length(Vec2(view));
      const double t = glm::dot(p - o, d) / (len * len);
      const double distance = distancePointSegment(p, o, o + d);
      if (align <= 0.0 || t < 0.0 || t > 1.0 || distance > std::max(0.5 * g.width(e), 3.0)) continue;
      best_align = std::max(best_align, align);
    }
    const uint32_t cell = cells.lookup(eye, view);
    ASSERT_NE(cell, kNone);
    const Vec2 o = g.originPosition(cell), d = g.destinationPosition(cell) - o;
    const double align = (d.x * view.x + d.y * view.y) / glm::length(d) / glm::length(Vec2(view));
    if (best_align > 0.0) {
      ++on_street;
      EXPECT_NEAR(align, best_align, 1e-6) << "sample " << i;
    } else {
      EXPECT_EQ(cell, g.nearestOrientedEdge(p, Vec2(view))) << "sample " << i;
    }
  }
  EXPECT_GT(on_street, 500u);
}

// The case that motivates the street rule: on the right lane of a 24 m avenue, 3 m before a junction with a narrow
// cross street, looking along the avenue (10 degrees towards the cross street). The nearest agreeing edge is the
// cross street (its centreline is nearer); the street rule keeps the avenue.
TEST(CellsTest, StreetLookupKeepsTheAvenueBeforeAJunction) {
  // Avenue along y (junctions 0 -> 1 -> 2), cross street along x from junction 1 (junction 3), plus a closing
  // street so that faces exist.
  const StreetGraph g = StreetGraph::build({{0, 0}, {0, 100}, {0, 200}, {100, 100}, {100, 0}},
                                           {{0, 1, 24.0f, kAvenue}, {1, 2, 24.0f, kAvenue}, {1, 3, 10.0f, kStreet},
                                            {3, 4, 10.0f}, {4, 0, 10.0f}},
                                           "avenue");
  scene::Scene empty;
  const Vec3 eye(6.0f, 97.0f, 1.2f);  // right lane, 3 m before the junction centre
  const Vec3 view(std::sin(0.17f), std::cos(0.17f), 0.0f);
  CellOptions nearest;
  nearest.lookup = CellLookup::Nearest;
  EXPECT_EQ(CellMap(g, empty, nearest).lookup(eye, view), 4u);  // street 2 (cross street), 1 -> 3
  EXPECT_EQ(CellMap(g, empty).lookup(eye, view), 0u);           // street 0 (avenue), 0 -> 1
  // Past the junction centre the avenue continues as half-edge 2 (street 1, 1 -> 2).
  EXPECT_EQ(CellMap(g, empty).lookup(Vec3(6.0f, 103.0f, 1.2f), view), 2u);
  EXPECT_THROW(parseCellLookup("closest"), Error);
}

TEST(CellsTest, ZeroLengthStreetIsReportedNotACrash) {
  // A street file with a zero-length street: a farfield::Error naming the street.
  const nlohmann::json j = {{"format", "farfield-streets"},
                            {"version", 1},
                            {"junctions", {{0.0, 0.0}, {50.0, 0.0}, {50.0, 0.0}}},
                            {"streets", {{{"a", 0}, {"b", 1}}, {{"a", 1}, {"b", 2}}}}};
  try {
    StreetGraph::fromJson(j, "zero.streets.json");
    FAIL() << "expected farfield::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("zero.streets.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("zero length"), std::string::npos) << e.what();
  }
  // A street too short to look along is a degenerate cell (both directions), reported by the cell map.
  StreetGraph g = StreetGraph::build({{0.0f, 0.0f}, {50.0f, 0.0f}, {50.0f, 0.001f}}, {{0, 1}, {1, 2}}, "short");
  scene::Scene empty;
  const CellMap cells(std::move(g), empty);
  EXPECT_EQ(cells.degenerateCells(), (std::vector<uint32_t>{2, 3}));
  EXPECT_FALSE(cells.degenerate(0));
  EXPECT_TRUE(cells.localObjects(2).empty());
}

TEST(CellsTest, ParsesLocalModelNames) {
  EXPECT_EQ(parseLocalModel("edge"), LocalModel::Edge);
  EXPECT_EQ(parseLocalModel("junction"), LocalModel::Junction);
  EXPECT_THROW(parseLocalModel("block"), Error);
  EXPECT_STREQ(localModelName(LocalModel::Junction), "junction");
}

}  // namespace
}  // namespace farfield::urban
