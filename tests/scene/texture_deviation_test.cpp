#include "farfield/scene/texture_deviation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "farfield/scene/deforming_lod.h"
#include "farfield/scene/gltf_skin.h"
#include "farfield/scene/skin.h"
#include "support/test_support.h"

namespace farfield::scene {
namespace {

// An n x n grid of unit squares, two triangles each; vertices row-major, uvs (x, y) / n.
struct Grid {
  int n;
  std::vector<uint32_t> indices;
  std::vector<Vec2> uvs;
  uint32_t at(int x, int y) const { return uint32_t(y * (n + 1) + x); }
  explicit Grid(int size) : n(size) {
    for (int y = 0; y <= n; ++y)
      for (int x = 0; x <= n; ++x) uvs.push_back(Vec2(float(x), float(y)) / float(n));
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        indices.insert(indices.end(),
                       {at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y), at(x + 1, y + 1), at(x, y + 1)});
  }
  // The grid with vertex `from` merged into `into` (a half-edge collapse): its triangles that held both dropped.
  std::vector<uint32_t> merged(uint32_t from, uint32_t into) const {
    std::vector<uint32_t> out;
    for (size_t t = 0; t < indices.size(); t += 3) {
      uint32_t c[3] = {indices[t], indices[t + 1], indices[t + 2]};
      for (uint32_t& i : c)
        if (i == from) i = into;
      if (c[0] != c[1] && c[1] != c[2] && c[0] != c[2]) out.insert(out.end(), {c[0], c[1], c[2]});
    }
    return out;
  }
  // Positions: (x, y, height(x, y)).
  template <class Height>
  std::vector<Vec3> pose(Height height) const {
    std::vector<Vec3> p;
    for (int y = 0; y <= n; ++y)
      for (int x = 0; x <= n; ++x) p.push_back(Vec3(float(x), float(y), height(x, y)));
    return p;
  }
};

bool holds(const Vec3& w) { return w.x >= -1e-5f && w.y >= -1e-5f && w.z >= -1e-5f; }

// textureDeviation by brute force: every full triangle tried for every sample (no grid), nearest in uv where none
// holds it.
double bruteDeviation(std::span<const uint32_t> full, std::span<const uint32_t> level,
                      std::span<const std::vector<Vec3>> poses, std::span<const Vec2> uvs, int n) {
  double worst = 0.0;
  for (size_t t = 0; t + 2 < level.size(); t += 3)
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const Vec3 b(float(i) / float(n), float(j) / float(n), float(n - i - j) / float(n));
        const Vec2 uv = uvs[level[t]] * b.x + uvs[level[t + 1]] * b.y + uvs[level[t + 2]] * b.z;
        auto deviation = [&](size_t f, const Vec3& w) {
          double far = 0.0;
          for (const std::vector<Vec3>& p : poses) {
            const Vec3 shown = p[level[t]] * b.x + p[level[t + 1]] * b.y + p[level[t + 2]] * b.z;
            const Vec3 home = p[full[f]] * w.x + p[full[f + 1]] * w.y + p[full[f + 2]] * w.z;
            far = std::max(far, double(glm::length(shown - home)));
          }
          return far;
        };
        double nearest = std::numeric_limits<double>::infinity();
        float nearest_uv = std::numeric_limits<float>::infinity();
        size_t nearest_f = 0;
        Vec3 nearest_w(0.0f);
        for (size_t f = 0; f + 2 < full.size(); f += 3) {
          const Vec2 &a = uvs[full[f]], &c = uvs[full[f + 1]], &d = uvs[full[f + 2]];
          const Vec3 w = barycentric2(uv, a, c, d);
          if (!std::isfinite(w.x)) continue;  // no uv area
          if (holds(w)) {
            nearest = std::min(nearest, deviation(f, w));
            continue;
          }
          const Vec3 at = nearestBarycentric2(uv, a, c, d);  // (not `n`: the samples' steps)
          const float duv = glm::length(a * at.x + c * at.y + d * at.z - uv);
          if (duv < nearest_uv) {
            nearest_uv = duv;
            nearest_f = f;
            nearest_w = at;
          }
        }
        if (!std::isfinite(nearest) && std::isfinite(nearest_uv)) nearest = deviation(nearest_f, nearest_w);
        if (std::isfinite(nearest)) worst = std::max(worst, nearest);
      }
  return worst;
}

TEST(TextureDeviation, BarycentricCoordinatesRebuildThePointAndTheNearestPointIsInTheTriangle) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 2.0f);
  for (int k = 0; k < 200; ++k) {
    const Vec2 a(u(rng), u(rng)), b(u(rng), u(rng)), c(u(rng), u(rng)), p(u(rng), u(rng));
    const Vec3 w = barycentric2(p, a, b, c);
    EXPECT_NEAR(w.x + w.y + w.z, 1.0f, 1e-4f);
    const Vec2 back = a * w.x + b * w.y + c * w.z;
    EXPECT_NEAR(glm::length(back - p), 0.0f, 1e-3f * (1.0f + glm::length(p)));
    const Vec3 n = nearestBarycentric2(p, a, b, c);
    EXPECT_TRUE(holds(n));
    const Vec2 q = a * n.x + b * n.y + c * n.z;
    if (holds(w)) {
      EXPECT_NEAR(glm::length(q - p), 0.0f, 1e-3f);
    }
    // No point of the triangle (sampled) is nearer p than q.
    for (int s = 0; s <= 10; ++s)
      for (int t = 0; s + t <= 10; ++t) {
        const Vec2 x = a * (float(s) / 10.0f) + b * (float(t) / 10.0f) + c * (float(10 - s - t) / 10.0f);
        EXPECT_LE(glm::length(q - p), glm::length(x - p) + 1e-4f);
      }
  }
  EXPECT_TRUE(std::isnan(barycentric2(Vec2(0.5f), Vec2(0.0f), Vec2(1.0f), Vec2(2.0f)).x));  // no area
}

TEST(TextureDeviation, TheLocatorFindsEveryTriangleThatHoldsATexelAndTheNearestOutsideTheCharts) {
  // A jittered grid, its uvs jittered too (still a chart without fold-overs), and a sliver of no uv area.
  Grid g(6);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> jitter(-0.03f, 0.03f);
  for (int y = 1; y < g.n; ++y)
    for (int x = 1; x < g.n; ++x) g.uvs[g.at(x, y)] += Vec2(jitter(rng), jitter(rng));
  const UvLocator locator(g.indices, g.uvs);
  std::uniform_real_distribution<float> u(-0.3f, 1.3f);
  std::vector<UvLocator::Hit> hits;
  for (int k = 0; k < 2000; ++k) {
    const Vec2 uv(u(rng), u(rng));
    locator.locate(uv, hits);
    std::vector<uint32_t> brute;
    float nearest = std::numeric_limits<float>::infinity();
    for (uint32_t t = 0; t * 3 < g.indices.size(); ++t) {
      const Vec2 &a = g.uvs[g.indices[3 * t]], &b = g.uvs[g.indices[3 * t + 1]], &c = g.uvs[g.indices[3 * t + 2]];
      if (holds(barycentric2(uv, a, b, c))) brute.push_back(t);
      const Vec3 n = nearestBarycentric2(uv, a, b, c);
      nearest = std::min(nearest, glm::length(a * n.x + b * n.y + c * n.z - uv));
    }
    if (!brute.empty()) {
      std::vector<uint32_t> found;
      for (const UvLocator::Hit& h : hits) found.push_back(h.triangle);
      std::sort(found.begin(), found.end());
      EXPECT_EQ(found, brute) << uv.x << " " << uv.y;
    } else {
      ASSERT_EQ(hits.size(), 1u);
      const uint32_t t = hits[0].triangle;
      const Vec3 w = hits[0].barycentric;
      const Vec2 q = g.uvs[g.indices[3 * t]] * w.x + g.uvs[g.indices[3 * t + 1]] * w.y + g.uvs[g.indices[3 * t + 2]] * w.z;
      EXPECT_NEAR(glm::length(q - uv), nearest, 1e-5f);
    }
  }
}

// Uvs at the ends of the float range (a defect of real data that validation lets through: they are finite) make the
// charts' span overflow; the locator still finds the triangles that hold a texel of the ordinary chart.
TEST(TextureDeviation, TheLocatorCopesWithUvsAtTheEndsOfTheFloatRange) {
  Grid g(3);
  const float big = 3.0e38f;
  const uint32_t first = uint32_t(g.uvs.size());
  g.uvs.insert(g.uvs.end(), {Vec2(-big, -big), Vec2(big, -big), Vec2(-big, big)});
  g.indices.insert(g.indices.end(), {first, first + 1, first + 2});
  const UvLocator locator(g.indices, g.uvs);
  std::vector<UvLocator::Hit> hits;
  for (const Vec2 uv : {Vec2(0.1f, 0.2f), Vec2(0.5f, 0.5f), Vec2(0.9f, 0.7f)}) {
    locator.locate(uv, hits);
    bool in_grid = false;
    for (const UvLocator::Hit& h : hits) {
      const uint32_t t = h.triangle;
      const Vec2 q = g.uvs[g.indices[3 * t]] * h.barycentric.x + g.uvs[g.indices[3 * t + 1]] * h.barycentric.y +
                     g.uvs[g.indices[3 * t + 2]] * h.barycentric.z;
      if (t < uint32_t(g.n * g.n * 2)) {
        in_grid = true;
        EXPECT_NEAR(glm::length(q - uv), 0.0f, 1e-5f) << uv.x << " " << uv.y;
      }
    }
    EXPECT_TRUE(in_grid) << uv.x << " " << uv.y << ": the grid's triangle holding it";
  }
}

TEST(TextureDeviation, AMergeMovesTheTextureOnlyWhereTheSurfaceIsNotLinearInItsUvs) {
  const Grid g(4);
  const uint32_t centre = g.at(2, 2), right = g.at(3, 2);
  const std::vector<uint32_t> level = g.merged(centre, right);
  ASSERT_EQ(level.size(), g.indices.size() - 6);
  // Flat, positions linear in the uvs: the merged fan shows each texel where the grid does.
  const std::vector<std::vector<Vec3>> flat = {g.pose([](int, int) { return 0.0f; })};
  EXPECT_LT(textureDeviation(g.indices, g.indices, flat, g.uvs), 1e-5);
  EXPECT_LT(textureDeviation(g.indices, level, flat, g.uvs), 1e-5);
  // The merged vertex raised by h in a second pose: the flat fan shows the raised texels at height 0. Sampled at
  // quarter steps, the sample of the level nearest the removed vertex's texel is within half a cell of it, where the
  // full surface is at least h / 2 high; no texel moves further than the bump's height plus a cell.
  const float h = 0.8f;
  const std::vector<std::vector<Vec3>> bumped = {
      flat[0], g.pose([&](int x, int y) { return x == 2 && y == 2 ? h : 0.0f; })};
  const double d = textureDeviation(g.indices, level, bumped, g.uvs);
  EXPECT_GE(d, 0.5 * h);
  EXPECT_LE(d, std::hypot(double(h), 1.0));
  EXPECT_NEAR(d, bruteDeviation(g.indices, level, bumped, g.uvs, 4), 1e-5);
  // The full mesh against itself: nothing moves in any pose.
  EXPECT_LT(textureDeviation(g.indices, g.indices, bumped, g.uvs), 1e-5);
}

TEST(TextureDeviation, ARealModelsLevelsMoveTheirTexelsAsTheBruteForceFinds) {
  FF_SHARED_FILE_OR_SKIP(man_glb, "models/CesiumMan.glb");
  const SkinnedModel man = importSkinnedModel(man_glb.string());
  const int a = man.findAnimation("walk");
  const Animation& anim = man.animations[size_t(std::max(a, 0))];
  std::vector<std::vector<Vec3>> poses;
  for (int p = 0; p < 4; ++p)
    poses.push_back(skinMesh(man, jointMatrices(man, &anim, anim.start + anim.duration * float(p) / 4.0f)).positions);
  DeformingLodOptions options;
  options.triangle_ratios = {0.25};
  const std::vector<DeformingLevel> levels =
      deformingLevels(man.mesh.indices, poses, options, man.name, {}, man.mesh.uvs);
  ASSERT_EQ(levels.size(), 1u);
  EXPECT_GT(levels[0].texture_error, 0.0);
  EXPECT_NEAR(levels[0].texture_error,
              bruteDeviation(man.mesh.indices, levels[0].indices, poses, man.mesh.uvs, 4), 1e-5);
  // Without uvs, no texture to move.
  EXPECT_EQ(deformingLevels(man.mesh.indices, poses, options, man.name)[0].texture_error, 0.0);
}

}  // namespace
}  // namespace farfield::scene
