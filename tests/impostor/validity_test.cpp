// impostor/validity.h against brute force: the parallax of points on one capture ray through a box, measured by
// dense sampling of rays and eyes, never exceeds the closed form; and the region's frame and envelope lookup.
#include "farfield/impostor/validity.h"

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "farfield/core/camera.h"
#include "farfield/impostor/grid_mesh.h"

namespace farfield::impostor {
namespace {

// The largest angle, seen from `eye`, between the entry and exit points of rays from `capture` through `box`,
// over `rays` random rays aimed at random points of the box (the subtended angle of a chord bounds that of any two
// of its points).
double bruteForceParallax(const Vec3& capture, const Vec3& eye, const Box3& box, int rays, std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const DVec3 e(capture), v(eye), lo(box.lo), hi(box.hi);
  double worst = 0.0;
  for (int i = 0; i < rays; ++i) {
    // Aim at a random point of the box surface or inside (corners and faces give the extremes).
    DVec3 target(lo.x + unit(rng) * (hi.x - lo.x), lo.y + unit(rng) * (hi.y - lo.y), lo.z + unit(rng) * (hi.z - lo.z));
    if (i % 3 == 0) target[i % 2] = (unit(rng) < 0.5 ? lo : hi)[i % 2];
    const DVec3 u = glm::normalize(target - e);
    // Slab intersection.
    double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      if (std::abs(u[a]) < 1e-12) continue;
      double ta = (lo[a] - e[a]) / u[a], tb = (hi[a] - e[a]) / u[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    if (!(t1 > t0)) continue;
    const DVec3 a = glm::normalize(e + t0 * u - v), b = glm::normalize(e + t1 * u - v);
    worst = std::max(worst, std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0)));
  }
  return worst;
}

TEST(ParallaxBound, NeverBelowBruteForceOverRandomConfigurations) {
  std::mt19937 rng(20261201);
  std::uniform_real_distribution<float> coord(-200.0f, 200.0f), size(1.0f, 60.0f), step(-60.0f, 60.0f);
  int compared = 0;
  double tightest = 1e9;
  for (int trial = 0; trial < 3000; ++trial) {
    const Vec3 lo(coord(rng), coord(rng), coord(rng) * 0.1f);
    const Box3 box{lo, lo + Vec3(size(rng), size(rng), size(rng))};
    const Vec3 capture(coord(rng), coord(rng), 1.7f);
    const Vec3 eye = capture + Vec3(step(rng), step(rng), step(rng) * 0.02f);
    const double bound = parallaxBound(capture, eye, box);
    const double brute = bruteForceParallax(capture, eye, box, 400, rng);
    ASSERT_GE(bound + 1e-9, brute) << "trial " << trial;
    if (brute > 1e-3 && bound < kPi) {
      tightest = std::min(tightest, bound / brute);
      ++compared;
    }
  }
  EXPECT_GT(compared, 1000);
  EXPECT_LT(tightest, 2.0);  // not uselessly loose: somewhere within 2x of the sampled truth
}

TEST(ParallaxBound, ZeroAtTheCaptureEyeAndPiInsideTheBox) {
  const Box3 box{Vec3(10, -5, 0), Vec3(20, 5, 10)};
  EXPECT_EQ(parallaxBound(Vec3(0, 0, 2), Vec3(0, 0, 2), box), 0.0);
  EXPECT_EQ(parallaxBound(Vec3(0, 0, 2), Vec3(15, 0, 2), box), kPi);
  EXPECT_EQ(parallaxBound(Vec3(15, 0, 2), Vec3(0, 0, 2), box), kPi);
  EXPECT_EQ(parallaxBound(Vec3(0, 0, 2), Vec3(1, 0, 2), Box3{}), 0.0);
}

// Motion along the ray towards a distant box shows far less parallax than motion across it: the direction term.
TEST(ParallaxBound, MotionAlongTheViewAxisIsCheaperThanAcross) {
  const Box3 box{Vec3(295, -10, 0), Vec3(305, 10, 20)};
  const Vec3 capture(0, 0, 10);
  const double along = parallaxBound(capture, capture + Vec3(50, 0, 0), box);
  const double across = parallaxBound(capture, capture + Vec3(0, 50, 0), box);
  EXPECT_LT(along, 0.2 * across);
  std::mt19937 rng(7);
  EXPECT_GE(along, bruteForceParallax(capture, capture + Vec3(50, 0, 0), box, 2000, rng));
}

// A capture whose depth has a slanted wall, a step to a nearer box and sky: the grid mesh's triangles cut across the
// step (rubber sheets) and follow the wall. Brute force: points sampled on every triangle, each showing the texel its
// capture ray passes through (projective texturing), seen from random eyes: the angle between the point and what its
// texel shows (the texel's captured point) never exceeds triangleErrorBound, up to the texel's own size.
TEST(TriangleError, NeverBelowBruteForceOnAGridMesh) {
  Camera camera;
  camera.eye = Vec3(0.0f, 0.0f, 2.0f);
  camera.at = Vec3(0.0f, 100.0f, 2.0f);
  camera.width = camera.height = 64;
  camera.near_plane = 1.0f;
  camera.far_plane = 1000.0f;
  image::ColorImage color(64, 64, image::Rgba8(0, 0, 0, 0));
  image::DepthImage depth(64, 64, 0.0f);
  auto ray = [&](double px, double py) {
    const Vec3 p = camera.unproject(float(px), float(py), 0.5f);
    return glm::normalize(DVec3(p) - DVec3(camera.eye));
  };
  for (int y = 8; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      // Wall receding from 30 m (left) to 90 m (right) along the view axis; a box at 15 m in the middle.
      double along = 30.0 + 60.0 * x / 63.0;
      if (x >= 24 && x < 40 && y >= 30) along = 15.0;
      const DVec3 u = ray(x + 0.5, y + 0.5);
      const DVec3 forward = glm::normalize(DVec3(camera.at) - DVec3(camera.eye));
      const Vec3 world = Vec3(DVec3(camera.eye) + u * (along / glm::dot(u, forward)));
      depth.at(x, y) = camera.project(world).z;
      color.at(x, y) = image::Rgba8(200, 200, 200, 255);
    }
  GridMeshOptions options;
  options.grid_spacing_px = 8.0;
  const DepthMeshImpostor grid = buildGridMesh(color, depth, camera, options);
  const std::vector<TriangleError> errors = triangleErrors(grid, depth, camera);
  ASSERT_EQ(errors.size(), grid.mesh.triangleCount());
  ASSERT_GT(errors.size(), 50u);

  std::mt19937 rng(99);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<float> step(-6.0f, 6.0f);
  const double texel = 2.0 * std::tan(0.5 * double(camera.fov_y)) / 64.0;  // angle of a texel at the centre
  size_t checked = 0;
  double largest_bound = 0.0;
  for (int trial = 0; trial < 40; ++trial) {
    const Vec3 eye = camera.eye + Vec3(step(rng), step(rng) * 0.5f, step(rng) * 0.1f);
    for (size_t t = 0; t < grid.mesh.triangleCount(); ++t) {
      const double bound = triangleErrorBound(camera.eye, eye, errors[t]);
      largest_bound = std::max(largest_bound, bound);
      const Vec3 a = grid.mesh.positions[grid.mesh.indices[3 * t]];
      const Vec3 b = grid.mesh.positions[grid.mesh.indices[3 * t + 1]];
      const Vec3 c = grid.mesh.positions[grid.mesh.indices[3 * t + 2]];
      for (int k = 0; k < 12; ++k) {
        double wa = unit(rng), wb = unit(rng);
        if (wa + wb > 1.0) {
          wa = 1.0 - wa;
          wb = 1.0 - wb;
        }
        const DVec3 x = wa * DVec3(a) + wb * DVec3(b) + (1.0 - wa - wb) * DVec3(c);
        const Vec3 pixel = camera.project(Vec3(x));
        const int px = int(std::floor(pixel.x)), py = int(std::floor(pixel.y));
        if (px < 0 || py < 0 || px >= 64 || py >= 64 || depth.at(px, py) <= 0.0f) continue;  // cut by alpha
        const DVec3 shown(camera.unproject(float(px) + 0.5f, float(py) + 0.5f, depth.at(px, py)));
        const DVec3 to_x = glm::normalize(x - DVec3(eye)), to_shown = glm::normalize(shown - DVec3(eye));
        const double angle = std::acos(std::clamp(glm::dot(to_x, to_shown), -1.0, 1.0));
        // Up to the texel's own extent (the point and the texel centre are up to a texel apart from the capture
        // eye), magnified by the distance ratio.
        const double slack = 1.5 * texel * glm::length(x - DVec3(camera.eye)) / glm::length(x - DVec3(eye));
        ASSERT_LE(angle, bound + slack) << "triangle " << t << " trial " << trial;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 10000u);
  EXPECT_GT(largest_bound, 0.05);  // the rubber sheets across the step are charged
}

TEST(ValidityRegion, LocalFrameAndEnvelopeLookup) {
  ValidityRegion r;
  r.origin = Vec3(10, 0, 1.7f);
  r.end = Vec3(10, 100, 11.7f);  // along +y, climbing 10 m
  r.half_width = 4.0f;
  r.below = 0.5f;
  r.above = 0.25f;
  r.back = 2.0f;
  r.step = 10.0f;
  r.envelope = {0.0f, 0.01f, 0.02f, 0.05f};  // s <= 0, 10, 20, 30
  const Vec3 p = r.local(Vec3(7, 15, 3.2f));
  EXPECT_NEAR(p.x, 15.0f, 1e-4f);
  EXPECT_NEAR(p.y, 3.0f, 1e-4f);   // left of the axis (x decreases) is +l
  EXPECT_NEAR(p.z, 0.0f, 1e-4f);   // on the climbing eye line
  EXPECT_FLOAT_EQ(float(r.errorAt(Vec3(10, 0, 1.7f))), 0.0f);
  EXPECT_FLOAT_EQ(float(r.errorAt(Vec3(10, -1.5f, 1.7f))), 0.0f);
  EXPECT_FLOAT_EQ(float(r.errorAt(Vec3(10, 15, 3.2f))), 0.02f);  // s = 15 takes the sample at 20
  EXPECT_FLOAT_EQ(float(r.errorAt(Vec3(10, 30, 4.7f))), 0.05f);
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(r.errorAt(Vec3(10, 31, 4.8f)), inf);   // beyond the envelope
  EXPECT_EQ(r.errorAt(Vec3(10, -3, 1.7f)), inf);   // behind
  EXPECT_EQ(r.errorAt(Vec3(15, 5, 2.2f)), inf);    // too far across
  EXPECT_EQ(r.errorAt(Vec3(10, 5, 3.0f)), inf);    // too high
  EXPECT_TRUE(r.valid(Vec3(10, 15, 3.2f), 0.02));
  EXPECT_FALSE(r.valid(Vec3(10, 15, 3.2f), 0.019));
  EXPECT_DOUBLE_EQ(r.reach(0.02), 20.0);
  EXPECT_EQ(ValidityRegion{}.errorAt(Vec3(0.0f)), inf);
}

// Three lines across the street: a viewpoint between two lines gets the larger of their envelopes.
TEST(ValidityRegion, LateralLinesBracketTheViewpoint) {
  ValidityRegion r;
  r.origin = Vec3(0, 0, 2);
  r.end = Vec3(100, 0, 2);  // along +x; +l is +y
  r.half_width = 4.0f;
  r.below = r.above = 1.0f;
  r.step = 10.0f;
  r.laterals = 3;           // l = -4, 0, +4
  r.envelope = {0.0f, 0.03f, 0.09f,   // right side (l = -4)
                0.0f, 0.01f, 0.02f,   // centreline
                0.0f, 0.02f, 0.05f};  // left side (l = +4)
  ASSERT_EQ(r.samples(), 3u);
  EXPECT_FLOAT_EQ(float(r.errorAt(Vec3(15, 0, 2))), 0.02f);    // on the centreline
  EXPECT_FLOAT_EQ(float(r.errorAt(Vec3(15, 1, 2))), 0.05f);    // between centre and left
  EXPECT_FLOAT_EQ(float(r.errorAt(Vec3(15, -1, 2))), 0.09f);   // between centre and right
  EXPECT_FLOAT_EQ(float(r.errorAt(Vec3(5, -4, 2))), 0.03f);    // on the right line
  EXPECT_EQ(r.errorAt(Vec3(5, -4.5f, 2)), std::numeric_limits<double>::infinity());
  EXPECT_DOUBLE_EQ(r.reach(0.015), 10.0);
}

}  // namespace
}  // namespace farfield::impostor
