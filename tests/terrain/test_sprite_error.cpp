// The LOD-sprite error metric (Chen et al. 1999, equations 1-2) against independent computations: a hand-worked
// case and a numerical one (marching along the ray v1 -> C over the quadrant's fan surface).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "farfield/core/camera.h"
#include "farfield/terrain/cdlod.h"
#include "farfield/terrain/cdlod_sprite_error.h"
#include "farfield/terrain/fractal.h"
#include "farfield/terrain/sprite_error.h"

namespace farfield::terrain {
namespace {

TEST(SpriteError, FlatQuadrantByHand) {
  // Corners at z = 0 around (0, 0); true centre C 10 m above. v1 straight above: the ray v1 -> C is vertical, so
  // C' = (0, 0, 0). From v2 = (100, 0, 0): theta = angle between (-100, 0, 10) and (-100, 0, 0) = atan(10 / 100).
  const std::array<DVec3, 4> q = {DVec3(-5, -5, 0), DVec3(5, -5, 0), DVec3(5, 5, 0), DVec3(-5, 5, 0)};
  const DVec3 c(0, 0, 10), v1(0, 0, 500), v2(100, 0, 0);
  DVec3 cp;
  ASSERT_TRUE(spriteProjection(c, q, v1, cp));
  EXPECT_NEAR(cp.x, 0.0, 1e-9);
  EXPECT_NEAR(cp.z, 0.0, 1e-9);
  EXPECT_NEAR(quadrantTheta(c, q, v1, v2), std::atan(0.1), 1e-12);
  // From v1 itself the error is zero (the sprite is exact from where it was taken).
  EXPECT_NEAR(quadrantTheta(c, q, v1, v1), 0.0, 1e-9);
  // Oblique v1 = (-100, 0, 100): the ray through C = (0, 0, 10) descends 0.9 m per metre and meets z = 0 at x = 10 / 0.9.
  const DVec3 v1b(-100, 0, 100);
  ASSERT_TRUE(spriteProjection(c, q, v1b, cp));
  EXPECT_NEAR(cp.x, 10.0 / 0.9, 1e-9);
  EXPECT_NEAR(cp.z, 0.0, 1e-9);
  // A grazing ray (1 mm of descent over a kilometre) meets the plane z = 0 10 km past C: with `near`, C' is kept
  // where the ray leaves the quadrant's box grown by its size on each side, x = 15.
  const DVec3 v1c(-1000, 0, 10.001);
  ASSERT_TRUE(spriteProjection(c, q, v1c, cp));
  EXPECT_GT(cp.x, 1e6);
  ASSERT_TRUE(spriteProjection(c, q, v1c, cp, true));
  EXPECT_NEAR(cp.x, 15.0, 1e-6);
  EXPECT_NEAR(cp.z, 10.001 - 1.015 * 0.001, 1e-6);
}

// Independent: the fan surface height over (x, y) (4 triangles around the mean of the corners), the first crossing
// of the ray v1 -> C with it by fine marching and bisection, theta from acos of the normalised dot product.
double fanHeight(const std::array<DVec3, 4>& q, const DVec3& centre, double x, double y, bool& inside) {
  for (int k = 0; k < 4; ++k) {
    const DVec3 a = centre, b = q[size_t(k)], c = q[size_t((k + 1) % 4)];
    const double det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    const double l1 = ((x - a.x) * (c.y - a.y) - (c.x - a.x) * (y - a.y)) / det;
    const double l2 = ((b.x - a.x) * (y - a.y) - (x - a.x) * (b.y - a.y)) / det;
    if (l1 >= -1e-12 && l2 >= -1e-12 && l1 + l2 <= 1 + 1e-12) {
      inside = true;
      return a.z + l1 * (b.z - a.z) + l2 * (c.z - a.z);
    }
  }
  inside = false;
  return 0.0;
}

bool marchedProjection(const std::array<DVec3, 4>& q, const DVec3& c, const DVec3& v1, DVec3& out) {
  DVec3 centre(0.0);
  for (const auto& p : q) centre += p / 4.0;
  auto f = [&](double t, bool& inside) {
    const DVec3 p = v1 + t * (c - v1);
    return p.z - fanHeight(q, centre, p.x, p.y, inside);
  };
  const int steps = 200000;
  double prev_t = 0.0, prev_f = 0.0;
  bool have_prev = false;
  for (int s = 0; s <= steps; ++s) {
    const double t = 3.0 * s / steps;
    bool inside = false;
    const double v = f(t, inside);
    if (!inside) {
      have_prev = false;
      continue;
    }
    if (have_prev && ((prev_f > 0) != (v > 0))) {
      double lo = prev_t, hi = t;
      for (int it = 0; it < 100; ++it) {
        const double mid = 0.5 * (lo + hi);
        bool in = false;
        ((f(mid, in) > 0) == (prev_f > 0) ? lo : hi) = mid;
      }
      out = v1 + 0.5 * (lo + hi) * (c - v1);
      return true;
    }
    prev_t = t, prev_f = v, have_prev = true;
  }
  return false;
}

TEST(SpriteError, ThetaMatchesIndependentComputationOnRandomQuadrants) {
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int compared = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const double half = 20.0 + 10.0 * (u(rng) + 1.0);
    std::array<DVec3, 4> q = {DVec3(-half, -half, 30 * u(rng)), DVec3(half, -half, 30 * u(rng)),
                              DVec3(half, half, 30 * u(rng)), DVec3(-half, half, 30 * u(rng))};
    const DVec3 c(0.0, 0.0, 40.0 * u(rng));
    // Keyframe and novel viewpoints well above, 200-600 m away.
    const DVec3 v1(300 * u(rng), 300 * u(rng), 250 + 200 * (u(rng) + 1));
    const DVec3 v2 = v1 + DVec3(60 * u(rng), 60 * u(rng), 30 * u(rng));
    DVec3 expected;
    if (!marchedProjection(q, c, v1, expected)) continue;  // grazing rays: the fallback is not what this checks
    DVec3 got;
    ASSERT_TRUE(spriteProjection(c, q, v1, got));
    EXPECT_NEAR(glm::length(got - expected), 0.0, 1e-4) << "trial " << trial;
    const DVec3 a = glm::normalize(c - v2), b = glm::normalize(expected - v2);
    const double theta = std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
    EXPECT_NEAR(quadrantTheta(c, q, v1, v2), theta, 1e-6) << "trial " << trial;
    ++compared;
  }
  EXPECT_GT(compared, 150);
}

// spriteTheta's series for small angles against atan2 of the same sine and cosine, from a micro-radian to past the
// series' range (1/16) and to obtuse angles: equal to a few units in the last place of a double (a term left out of
// the series, or a wrong coefficient, shows as 1e-13 or more at the range's end).
TEST(SpriteError, ThetaEqualsAtan2FromMicroradiansToObtuseAngles) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  size_t compared = 0;
  for (double angle = 1e-6; angle < 3.0; angle *= 1.07) {
    for (int trial = 0; trial < 4; ++trial) {
      const DVec3 v2(unit(rng) * 500.0, unit(rng) * 500.0, 300.0 + unit(rng) * 100.0);
      const DVec3 dir = glm::normalize(DVec3(unit(rng), unit(rng), unit(rng) - 2.0));
      DVec3 side = glm::normalize(glm::cross(dir, DVec3(0.3, 1.0, 0.2)));
      const double da = 200.0 + 800.0 * (unit(rng) + 1.0), db = 200.0 + 800.0 * (unit(rng) + 1.0);
      const DVec3 c = v2 + da * dir;
      const DVec3 c_prime = v2 + db * (std::cos(angle) * dir + std::sin(angle) * side);
      const DVec3 a = c - v2, b = c_prime - v2;
      const double expected = std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
      EXPECT_NEAR(spriteTheta(c, c_prime, v2), expected, 4e-16 * expected + 1e-300) << "angle " << angle;
      EXPECT_NEAR(spriteTheta(c, c_prime, v2), angle, 1e-9 * angle + 1e-12) << "angle " << angle;
      ++compared;
    }
  }
  EXPECT_GT(compared, 800u);
}

TEST(SpriteError, KeyframeDueWhenMeanSquareReachesThreshold) {
  Camera camera;
  camera.width = 512;
  camera.height = 512;
  camera.fov_y = float(degToRad(60.0));
  const double beta = pixelAngle(camera);
  EXPECT_NEAR(beta, degToRad(60.0) / 512.0, 1e-6);  // square image: horizontal fov = vertical fov
  SpriteError e;
  e.quadrants = 10;
  e.mean_theta_sq = 0.99 * beta * beta;
  EXPECT_FALSE(keyframeDue(e, beta, 1.0));
  e.mean_theta_sq = 1.0 * beta * beta;
  EXPECT_TRUE(keyframeDue(e, beta, 1.0));
  EXPECT_FALSE(keyframeDue(e, beta, 2.0));
  EXPECT_NEAR(e.pixels(beta), 1.0, 1e-12);
  e.quadrants = 0;
  EXPECT_FALSE(keyframeDue(e, beta, 1.0));
}

// A fractal of size^2 points, 20 m cells, for the CDLOD metric's tests.
Heightfield cdlodTestFractal(int size, uint64_t seed, double relief) {
  FractalOptions fo;
  fo.size = size;
  fo.seed = seed;
  fo.cell_size = 20.0;
  fo.relief = relief;
  return fractalTerrain(fo);
}

// A size x size camera with a 60 degree field of view.
Camera metricCamera(Vec3 eye, Vec3 at, int size) {
  Camera camera;
  camera.eye = eye;
  camera.at = at;
  camera.width = camera.height = size;
  camera.fov_y = float(degToRad(60.0));
  camera.near_plane = 1.0f;
  camera.far_plane = 50000.0f;
  return camera;
}

// The CDLOD metric tests' view: high over the grid's corner, looking across it, and its 4 px selection.
Camera acrossTheGrid(const Heightfield& hf) {
  return metricCamera(Vec3(200.0f, 300.0f, hf.maxHeight() + 300.0f), Vec3(3000.0f, 3500.0f, 0.0f), 512);
}
CdlodSelection lowSelection(const CdlodTerrain& lod, const Camera& camera) {
  CdlodSelection selection;
  lod.select(camera, 4.0f, true, selection);
  return selection;
}

// Equation 2 over a CDLOD mesh (the GPU sprite frame's, lod_sprite.h's gpu_low): every cell of the selection's nodes
// of level >= 1 inside the grid is a quadrant (counted independently here), and the evenly spread sample stands for
// the mean over every cell.
TEST(SpriteError, CdlodSampleStandsForEveryCell) {
  const Heightfield hf = cdlodTestFractal(257, 5, 600.0);
  const CdlodTerrain lod(hf, CdlodOptions{16, 16, 0.2f});
  const Camera camera = acrossTheGrid(hf);
  const CdlodSelection selection = lowSelection(lod, camera);
  const int p = lod.patchCells();
  size_t cells = 0;
  for (const CdlodNode& n : selection.nodes) {
    if (n.level < 1) continue;
    const int s = 1 << n.level;
    for (int j = 0; j < p; ++j)
      for (int i = 0; i < p; ++i)
        if ((n.x * p + i + 1) * s <= hf.width - 1 && (n.y * p + j + 1) * s <= hf.height - 1) ++cells;
  }
  ASSERT_GT(cells, 2000u) << "the test needs a mesh larger than the sample";
  double previous = 0.0;
  for (const float move : {10.0f, 40.0f, 160.0f}) {
    const Vec3 v2 = camera.eye + Vec3(move, 0.5f * move, -0.2f * move);
    const SpriteError all = spriteError(lod, selection.nodes, camera.eye, v2, 0);
    EXPECT_EQ(all.quadrants + all.skipped, cells);
    const SpriteError sample = spriteError(lod, selection.nodes, camera.eye, v2, 512);
    EXPECT_GT(sample.quadrants, 300u);
    EXPECT_LT(sample.quadrants + sample.skipped, 512u + selection.nodes.size());
    const double ratio = std::sqrt(sample.mean_theta_sq / all.mean_theta_sq);
    std::printf("move %.0f m: %zu cells, error %.3f px (every cell) / %.3f px (%zu sampled), ratio %.3f\n", move,
                cells, all.pixels(pixelAngle(camera)), sample.pixels(pixelAngle(camera)), sample.quadrants, ratio);
    EXPECT_NEAR(ratio, 1.0, 0.2);
    // The same sample from frame to frame, and a larger move shows a larger error.
    EXPECT_EQ(spriteError(lod, selection.nodes, camera.eye, v2, 512).mean_theta_sq, sample.mean_theta_sq);
    EXPECT_GT(all.mean_theta_sq, previous);
    previous = all.mean_theta_sq;
  }
  EXPECT_LT(spriteError(lod, selection.nodes, camera.eye, camera.eye, 512).mean_theta_sq, 1e-20);
}

// The sprite's magnification (SpriteError::mean_magnification): over every cell, the mean of |C - v1| / |C - v2| with
// C each cell's central grid point, counted independently here; a view that moved halfway towards the ground sees
// the sprite magnified, one that moved away minified, and the same viewpoint not at all; the keyframe is due past
// the bound.
TEST(SpriteError, MagnificationIsTheMeanDistanceRatioOverTheCells) {
  const Heightfield hf = cdlodTestFractal(129, 3, 300.0);
  const CdlodTerrain lod(hf, CdlodOptions{8, 16, 0.2f});
  const Camera camera =
      metricCamera(Vec3(1280.0f, -600.0f, hf.maxHeight() + 400.0f), Vec3(1280.0f, 1280.0f, 0.0f), 256);
  CdlodSelection selection;
  lod.select(camera, 4.0f, true, selection);
  const Vec3 centre(1280.0f, 1280.0f, hf.sample(1280.0, 1280.0));
  const int p = lod.patchCells();
  for (const float toward : {0.5f, -0.5f, 0.0f}) {
    const Vec3 v2 = camera.eye + (centre - camera.eye) * (0.5f * toward);
    double sum = 0.0;
    size_t cells = 0;
    for (const CdlodNode& n : selection.nodes) {
      if (n.level < 1) continue;
      const int s = 1 << n.level;
      for (int j = 0; j < p; ++j)
        for (int i = 0; i < p; ++i) {
          const int cx = (n.x * p + i) * s, cy = (n.y * p + j) * s;
          if (cx + s > hf.width - 1 || cy + s > hf.height - 1) continue;
          const DVec3 c(hf.position(cx + s / 2, cy + s / 2));
          sum += glm::length(c - DVec3(camera.eye)) / glm::length(c - DVec3(v2));
          ++cells;
        }
    }
    const SpriteError e = spriteError(lod, selection.nodes, camera.eye, v2, 0);
    ASSERT_EQ(e.skipped, 0u);
    ASSERT_GT(cells, 100u);
    ASSERT_EQ(e.quadrants, cells);
    EXPECT_NEAR(e.mean_magnification, sum / double(cells), 1e-9) << "moved " << toward;
    if (toward > 0.0f) {
      EXPECT_GT(e.mean_magnification, 1.1);
    } else if (toward < 0.0f) {
      EXPECT_LT(e.mean_magnification, 0.95);
    } else {
      EXPECT_DOUBLE_EQ(e.mean_magnification, 1.0);
    }
    const double beta = pixelAngle(camera);
    EXPECT_EQ(keyframeDue(e, beta, 1e9, std::max(1.0001, e.mean_magnification * 0.99)), toward > 0.0f);
    EXPECT_FALSE(keyframeDue(e, beta, 1e9, e.mean_magnification + 0.01));
    EXPECT_FALSE(keyframeDue(e, beta, 1e9, 0.0));  // no bound on the magnification
  }
}


void expectSameError(const SpriteError& a, const SpriteError& b, const std::string& where) {
  EXPECT_EQ(a.mean_theta_sq, b.mean_theta_sq) << where;
  EXPECT_EQ(a.mean_magnification, b.mean_magnification) << where;
  EXPECT_EQ(a.max_theta, b.max_theta) << where;
  EXPECT_EQ(a.quadrants, b.quadrants) << where;
  EXPECT_EQ(a.skipped, b.skipped) << where;
}

// The sample kept from measure to measure (cdlod_sprite_error.h) along a flight: every measure equals a fresh
// spriteError over the same nodes and viewpoints, bit for bit, while most nodes' points and projections came from the
// measures before (so that a kept sample that went stale, or a key that mixed nodes up, shows as a difference).
TEST(CdlodSpriteError, AKeptSampleEqualsAFreshOneAlongAFlight) {
  const Heightfield hf = cdlodTestFractal(257, 5, 600.0);
  const CdlodTerrain lod(hf, CdlodOptions{16, 16, 0.2f});
  CdlodSpriteError kept;
  CdlodSelection selection;
  Vec3 anchor(0.0f);
  for (int f = 0; f < 40; ++f) {
    const float t = float(f);
    const Vec3 eye(200.0f + 30.0f * t, 300.0f + 12.0f * t, hf.maxHeight() + 300.0f - 4.0f * t);
    const Camera camera = metricCamera(eye, Vec3(3000.0f + 20.0f * t, 3500.0f - 15.0f * t, 0.0f), 512);
    lod.select(camera, 4.0f, true, selection);
    if (f % 10 == 0) anchor = camera.eye;  // a keyframe
    const std::string where = "frame " + std::to_string(f);
    expectSameError(kept.measure(lod, heightfieldHeights(hf), 0, selection.nodes, anchor, camera.eye, 512),
                    spriteError(lod, selection.nodes, anchor, camera.eye, 512), where);
    if (f % 7 == 3) {  // another keyframe's error in the same frame (a keyframe rendered ahead, a cached one)
      const Vec3 other = camera.eye + Vec3(-150.0f, 80.0f, 40.0f);
      expectSameError(kept.measure(lod, heightfieldHeights(hf), 0, selection.nodes, other, camera.eye, 512),
                      spriteError(lod, selection.nodes, other, camera.eye, 512), where + ", another keyframe");
    }
  }
  const CdlodSpriteError::Counters& c = kept.counters();
  std::printf("%zu measures: cells kept %zu, gathered %zu; projections kept %zu; %zu nodes held\n", c.measures,
              c.cells_kept, c.cells_gathered, c.projections_kept, kept.heldNodes());
  EXPECT_GT(c.cells_kept, 2 * c.cells_gathered);
  EXPECT_GT(c.projections_kept, c.cells_gathered);
  EXPECT_LT(kept.heldNodes(), (CdlodSpriteError::kKeepMeasures + 1) * selection.nodes.size());
  const Vec3 v2 = anchor + Vec3(60.0f, 30.0f, -10.0f), other = anchor + Vec3(-150.0f, 80.0f, 40.0f);
  // Three keyframes in a random order, the view moving: still every measure a fresh one's.
  std::mt19937 rng(11);
  const Vec3 eyes[3] = {anchor, other, anchor + Vec3(90.0f, -60.0f, 20.0f)};
  for (int m = 0; m < 30; ++m) {
    const Vec3& v1 = eyes[rng() % 3];
    const Vec3 moved = v2 + Vec3(5.0f * float(m), -3.0f * float(m), 0.0f);
    expectSameError(kept.measure(lod, heightfieldHeights(hf), 0, selection.nodes, v1, moved, 512),
                    spriteError(lod, selection.nodes, v1, moved, 512), "measure " + std::to_string(m));
  }
}

// The kept sample's tests' scene: a fractal, its CDLOD tree, the view across it with its 4 px selection, and a
// keyframe's viewpoint v1 near the eye.
struct KeptSampleScene {
  explicit KeptSampleScene(uint64_t seed)
      : hf(cdlodTestFractal(257, seed, 600.0)),
        lod(hf, CdlodOptions{16, 16, 0.2f}),
        camera(acrossTheGrid(hf)),
        selection(lowSelection(lod, camera)),
        v1(camera.eye + Vec3(-100.0f, 40.0f, 30.0f)) {}
  KeptSampleScene(const KeptSampleScene&) = delete;  // lod refers to hf
  KeptSampleScene& operator=(const KeptSampleScene&) = delete;
  const Heightfield hf;
  const CdlodTerrain lod;
  const Camera camera;
  const CdlodSelection selection;
  const Vec3 v1;
};

// A height the terrain only stood in for (a paged terrain's overview, its page not held) is kept while the terrain's
// heights version stays, and asked for again once it changed (a page came): the measure then equals a fresh one over
// the grid's own heights; the heights that were the grid's own are never asked for again.
TEST(CdlodSpriteError, HeightsThatStoodInAreAskedForAgainWhenPagesCame) {
  const KeptSampleScene s(6);
  size_t asked = 0;
  auto heights = [&](bool east_held) {
    return [&s, &asked, east_held](std::span<const IVec2> points, std::span<float> out, std::span<uint8_t> own) {
      asked += points.size();
      for (size_t k = 0; k < points.size(); ++k) {
        const int i = std::clamp(points[k].x, 0, s.hf.width - 1), j = std::clamp(points[k].y, 0, s.hf.height - 1);
        const bool held = east_held || i < s.hf.width / 2;
        out[k] = s.hf.at(i, j) + (held ? 0.0f : 80.0f);  // a coarse stand-in, off by 80 m
        own[k] = held ? 1 : 0;
      }
    };
  };
  CdlodSpriteError kept;
  const SpriteError stood_in = kept.measure(s.lod, heights(false), 1, s.selection.nodes, s.v1, s.camera.eye, 512);
  const size_t first = asked;
  asked = 0;
  expectSameError(kept.measure(s.lod, heights(false), 1, s.selection.nodes, s.v1, s.camera.eye, 512), stood_in,
                  "the same version");
  EXPECT_EQ(asked, 0u) << "the stand-ins are kept while the version stays";
  const SpriteError own = kept.measure(s.lod, heights(true), 2, s.selection.nodes, s.v1, s.camera.eye, 512);
  expectSameError(own, spriteError(s.lod, s.selection.nodes, s.v1, s.camera.eye, 512), "after the pages came");
  EXPECT_NE(stood_in.mean_theta_sq, own.mean_theta_sq);
  EXPECT_GT(asked, 0u);
  EXPECT_LT(asked, first);
  asked = 0;
  kept.measure(s.lod, heights(true), 3, s.selection.nodes, s.v1, s.camera.eye, 512);
  EXPECT_EQ(asked, 0u) << "every height is the grid's own now";
}

// A node's sample is every k-th of its cells with k a power of two, so that the samples of one node nest: where the
// nodes' shares halve (here: half the sample), every sampled cell is one held already and no height is asked for;
// where they double, at most about half of the sampled cells are new. Each measure still equals a fresh one.
TEST(CdlodSpriteError, ANodesSamplesNestAsItsShareChanges) {
  const KeptSampleScene s(5);
  size_t asked = 0;
  const GridHeightsFn heights = [&](std::span<const IVec2> points, std::span<float> out, std::span<uint8_t> own) {
    asked += points.size();
    heightfieldHeights(s.hf)(points, out, own);
  };
  CdlodSpriteError kept;
  auto measure = [&](size_t sample, const std::string& where) {
    asked = 0;
    const SpriteError e = kept.measure(s.lod, heights, 0, s.selection.nodes, s.v1, s.camera.eye, sample);
    expectSameError(e, spriteError(s.lod, s.selection.nodes, s.v1, s.camera.eye, sample), where);
    return e;
  };
  const SpriteError first = measure(1024, "a sample of 1,024");
  ASSERT_GT(asked, 0u);
  const SpriteError half = measure(512, "half the sample");
  EXPECT_EQ(asked, 0u) << "every cell of the half sample was in the whole one";
  EXPECT_LT(half.quadrants, first.quadrants);
  measure(256, "a quarter");
  EXPECT_EQ(asked, 0u);
  const SpriteError twice = measure(2048, "twice the first sample");
  EXPECT_GT(twice.quadrants, first.quadrants + first.quadrants / 2);
  EXPECT_GT(asked, 0u);
  EXPECT_LE(asked / 5, (twice.quadrants + twice.skipped) * 6 / 10) << "at most about half of its cells are new";
}

}  // namespace
}  // namespace farfield::terrain
