// Planar invariants of a street graph, checked independently of urban::StreetGraph's own construction: the
// half-edge invariants of the street-graph tests, Euler's formula with components counted here, every face a
// closed cycle, blocks counter-clockwise, and no two streets crossing (sweep over x with exact predicates).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <vector>

#include "farfield/core/polygon2d.h"
#include "farfield/urban/street_graph.h"

namespace farfield::test {

inline double orient2(const DVec2& a, const DVec2& b, const DVec2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// Closed segments share a point (touching counts).
inline bool segmentsShareAPoint(const DVec2& a, const DVec2& b, const DVec2& c, const DVec2& d) {
  auto sgn = [](double v) { return (v > 0) - (v < 0); };
  auto within = [](const DVec2& p, const DVec2& q, const DVec2& r) {
    return std::min(p.x, q.x) <= r.x && r.x <= std::max(p.x, q.x) && std::min(p.y, q.y) <= r.y &&
           r.y <= std::max(p.y, q.y);
  };
  const int o1 = sgn(orient2(a, b, c)), o2 = sgn(orient2(a, b, d)), o3 = sgn(orient2(c, d, a)),
            o4 = sgn(orient2(c, d, b));
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && within(a, b, c)) || (o2 == 0 && within(a, b, d)) || (o3 == 0 && within(c, d, a)) ||
         (o4 == 0 && within(c, d, b));
}

// Pairs of streets that meet anywhere but at a shared junction (or overlap from a shared junction). Sweep: streets
// sorted by their smallest x; each is compared with the following ones until their smallest x passes its largest.
inline size_t countCrossings(const urban::StreetGraph& g, size_t max_report = 5) {
  const auto& st = g.streets();
  std::vector<uint32_t> order(st.size());
  std::iota(order.begin(), order.end(), 0u);
  auto lo_x = [&](uint32_t s) { return std::min(g.position(st[s].a).x, g.position(st[s].b).x); };
  auto hi_x = [&](uint32_t s) { return std::max(g.position(st[s].a).x, g.position(st[s].b).x); };
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return lo_x(a) < lo_x(b); });
  size_t bad = 0;
  for (size_t i = 0; i < order.size(); ++i) {
    const urban::Street& s = st[order[i]];
    const DVec2 a(g.position(s.a)), b(g.position(s.b));
    const float end = hi_x(order[i]);
    for (size_t k = i + 1; k < order.size() && lo_x(order[k]) <= end; ++k) {
      const urban::Street& t = st[order[k]];
      const DVec2 c(g.position(t.a)), d(g.position(t.b));
      const int shared = (s.a == t.a) + (s.a == t.b) + (s.b == t.a) + (s.b == t.b);
      bool meet = false;
      if (shared == 0) {
        meet = segmentsShareAPoint(a, b, c, d);
      } else if (shared == 1) {
        const uint32_t j = (s.a == t.a || s.a == t.b) ? s.a : s.b;
        const DVec2 o(g.position(j)), p = (s.a == j) ? b : a, q = (t.a == j) ? d : c;
        meet = orient2(o, p, q) == 0.0 && glm::dot(p - o, q - o) > 0.0;  // overlapping from the junction
      } else {
        meet = true;  // duplicate street
      }
      if (meet) {
        if (bad < max_report)
          ADD_FAILURE() << "streets " << order[i] << " and " << order[k] << " meet outside a shared junction near ("
                        << a.x << ", " << a.y << ")";
        ++bad;
      }
    }
  }
  return bad;
}

inline void checkStreetGraph(const urban::StreetGraph& g) {
  const uint32_t n = uint32_t(g.halfEdgeCount());
  ASSERT_EQ(n, 2 * g.streetCount());
  for (uint32_t e = 0; e < n; ++e) {
    ASSERT_EQ(urban::StreetGraph::twin(urban::StreetGraph::twin(e)), e);
    ASSERT_NE(urban::StreetGraph::twin(e), e);
    ASSERT_EQ(g.next(g.prev(e)), e);
    ASSERT_EQ(g.prev(g.next(e)), e);
    ASSERT_EQ(g.destination(e), g.origin(g.next(e)));
    ASSERT_EQ(g.origin(urban::StreetGraph::twin(e)), g.destination(e));
    ASSERT_LT(g.face(e), g.faceCount());
  }
  // Faces: closed cycles carrying their face; each half-edge on at most one walked cycle; blocks CCW.
  std::vector<int> seen(n, 0);
  for (uint32_t f = 0; f < g.faceCount(); ++f) {
    const auto edges = g.edgesOfFace(f);
    for (size_t i = 0; i < edges.size(); ++i) {
      ASSERT_EQ(g.face(edges[i]), f);
      ASSERT_EQ(g.next(edges[i]), edges[(i + 1) % edges.size()]);
      ++seen[edges[i]];
    }
    if (!g.isOuter(f)) {
      EXPECT_GE(edges.size(), 3u);
      EXPECT_GT(signedArea(g.facePolygon(f)), 0.0) << "block " << f;
    }
  }
  for (uint32_t e = 0; e < n; ++e) ASSERT_LE(seen[e], 1);
  // Every half-edge lies on a cycle of its face: walk from it and come back.
  for (uint32_t e = 0; e < n; ++e) {
    uint32_t x = e;
    size_t steps = 0;
    do {
      x = g.next(x);
      ASSERT_LE(++steps, size_t(n));
      ASSERT_EQ(g.face(x), g.face(e));
    } while (x != e);
  }
  // Euler: V - E + F = 1 + C, components counted here by union-find (no isolated junctions expected).
  std::vector<uint32_t> parent(g.junctionCount());
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  size_t components = g.junctionCount();
  for (const auto& s : g.streets()) {
    const uint32_t a = find(s.a), b = find(s.b);
    if (a != b) parent[a] = b, --components;
  }
  for (uint32_t j = 0; j < g.junctionCount(); ++j) EXPECT_GT(g.degree(j), 0u) << "isolated junction " << j;
  if (g.junctionCount() > 0) {
    EXPECT_EQ(int64_t(g.junctionCount()) - int64_t(g.streetCount()) + int64_t(g.faceCount()),
              1 + int64_t(components));
  }
  EXPECT_EQ(countCrossings(g), 0u);
}

}  // namespace farfield::test
