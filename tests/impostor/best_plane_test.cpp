// impostor/best_plane.h against an exhaustive search over orientations: no normal of a dense grid over the allowed
// cone gives a smaller mean squared distance than the chosen plane's.
#include "farfield/impostor/best_plane.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "farfield/core/error.h"

namespace farfield::impostor {
namespace {

DVec3 randomUnit(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return glm::normalize(DVec3(g(rng), g(rng), g(rng)));
}

// The smallest objective over normals within max_tilt of v: a polar grid of the cap.
double exhaustiveMinimum(const std::vector<DVec3>& pts, const DVec3& v, double max_tilt) {
  const DVec3 a = glm::normalize(glm::cross(v, std::abs(v.z) < 0.9 ? DVec3(0, 0, 1) : DVec3(1, 0, 0)));
  const DVec3 b = glm::cross(v, a);
  double best = meanSquaredDistance(pts, v);
  constexpr int kRings = 150, kSpokes = 360;
  for (int i = 1; i <= kRings; ++i) {
    const double tilt = max_tilt * i / kRings;
    for (int j = 0; j < kSpokes; ++j) {
      const double phi = 2 * kPi * j / kSpokes;
      const DVec3 n = std::cos(tilt) * v + std::sin(tilt) * (std::cos(phi) * a + std::sin(phi) * b);
      best = std::min(best, meanSquaredDistance(pts, n));
    }
  }
  return best;
}

TEST(BestPlane, NoOrientationOfTheConeDoesBetter) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int rim_cases = 0;
  for (int trial = 0; trial < 16; ++trial) {
    // A flattened, rotated cloud (a facade, a tree crown, a roof) and a capture eye in a random direction.
    const DVec3 ax = randomUnit(rng);
    const DVec3 ay = glm::normalize(glm::cross(ax, randomUnit(rng)));
    const DVec3 az = glm::cross(ax, ay);
    const DVec3 extent(10.0, 3.0 + 5.0 * std::abs(u(rng)), 0.5 + std::abs(u(rng)));
    std::vector<DVec3> pts;
    const DVec3 centre(u(rng) * 100, u(rng) * 100, u(rng) * 20);
    for (int i = 0; i < 200; ++i) pts.push_back(centre + u(rng) * extent.x * ax + u(rng) * extent.y * ay +
                                                u(rng) * extent.z * az);
    const DVec3 eye = centre + 80.0 * randomUnit(rng);
    const double max_tilt = degToRad(trial % 2 ? 60.0 : 30.0);
    const BestPlane best = bestPlane(pts, eye, max_tilt);
    const DVec3 v = glm::normalize(eye - best.plane.point);
    EXPECT_GE(glm::dot(best.plane.normal, v), std::cos(max_tilt) - 1e-9);
    EXPECT_NEAR(glm::length(best.plane.normal), 1.0, 1e-12);
    const double mine = meanSquaredDistance(pts, best.plane.normal);
    const double grid = exhaustiveMinimum(pts, v, max_tilt);
    EXPECT_LE(mine, grid * (1.0 + 1e-9) + 1e-12) << "trial " << trial;
    // And not a lucky tie with a poor grid: the grid gets close to it.
    EXPECT_LE(grid, mine * 1.01 + 1e-9) << "trial " << trial;
    EXPECT_NEAR(best.rms_distance * best.rms_distance, mine, 1e-9 * (1 + mine));
    if (glm::dot(best.plane.normal, v) < std::cos(max_tilt) + 1e-6) ++rim_cases;
  }
  EXPECT_GT(rim_cases, 2);  // both branches (free eigenvector and cone rim) were exercised
  EXPECT_LT(rim_cases, 14);
}

TEST(BestPlane, FlatSamplesGiveTheirOwnPlane) {
  std::vector<DVec3> pts;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) pts.push_back(DVec3(i, 3.0, j));
  const BestPlane best = bestPlane(pts, DVec3(4, -50, 6));
  EXPECT_NEAR(std::abs(best.plane.normal.y), 1.0, 1e-12);
  EXPECT_LT(best.plane.normal.y, 0.0);  // towards the eye
  EXPECT_NEAR(best.max_distance, 0.0, 1e-12);
}

TEST(BestPlane, BadInputIsAnError) {
  const std::vector<DVec3> none;
  EXPECT_THROW(bestPlane(none, DVec3(0, 0, 10)), Error);
  const std::vector<DVec3> one{DVec3(0, 0, 0), DVec3(std::nan(""), 0, 0)};
  EXPECT_THROW(bestPlane(one, DVec3(0, 0, 10)), Error);
  const std::vector<DVec3> two{DVec3(0, 0, 0), DVec3(1, 0, 0)};
  EXPECT_THROW(bestPlane(two, DVec3(0.5, 0, 0)), Error);
  EXPECT_THROW(bestPlane(two, DVec3(0, 0, 10), 2.0), Error);
}

}  // namespace
}  // namespace farfield::impostor
