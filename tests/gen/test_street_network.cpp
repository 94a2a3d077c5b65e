// Procedural street network: planar, connected (Euler's formula), half-edge invariants, block count, determinism,
// street classes, buildable blocks; brute-force checks independent of the generator.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "farfield/core/error.h"
#include "farfield/core/polygon2d.h"
#include "farfield/gen/street_network.h"

using farfield::Vec2;
using farfield::gen::generateStreetNetwork;
using farfield::gen::StreetNetworkOptions;
using farfield::urban::StreetGraph;

namespace {

StreetGraph make(int blocks, uint64_t seed) {
  StreetNetworkOptions o;
  o.blocks = blocks;
  o.seed = seed;
  return generateStreetNetwork(o);
}

}  // namespace

TEST(StreetNetwork, EulerAndHalfEdgeInvariants) {
  for (int blocks : {10, 57, 300, 1500}) {
    for (uint64_t seed : {1u, 2u, 3u}) {
      SCOPED_TRACE("blocks " + std::to_string(blocks) + " seed " + std::to_string(seed));
      const StreetGraph g = make(blocks, seed);
      // Connected planar graph: V - E + F = 2 with F counting the outer face.
      EXPECT_EQ(g.componentCount(), 1u);
      EXPECT_EQ(int64_t(g.junctionCount()) - int64_t(g.streetCount()) + int64_t(g.faceCount()), 2);
      EXPECT_TRUE(g.isOuter(0));
      const uint32_t n = uint32_t(g.halfEdgeCount());
      for (uint32_t e = 0; e < n; ++e) {
        ASSERT_EQ(StreetGraph::twin(StreetGraph::twin(e)), e);
        ASSERT_EQ(g.next(g.prev(e)), e);
        ASSERT_EQ(g.destination(e), g.origin(g.next(e)));
        // The blocks touching an edge are exactly its face and its twin's face (the outer one left out).
        std::vector<uint32_t> expect;
        for (uint32_t f : {g.face(e), g.face(StreetGraph::twin(e))})
          if (f != 0 && std::find(expect.begin(), expect.end(), f) == expect.end()) expect.push_back(f);
        auto got = g.blocksOfEdge(e);
        std::sort(got.begin(), got.end());
        std::sort(expect.begin(), expect.end());
        ASSERT_EQ(got, expect);
      }
      // Each face's boundary is a closed cycle: following next() from its edge returns to it, all on that face;
      // together the cycles cover every half-edge once.
      std::vector<int> covered(n, 0);
      for (uint32_t f = 0; f < g.faceCount(); ++f) {
        const uint32_t start = g.faces()[f].edge;
        uint32_t e = start;
        size_t steps = 0;
        do {
          ASSERT_EQ(g.face(e), f);
          ++covered[e];
          e = g.next(e);
          ASSERT_LE(++steps, size_t(n));
        } while (e != start);
        if (f != 0) {
          EXPECT_GT(farfield::signedArea(g.facePolygon(f)), 0.0);
        }
      }
      for (uint32_t e = 0; e < n; ++e) ASSERT_EQ(covered[e], 1) << "half-edge " << e;
    }
  }
}

TEST(StreetNetwork, PlanarByBruteForce) {
  for (uint64_t seed : {4u, 5u}) {
    const StreetGraph g = make(250, seed);
    const auto& st = g.streets();
    const auto& p = g.junctions();
    for (size_t i = 0; i < st.size(); ++i) {
      for (size_t k = i + 1; k < st.size(); ++k) {
        const auto &a = st[i], &b = st[k];
        const bool share = a.a == b.a || a.a == b.b || a.b == b.a || a.b == b.b;
        if (!share) {
          ASSERT_FALSE(farfield::segmentsIntersect(p[a.a], p[a.b], p[b.a], p[b.b]))
              << "streets " << i << " and " << k << " cross (seed " << seed << ")";
        } else {
          // Streets meeting at a junction must leave it in different directions.
          const uint32_t c = (a.a == b.a || a.a == b.b) ? a.a : a.b;
          const Vec2 u = glm::normalize(p[a.a == c ? a.b : a.a] - p[c]);
          const Vec2 v = glm::normalize(p[b.a == c ? b.b : b.a] - p[c]);
          ASSERT_LT(glm::dot(u, v), 0.9999f) << "streets " << i << " and " << k << " overlap";
        }
      }
    }
  }
}

TEST(StreetNetwork, BlockCountWithinTenPercent) {
  for (int blocks : {10, 25, 100, 777, 5000}) {
    for (uint64_t seed : {1u, 9u}) {
      const StreetGraph g = make(blocks, seed);
      EXPECT_NEAR(double(g.blockCount()), double(blocks), 0.1 * blocks) << blocks << " seed " << seed;
    }
  }
  // The largest supported request, once (well under a second).
  const StreetGraph big = make(50000, 1);
  EXPECT_NEAR(double(big.blockCount()), 50000.0, 5000.0);
  EXPECT_EQ(int64_t(big.junctionCount()) - int64_t(big.streetCount()) + int64_t(big.faceCount()), 2);
}

TEST(StreetNetwork, DeterministicPerSeed) {
  const StreetGraph a = make(200, 42), b = make(200, 42), c = make(200, 43);
  ASSERT_EQ(a.junctionCount(), b.junctionCount());
  ASSERT_EQ(a.streetCount(), b.streetCount());
  for (uint32_t j = 0; j < a.junctionCount(); ++j) ASSERT_EQ(a.position(j), b.position(j));
  for (uint32_t s = 0; s < a.streetCount(); ++s) {
    ASSERT_EQ(a.streets()[s].a, b.streets()[s].a);
    ASSERT_EQ(a.streets()[s].b, b.streets()[s].b);
    ASSERT_EQ(a.streets()[s].width, b.streets()[s].width);
  }
  bool differs = a.junctionCount() != c.junctionCount();
  for (uint32_t j = 0; !differs && j < a.junctionCount(); ++j) differs = a.position(j) != c.position(j);
  EXPECT_TRUE(differs);
}

TEST(StreetNetwork, StreetClassesDegreesDiagonalsAndCurves) {
  const StreetGraph g = make(400, 7);
  std::map<size_t, int> degrees;
  for (uint32_t j = 0; j < g.junctionCount(); ++j) ++degrees[g.degree(j)];
  EXPECT_GE(degrees.begin()->first, 2u);   // no dead ends
  EXPECT_LE(degrees.rbegin()->first, 5u);  // at most five streets meet
  EXPECT_GT(degrees[4], 0);
  EXPECT_GT(degrees[3], 0);
  int avenues = 0, streets = 0, lanes = 0, oblique_avenue = 0, curved = 0;
  for (uint32_t s = 0; s < g.streetCount(); ++s) {
    const auto& st = g.streets()[s];
    switch (st.street_class) {
      case farfield::urban::kAvenue:
        EXPECT_GE(st.width, 20.0f);
        EXPECT_LE(st.width, 24.0f);
        ++avenues;
        break;
      case farfield::urban::kStreet:
        EXPECT_EQ(st.width, 12.0f);
        ++streets;
        break;
      case farfield::urban::kLane:
        EXPECT_EQ(st.width, 8.0f);
        ++lanes;
        break;
      default:
        ADD_FAILURE() << "street " << s << " has class " << st.street_class;
    }
    // A diagonal avenue runs at 20..70 degrees to the grid axes.
    const Vec2 d = glm::normalize(g.position(st.b) - g.position(st.a));
    if (st.street_class == farfield::urban::kAvenue && std::abs(d.x) > 0.35f && std::abs(d.y) > 0.35f)
      ++oblique_avenue;
  }
  // Curved streets: degree-2 junctions where the street turns (not a grid corner, not straight through).
  for (uint32_t j = 0; j < g.junctionCount(); ++j) {
    const auto out = g.outgoing(j);
    if (out.size() != 2) continue;
    const float c = glm::dot(g.direction(out[0]), g.direction(out[1]));
    if (c < -0.95f && c > -0.99999f) ++curved;
  }
  EXPECT_GT(avenues, 0);
  EXPECT_GT(streets, 0);
  EXPECT_GT(lanes, 0);  // blocks merged for irregularity are made up for by lanes across large blocks
  EXPECT_GT(oblique_avenue, 5);
  EXPECT_GT(curved, 10);
}

TEST(StreetNetwork, BuildableBlocksLeaveTheStreetsFree) {
  const StreetGraph g = make(150, 3);
  const auto blocks = farfield::gen::buildableBlocks(g);
  EXPECT_GE(blocks.size(), size_t(0.9 * g.blockCount()));
  for (const auto& b : blocks) {
    ASSERT_GE(b.footprint.size(), 3u);
    EXPECT_GT(farfield::signedArea(b.footprint), 0.0);
    ASSERT_FALSE(g.isOuter(b.face));
    const farfield::Polygon2 face = g.facePolygon(b.face);
    for (const Vec2& v : b.footprint) {
      // Inside its block, and at least half a street width from the centreline of every street around it.
      EXPECT_TRUE(farfield::pointInPolygon(v, face));
      for (uint32_t e : g.edgesOfFace(b.face))
        EXPECT_GE(farfield::distancePointSegment(v, g.originPosition(e), g.destinationPosition(e)),
                  0.5 * g.width(e) - 0.01)
            << "block " << b.face;
    }
  }
}

TEST(StreetNetwork, BadOptionsThrow) {
  StreetNetworkOptions o;
  o.blocks = 0;
  EXPECT_THROW(generateStreetNetwork(o), farfield::Error);
  o.blocks = 10;
  o.block_size = std::nanf("");
  EXPECT_THROW(generateStreetNetwork(o), farfield::Error);
  // Small requests still give a valid graph.
  for (int blocks = 1; blocks <= 9; ++blocks) {
    const StreetGraph g = make(blocks, 1);
    EXPECT_NEAR(double(g.blockCount()), double(blocks), 0.1 * blocks + 0.5);
  }
}
