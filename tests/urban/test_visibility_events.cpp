// Visibility-event weights (Decoret 1999, section 4.1): closed-form extremal angles against dense sampling of M on
// [PQ], hand-computed cases, critical zones against a support-function brute force, weights against brute force.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/core/polygon2d.h"
#include "farfield/urban/visibility_events.h"

namespace farfield::urban {
namespace {

// Equation 1 written out in world coordinates: cos AMB = (MA . MB) / (|MA| |MB|).
double angleAt(const DVec2& m, const DVec2& a, const DVec2& b) {
  const DVec2 u = a - m, v = b - m;
  const double c = glm::dot(u, v) / (glm::length(u) * glm::length(v));
  return std::acos(std::clamp(c, -1.0, 1.0));
}

struct Sampled {
  double min_angle = 0.0, max_angle = 0.0;
};

// Brute force: the angle at `coarse` + 1 evenly spaced points of [PQ], then every coarse local extremum (end points
// included) refined by ternary search over its two neighbouring intervals. Knows nothing of equations 3-5.
Sampled sampleExtremes(const DVec2& p, const DVec2& q, const DVec2& a, const DVec2& b, int coarse = 2000) {
  auto f = [&](double t) { return angleAt(p + (q - p) * t, a, b); };
  std::vector<double> v(size_t(coarse) + 1);
  for (int i = 0; i <= coarse; ++i) v[size_t(i)] = f(double(i) / coarse);
  Sampled s{*std::min_element(v.begin(), v.end()), *std::max_element(v.begin(), v.end())};
  auto refine = [&](int i, bool maximise) {
    double lo = double(std::max(i - 1, 0)) / coarse, hi = double(std::min(i + 1, coarse)) / coarse;
    for (int it = 0; it < 100; ++it) {
      const double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
      const bool keep_left = maximise ? f(m1) > f(m2) : f(m1) < f(m2);
      (keep_left ? hi : lo) = keep_left ? m2 : m1;
    }
    const double x = f(0.5 * (lo + hi));
    if (maximise)
      s.max_angle = std::max(s.max_angle, x);
    else
      s.min_angle = std::min(s.min_angle, x);
  };
  for (int i = 0; i <= coarse; ++i) {
    const double left = i > 0 ? v[size_t(i - 1)] : v[size_t(i)];
    const double right = i < coarse ? v[size_t(i + 1)] : v[size_t(i)];
    if (v[size_t(i)] >= left && v[size_t(i)] >= right) refine(i, true);
    if (v[size_t(i)] <= left && v[size_t(i)] <= right) refine(i, false);
  }
  return s;
}

double distanceToSegment(const DVec2& x, const DVec2& p, const DVec2& q) {
  const DVec2 e = q - p;
  const double len2 = glm::dot(e, e);
  const double t = len2 > 0.0 ? std::clamp(glm::dot(x - p, e) / len2, 0.0, 1.0) : 0.0;
  return glm::length(x - (p + e * t));
}

struct Worst {
  double error = 0.0;
  int count = 0;
};

// Compares one configuration; returns the larger of the min and max differences.
double compare(const DVec2& p, const DVec2& q, const DVec2& a, const DVec2& b, AngleCase expected_case) {
  const ExtremalAngles closed = extremalAngles(p, q, a, b);
  EXPECT_EQ(closed.angle_case, expected_case);
  const Sampled sampled = sampleExtremes(p, q, a, b);
  const double err = std::max(std::abs(closed.max_angle - sampled.max_angle),
                              std::abs(closed.min_angle - sampled.min_angle));
  // The returned extremal points lie on [PQ] and reach the reported angles.
  EXPECT_LT(distanceToSegment(closed.argmax, p, q), 1e-9 * (1.0 + glm::length(q - p)));
  EXPECT_LT(distanceToSegment(closed.argmin, p, q), 1e-9 * (1.0 + glm::length(q - p)));
  EXPECT_NEAR(angleAt(closed.argmax, a, b), closed.max_angle, 1e-6);
  EXPECT_NEAR(angleAt(closed.argmin, a, b), closed.min_angle, 1e-6);
  return err;
}

DVec2 randomPoint(std::mt19937_64& rng, double range) {
  std::uniform_real_distribution<double> u(-range, range);
  return DVec2(u(rng), u(rng));
}

TEST(ExtremalAngles, HandComputedParallelCase) {
  // A = (-1, 1), B = (1, 1) over [(-10, 0), (10, 0)]: the maximum is at H = (0, 0), where AMB is a right angle;
  // the minimum at P and Q (symmetric), atan(1/9) - atan(1/11).
  const ExtremalAngles e = extremalAngles({-10, 0}, {10, 0}, {-1, 1}, {1, 1});
  EXPECT_EQ(e.angle_case, AngleCase::Parallel);
  EXPECT_NEAR(e.max_angle, kPi / 2.0, 1e-12);
  EXPECT_NEAR(e.argmax.x, 0.0, 1e-12);
  EXPECT_NEAR(e.min_angle, std::atan(1.0 / 9.0) - std::atan(1.0 / 11.0), 1e-12);
  EXPECT_NEAR(std::abs(e.argmin.x), 10.0, 1e-12);
  // H off the segment: the angle only rises over [(-10, 0), (-5, 0)].
  const ExtremalAngles f = extremalAngles({-10, 0}, {-5, 0}, {-1, 1}, {1, 1});
  EXPECT_EQ(f.angle_case, AngleCase::Parallel);
  EXPECT_NEAR(f.max_angle, std::atan(1.0 / 4.0) - std::atan(1.0 / 6.0), 1e-12);
  EXPECT_NEAR(f.argmax.x, -5.0, 1e-12);
  EXPECT_NEAR(f.min_angle, std::atan(1.0 / 9.0) - std::atan(1.0 / 11.0), 1e-12);
}

TEST(ExtremalAngles, HandComputedGeneralCase) {
  // A = (0, 2), B = (0, 1) over [(-3, 0), (3, 0)]. In the paper's frame (the farther point at (0, 1)) B is at
  // (0, 1/2): M1 = 0 (collinear, angle 0), M2,3 = +-sqrt(1/8) / (1/2) = +-1/sqrt(2), i.e. +-sqrt(2) metres, where
  // the angle is atan(sqrt(2) / 4) (tan of the difference of atan(2/sqrt(2)) and atan(1/sqrt(2))).
  const ExtremalAngles e = extremalAngles({-3, 0}, {3, 0}, {0, 2}, {0, 1});
  EXPECT_EQ(e.angle_case, AngleCase::General);
  EXPECT_NEAR(e.min_angle, 0.0, 1e-12);
  EXPECT_NEAR(e.argmin.x, 0.0, 1e-12);
  EXPECT_NEAR(e.max_angle, std::atan(std::sqrt(2.0) / 4.0), 1e-12);
  EXPECT_NEAR(std::abs(e.argmax.x), std::sqrt(2.0), 1e-12);
  // Over [(-1, 0), (1, 0)] the critical points M2,3 fall outside: the maximum is at the end points, atan(1/3).
  const ExtremalAngles f = extremalAngles({-1, 0}, {1, 0}, {0, 2}, {0, 1});
  EXPECT_NEAR(f.max_angle, std::atan(1.0 / 3.0), 1e-12);
  EXPECT_NEAR(std::abs(f.argmax.x), 1.0, 1e-12);
  // Points on opposite sides: the angle is pi where [AB] crosses [PQ].
  const ExtremalAngles g = extremalAngles({-3, 0}, {3, 0}, {0, 2}, {2, -2});
  EXPECT_NEAR(g.max_angle, kPi, 1e-12);
  EXPECT_NEAR(g.argmax.x, 1.0, 1e-12);
}

TEST(ExtremalAngles, GeneralCaseMatchesDenseSampling) {
  std::mt19937_64 rng(12345);
  double worst = 0.0;
  int tested = 0;
  while (tested < 3000) {
    const DVec2 p = randomPoint(rng, 60.0), q = randomPoint(rng, 60.0);
    const DVec2 a = randomPoint(rng, 150.0), b = randomPoint(rng, 150.0);
    // Street-like configurations: the points stay at least a metre off the segment (blocks are off the street).
    if (distanceToSegment(a, p, q) < 1.0 || distanceToSegment(b, p, q) < 1.0) continue;
    worst = std::max(worst, compare(p, q, a, b, AngleCase::General));
    ++tested;
  }
  std::printf("[          ] general case: largest |closed form - sampling| = %.3g rad over %d configurations\n",
              worst, tested);
  EXPECT_LT(worst, 1e-4);
}

TEST(ExtremalAngles, ParallelCaseMatchesDenseSampling) {
  // Exactly parallel configurations: integer points, B = A + m d and Q = P + k d with the same integer direction d,
  // so (AB) and (PQ) are parallel without rounding.
  std::mt19937_64 rng(777);
  std::uniform_int_distribution<int> coord(-60, 60), dir(-5, 5), step(-12, 12);
  double worst = 0.0;
  int tested = 0;
  while (tested < 3000) {
    const DVec2 d(dir(rng), dir(rng));
    const int k = step(rng), m = step(rng);
    if (d == DVec2(0.0) || k == 0 || m == 0) continue;
    const DVec2 p(coord(rng), coord(rng)), a(coord(rng), coord(rng));
    const DVec2 q = p + d * double(k), b = a + d * double(m);
    if (cross2(d, a - p) == 0.0) continue;  // A and B on the line (PQ) itself: the collinear case
    if (distanceToSegment(a, p, q) < 1.0 || distanceToSegment(b, p, q) < 1.0) continue;
    worst = std::max(worst, compare(p, q, a, b, AngleCase::Parallel));
    ++tested;
  }
  std::printf("[          ] parallel case: largest |closed form - sampling| = %.3g rad over %d configurations\n",
              worst, tested);
  EXPECT_LT(worst, 1e-4);
}

TEST(ExtremalAngles, NearlyParallelConfigurationsStayAccurate) {
  // (AB) almost parallel to (PQ): equations 4-5 divide by 1 - y_B -> 0; the general branch must stay accurate.
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> u(-50.0, 50.0), tilt(-1e-6, 1e-6), depth(5.0, 80.0);
  double worst = 0.0;
  for (int i = 0; i < 1000; ++i) {
    const double y = depth(rng) * (i % 2 ? 1.0 : -1.0);
    const DVec2 p(u(rng), 0.0), q(u(rng), 0.0);
    const DVec2 a(u(rng), y);
    const DVec2 b(u(rng), y * (1.0 + tilt(rng)) + 1e-7);
    worst = std::max(worst, compare(p, q, a, b, AngleCase::General));
  }
  std::printf("[          ] nearly parallel: largest |closed form - sampling| = %.3g rad\n", worst);
  EXPECT_LT(worst, 1e-4);
}

TEST(ExtremalAngles, DegenerateConfigurations) {
  // A point on the cell: undefined angle, reported as the whole range.
  const ExtremalAngles on = extremalAngles({0, 0}, {10, 0}, {4, 0}, {3, 7});
  EXPECT_EQ(on.angle_case, AngleCase::OnCell);
  EXPECT_DOUBLE_EQ(on.variation(), kPi);
  // Both on the line (PQ), off the segment: constant angle.
  const ExtremalAngles same = extremalAngles({0, 0}, {10, 0}, {-4, 0}, {-9, 0});
  EXPECT_EQ(same.angle_case, AngleCase::Collinear);
  EXPECT_DOUBLE_EQ(same.max_angle, 0.0);
  const ExtremalAngles opposite = extremalAngles({0, 0}, {10, 0}, {-4, 0}, {19, 0});
  EXPECT_DOUBLE_EQ(opposite.min_angle, kPi);
  EXPECT_DOUBLE_EQ(opposite.variation(), 0.0);
  // One point on the line off the segment: the general formulas still hold (y_B = 0), checked by sampling.
  const ExtremalAngles one = extremalAngles({0, 0}, {10, 0}, {-4, 0}, {3, 7});
  const Sampled s = sampleExtremes({0, 0}, {10, 0}, {-4, 0}, {3, 7});
  EXPECT_NEAR(one.max_angle, s.max_angle, 1e-6);
  EXPECT_NEAR(one.min_angle, s.min_angle, 1e-6);
  // A point cell: a single viewpoint, no variation.
  const ExtremalAngles point = extremalAngles({2, 2}, {2, 2}, {-4, 5}, {3, 7});
  EXPECT_NEAR(point.variation(), 0.0, 1e-15);
  EXPECT_NEAR(point.max_angle, angleAt({2, 2}, {-4, 5}, {3, 7}), 1e-12);
  // A == B.
  EXPECT_DOUBLE_EQ(extremalAngles({0, 0}, {10, 0}, {3, 7}, {3, 7}).variation(), 0.0);
}

// ---- critical zones, distances, weights ----

Polygon2 rect(float x0, float y0, float x1, float y1) { return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}; }

// Random star-shaped footprint (possibly non-convex) around c, counter-clockwise.
Polygon2 randomFootprint(std::mt19937_64& rng, const Vec2& c, float radius) {
  std::uniform_int_distribution<int> count(3, 8);
  std::uniform_real_distribution<float> r(0.35f, 1.0f), jitter(-0.3f, 0.3f);
  const int n = count(rng);
  Polygon2 poly;
  for (int i = 0; i < n; ++i) {
    const float angle = float(2.0 * kPi) * (float(i) + 0.5f + jitter(rng)) / float(n);
    const float rr = radius * r(rng);
    poly.push_back(c + rr * Vec2(std::cos(angle), std::sin(angle)));
  }
  return poly;
}

// Signed distance from x to a convex polygon (negative inside), from core's point-in-polygon and boundary distance.
double signedDistance(const DVec2& x, const Polygon2& convex) {
  const Vec2 xf(float(x.x), float(x.y));
  const double d = distanceToBoundary(xf, convex);
  return pointInPolygon(xf, convex) ? -d : d;
}

// Distance from footprint `a` to the critical zone of `b` (negative when a vertex or edge of `a` goes inside),
// computed independently of intersectsConvex: the zone is core's convex hull of b's vertices and the cell's end
// points, and along each edge of `a` the signed distance to a convex set is a convex function, so a ternary search
// finds its minimum.
double zoneDistance(const Polygon2& a, const Polygon2& b, const CellSegment& cell) {
  std::vector<Vec2> points(b.begin(), b.end());
  points.push_back(cell.p);
  points.push_back(cell.q);
  const Polygon2 hull = convexHull(points);
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < a.size(); ++i) {
    const DVec2 u(a[i].x, a[i].y), v(a[(i + 1) % a.size()].x, a[(i + 1) % a.size()].y);
    auto f = [&](double t) { return signedDistance(u + (v - u) * t, hull); };
    double lo = 0.0, hi = 1.0;
    for (int it = 0; it < 80; ++it) {
      const double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
      (f(m1) < f(m2) ? hi : lo) = f(m1) < f(m2) ? m2 : m1;
    }
    best = std::min({best, f(0.0), f(0.5 * (lo + hi))});
  }
  return best;
}

TEST(CriticalZone, ObjectBehindAnotherIsRelatedAndOneAsideIsNot) {
  const CellSegment cell{{0, 0}, {10, 0}};
  const std::vector<EventObject> objects = {
      {rect(0, 20, 10, 30)},     // in front
      {rect(0, 50, 10, 60)},     // behind it: the front one lies in its critical zone
      {rect(200, 20, 210, 30)},  // far to the side: in nobody's zone, nobody in its
  };
  EXPECT_TRUE(intersectsConvex(objects[0].footprint, criticalZone(objects[1].footprint, cell)));
  EXPECT_FALSE(intersectsConvex(objects[1].footprint, criticalZone(objects[0].footprint, cell)));
  EXPECT_FALSE(intersectsConvex(objects[0].footprint, criticalZone(objects[2].footprint, cell)));
  EXPECT_FALSE(intersectsConvex(objects[2].footprint, criticalZone(objects[0].footprint, cell)));
  const EventGraph graph = computeEventGraph(objects, cell);
  EXPECT_GT(graph.weight(0, 1), 0.0);
  EXPECT_DOUBLE_EQ(graph.weight(0, 1), graph.weight(1, 0));
  EXPECT_EQ(graph.weight(0, 2), 0.0);
  EXPECT_EQ(graph.weight(1, 2), 0.0);
  EXPECT_EQ(graph.edgeCount(), 1u);
  EXPECT_EQ(graph.object_pairs, 3u);
  EXPECT_EQ(graph.zone_pairs, 1u);
  EXPECT_EQ(graph.point_pairs, 16u);
}

TEST(CriticalZone, DistanceToCellMatchesBruteForce) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<float> u(-80.0f, 80.0f), rad(3.0f, 25.0f);
  for (int trial = 0; trial < 200; ++trial) {
    const CellSegment cell{{u(rng) * 0.3f, u(rng) * 0.3f}, {u(rng) * 0.3f, u(rng) * 0.3f}};
    const Polygon2 poly = randomFootprint(rng, {u(rng), u(rng)}, rad(rng));
    // Brute force: the segment sampled densely against the polygon (inside -> 0, else distance to its boundary).
    double brute = std::numeric_limits<double>::infinity();
    for (int s = 0; s <= 4000; ++s) {
      const Vec2 m = cell.p + (cell.q - cell.p) * (float(s) / 4000.0f);
      brute = std::min(brute, pointInPolygon(m, poly) ? 0.0 : distanceToBoundary(m, poly));
    }
    const double got = distanceToCell(poly, cell);
    EXPECT_LE(got, brute + 1e-3) << "trial " << trial;
    EXPECT_GE(got, brute - 0.05) << "trial " << trial;  // the sampling step along the cell is <= 0.04 m
  }
}

TEST(EventGraph, WeightsMatchBruteForceOnRandomFootprints) {
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<float> u(-120.0f, 120.0f), rad(4.0f, 20.0f);
  int related = 0, unrelated = 0;
  for (int scene = 0; scene < 3; ++scene) {
    const CellSegment cell{{-15.0f + u(rng) * 0.05f, u(rng) * 0.05f}, {15.0f + u(rng) * 0.05f, u(rng) * 0.05f}};
    std::vector<EventObject> objects;
    while (objects.size() < 14) {
      const Vec2 c(u(rng), u(rng));
      const float r = rad(rng);
      // Keep footprints off the street.
      if (distanceToSegment(DVec2(c), DVec2(cell.p), DVec2(cell.q)) < double(r) + 3.0) continue;
      objects.push_back({randomFootprint(rng, c, r)});
    }
    const EventGraph graph = computeEventGraph(objects, cell);
    for (uint32_t i = 0; i < objects.size(); ++i)
      for (uint32_t j = i + 1; j < objects.size(); ++j) {
        const double d = std::min(zoneDistance(objects[i].footprint, objects[j].footprint, cell),
                                  zoneDistance(objects[j].footprint, objects[i].footprint, cell));
        const double w = graph.weight(i, j);
        if (d > 1e-3) {
          EXPECT_EQ(w, 0.0) << "scene " << scene << " pair " << i << "-" << j << " zone distance " << d;
          ++unrelated;
          continue;
        }
        if (d > -1e-3) continue;  // touching: either answer is right
        ++related;
        // Brute-force weight: the largest sampled variation over all vertex pairs.
        double brute = 0.0;
        for (const Vec2& a : objects[i].footprint)
          for (const Vec2& b : objects[j].footprint) {
            const Sampled s = sampleExtremes(DVec2(cell.p), DVec2(cell.q), DVec2(a), DVec2(b), 400);
            brute = std::max(brute, s.max_angle - s.min_angle);
          }
        EXPECT_NEAR(w, brute, 1e-4) << "scene " << scene << " pair " << i << "-" << j;
      }
  }
  EXPECT_GT(related, 10);
  EXPECT_GT(unrelated, 10);
}

TEST(EventGraph, LandmarksBoostTheirEdges) {
  const CellSegment cell{{0, 0}, {30, 0}};
  std::vector<EventObject> objects = {{rect(0, 20, 10, 30)}, {rect(5, 50, 15, 60)}, {rect(20, 80, 30, 90)}};
  const EventGraph plain = computeEventGraph(objects, cell);
  objects[1].landmark = true;
  VisibilityEventOptions options;
  options.landmark_boost = 3.0;
  const EventGraph boosted = computeEventGraph(objects, cell, options);
  ASSERT_GT(plain.weight(0, 1), 0.0);
  ASSERT_GT(plain.weight(0, 2), 0.0);
  EXPECT_NEAR(boosted.weight(0, 1), 3.0 * plain.weight(0, 1), 1e-12);
  EXPECT_NEAR(boosted.weight(1, 2), 3.0 * plain.weight(1, 2), 1e-12);
  EXPECT_DOUBLE_EQ(boosted.weight(0, 2), plain.weight(0, 2));
}

TEST(EventGraph, HullVerticesAgreeForConvexAndBoundNonConvexFootprints) {
  const CellSegment cell{{0, 0}, {30, 0}};
  // An L-shaped (non-convex) block behind a convex one.
  const Polygon2 ell = {{0, 40}, {30, 40}, {30, 50}, {10, 50}, {10, 70}, {0, 70}};
  const std::vector<EventObject> convex = {{rect(0, 20, 10, 30)}, {rect(5, 50, 15, 60)}};
  const std::vector<EventObject> mixed = {{rect(5, 15, 20, 25)}, {ell}};
  VisibilityEventOptions hull;
  hull.points = RepresentativePoints::HullVertices;
  EXPECT_DOUBLE_EQ(computeEventGraph(convex, cell).weight(0, 1), computeEventGraph(convex, cell, hull).weight(0, 1));
  const double all = computeEventGraph(mixed, cell).weight(0, 1);
  const double outer = computeEventGraph(mixed, cell, hull).weight(0, 1);
  EXPECT_GT(outer, 0.0);
  EXPECT_GE(all, outer);
}

TEST(EventGraph, ObjectOnTheCellGetsTheFullRange) {
  const CellSegment cell{{0, 0}, {30, 0}};
  const std::vector<EventObject> objects = {{rect(10, -2, 12, 2)}, {rect(0, 20, 10, 30)}};
  const EventGraph graph = computeEventGraph(objects, cell);
  EXPECT_DOUBLE_EQ(graph.weight(0, 1), kPi);
  EXPECT_GT(graph.on_cell, 0u);
}

TEST(EventGraph, BadInputThrows) {
  const CellSegment cell{{0, 0}, {30, 0}};
  const std::vector<EventObject> empty = {{rect(0, 20, 10, 30)}, {Polygon2{}}};
  EXPECT_THROW(computeEventGraph(empty, cell), Error);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<EventObject> bad = {{Polygon2{{0, 20}, {nan, 20}, {5, 30}}}};
  try {
    computeEventGraph(bad, cell);
    FAIL() << "expected farfield::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("vertex 1"), std::string::npos) << e.what();
  }
  EXPECT_THROW(computeEventGraph(std::vector<EventObject>{}, CellSegment{{nan, 0}, {1, 0}}), Error);
  VisibilityEventOptions options;
  options.landmark_boost = 0.5;
  EXPECT_THROW(computeEventGraph(std::vector<EventObject>{}, cell, options), Error);
}

}  // namespace
}  // namespace farfield::urban
