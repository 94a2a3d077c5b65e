#include "farfield/core/douglas_peucker.h"

#include <gtest/gtest.h>

#include <random>

namespace farfield {
namespace {

double distanceToPolyline(const DVec2& p, const std::vector<DVec2>& line, bool closed) {
  double best = 1e300;
  const size_t n = closed ? line.size() : line.size() - 1;
  for (size_t i = 0; i < n; ++i) {
    const DVec2 a = line[i], b = line[(i + 1) % line.size()];
    const DVec2 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double t = len2 > 0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    best = std::min(best, glm::length(p - (a + t * ab)));
  }
  return best;
}

TEST(DouglasPeuckerTest, NoisyLineCollapsesAndCornerSurvives) {
  std::vector<DVec2> line;
  for (int i = 0; i <= 20; ++i) line.push_back(DVec2(i, (i % 2) * 0.4));
  EXPECT_EQ(simplifyPolyline(line, 0.5).size(), 2u);
  EXPECT_GT(simplifyPolyline(line, 0.3).size(), 10u);  // the zigzag exceeds the tolerance: most points stay

  const std::vector<DVec2> vee = {{0, 0}, {5, 5}, {10, 0}};
  const std::vector<DVec2> kept = simplifyPolyline(vee, 1.0);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_EQ(kept[1], DVec2(5, 5));
  // Exactly collinear points go even with a zero tolerance.
  EXPECT_EQ(simplifyPolyline({{0, 0}, {1, 1}, {2, 2}, {3, 3}}, 0.0).size(), 2u);
}

TEST(DouglasPeuckerTest, RandomWalksStayWithinTolerance) {
  std::mt19937 rng(3);
  std::normal_distribution<double> step(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<DVec2> walk{{0, 0}};
    for (int i = 0; i < 200; ++i) walk.push_back(walk.back() + DVec2(1.0 + std::abs(step(rng)), step(rng)));
    const double tol = 0.5 + trial * 0.2;
    const std::vector<size_t> idx = douglasPeuckerIndices(walk, tol);
    ASSERT_GE(idx.size(), 2u);
    EXPECT_EQ(idx.front(), 0u);
    EXPECT_EQ(idx.back(), walk.size() - 1);
    for (size_t i = 1; i < idx.size(); ++i) EXPECT_LT(idx[i - 1], idx[i]);
    const std::vector<DVec2> simple = simplifyPolyline(walk, tol);
    for (const DVec2& p : walk) EXPECT_LE(distanceToPolyline(p, simple, false), tol + 1e-9);

    // The same walk closed into a loop.
    const std::vector<DVec2> closed = simplifyClosed(walk, tol);
    ASSERT_GE(closed.size(), 3u);
    for (const DVec2& p : walk) EXPECT_LE(distanceToPolyline(p, closed, true), tol + 1e-9);
  }
}

}  // namespace
}  // namespace farfield
