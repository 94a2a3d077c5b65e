// The Figure-8-style flythrough: starts away and high, zooms in, stays above the ground, passes the plain and the
// mountains the heightfield has (checked against heights sampled independently); and the texture's layout
// and rock share.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "farfield/core/error.h"
#include "farfield/terrain/flythrough.h"
#include "farfield/terrain/fractal.h"
#include "farfield/terrain/terrain_texture.h"

namespace farfield::terrain {
namespace {

// Plain on the west half (low, flat), a mountain range on the east half.
Heightfield plainAndMountains() {
  Heightfield hf(129, 97, 50.0);
  hf.source = "plain and mountains";
  for (int j = 0; j < hf.height; ++j)
    for (int i = 0; i < hf.width; ++i) {
      const double x = double(i) / (hf.width - 1);
      const double ridge = std::exp(-std::pow((x - 0.72) / 0.08, 2.0));
      hf.at(i, j) = float(100.0 + 1200.0 * ridge * (0.8 + 0.2 * std::sin(j * 0.3)));
    }
  return hf;
}

TEST(Flythrough, StartsAwayZoomsInAndCrossesPlainThenMountains) {
  const Heightfield hf = plainAndMountains();
  FlythroughOptions o;
  o.frames = 300;
  FlythroughLandmarks marks;
  const std::vector<Viewpoint> path = flythroughPath(hf, o, &marks);
  ASSERT_EQ(path.size(), 300u);
  const float ex = float(hf.extentX()), ey = float(hf.extentY());
  // Landmarks: the mountains on the ridge, the plains lower and flatter.
  EXPECT_NEAR(marks.mountains.x, 0.72f * ex, 0.1f * ex);
  EXPECT_LT(hf.sample(marks.plain.x, marks.plain.y), hf.sample(marks.mountains.x, marks.mountains.y) - 300.0f);
  EXPECT_LT(hf.sample(marks.beyond.x, marks.beyond.y), hf.sample(marks.mountains.x, marks.mountains.y) - 300.0f);
  // Starts outside the map and high above it; the distance to the map shrinks (zooms in).
  auto outside = [&](const Vec3& p) { return p.x < 0 || p.y < 0 || p.x > ex || p.y > ey; };
  EXPECT_TRUE(outside(path.front().eye));
  EXPECT_GT(path.front().eye.z, hf.maxHeight() + 1000.0f);
  EXPECT_FALSE(outside(path[path.size() / 2].eye));
  // Above the ground everywhere (sampled independently, bilinear) and over the mountains late in the path.
  for (const Viewpoint& v : path)
    if (!outside(v.eye)) {
      EXPECT_GT(v.eye.z, hf.sample(v.eye.x, v.eye.y) + 50.0f);
    }
  // The closest passes: the plain first, then the mountains, then the plain beyond; each passed within a few km.
  auto closest = [&](Vec2 mark, float* distance) {
    size_t best = 0;
    *distance = 1e30f;
    for (size_t f = 0; f < path.size(); ++f) {
      const float d = glm::length(Vec2(path[f].eye) - mark);
      if (d < *distance) *distance = d, best = f;
    }
    return best;
  };
  float dp = 0, dm = 0, db = 0;
  const size_t fp = closest(marks.plain, &dp), fm = closest(marks.mountains, &dm), fb = closest(marks.beyond, &db);
  EXPECT_LT(fp, fm);
  EXPECT_LT(fm, fb);
  EXPECT_LT(std::max({dp, dm, db}), 0.1f * ex);
  // Looking ahead and down (never up).
  for (const Viewpoint& v : path) EXPECT_LT(v.at.z, v.eye.z);
  EXPECT_THROW(flythroughPath(hf, FlythroughOptions{1}), Error);
  EXPECT_THROW(flythroughPath(hf, FlythroughOptions{kMaxFlythroughFrames + 1}), Error);
}

TEST(Flythrough, BackAndForthRepeatsTheSpanBothWays) {
  std::vector<Viewpoint> path(10);
  for (size_t i = 0; i < path.size(); ++i) path[i].eye = Vec3(float(i), 0, 0);
  const auto bf = backAndForth(path, 2, 4, 2);
  ASSERT_EQ(bf.size(), 16u);
  const float want[] = {2, 3, 4, 5, 5, 4, 3, 2, 2, 3, 4, 5, 5, 4, 3, 2};
  for (size_t i = 0; i < bf.size(); ++i) EXPECT_EQ(bf[i].eye.x, want[i]);
  EXPECT_THROW(backAndForth(path, 8, 4, 1), Error);
}

TEST(TerrainTexture, GridPointsMapToTexelCentres) {
  Heightfield hf(9, 5, 30.0);
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 9; ++i) hf.at(i, j) = float(10 * j);
  for (int scale : {1, 2}) {
    TextureOptions o;
    o.scale = scale;
    const image::ColorImage tex = terrainTexture(hf, o);
    ASSERT_EQ(tex.width(), 9 * scale);
    ASSERT_EQ(tex.height(), 5 * scale);
    // Grid point (3, 2) at world (90, 60): texel centre ((3 + 0.5) * s, (2 + 0.5) * s) / size.
    const Vec2 uv = texCoord(hf, Vec2(90.0f, 60.0f));
    EXPECT_NEAR(uv.x * tex.width(), 3.5f * scale, 1e-4f);
    EXPECT_NEAR(uv.y * tex.height(), 2.5f * scale, 1e-4f);
  }
  // Elevation drives the colour: the lowest row differs from the highest.
  const image::ColorImage tex = terrainTexture(hf);
  EXPECT_NE(tex.at(4, 0), tex.at(4, 4));
}

// Scale 1 reads grid points directly; the texels are those of the bilinear lookups, edges included.
TEST(TerrainTexture, TheDirectPathGivesTheBilinearLookupsTexels) {
  FractalOptions f;
  f.size = 65;
  f.seed = 12;
  f.cell_size = 25.0;
  f.relief = 900.0;
  Heightfield hf = fractalTerrain(f);
  hf = hf.crop(0, 0, 65, 40);  // not square
  TextureOptions slow;
  slow.bilinear_lookups = true;
  const image::ColorImage a = terrainTexture(hf), b = terrainTexture(hf, slow);
  size_t differ = 0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) differ += a.at(x, y) != b.at(x, y) ? 1 : 0;
  EXPECT_EQ(differ, 0u);
}


// The rock share skips the arccosine outside its band; every share is still the arccosine's, at and around the band's
// edges (where the shortcut would first go wrong) and over every normal.
TEST(TerrainTexture, TheRockShareIsTheArccosinesAtEveryNormal) {
  for (const float deg : {35.0f, 20.0f, 50.0f}) {
    const float rock = float(degToRad(deg));
    const RockShare share(rock);
    auto reference = [&](float nz) {
      return std::clamp((std::acos(std::clamp(nz, -1.0f, 1.0f)) - rock * 0.7f) / (rock * 0.6f), 0.0f, 1.0f);
    };
    size_t checked = 0, inside = 0;
    auto check = [&](float nz) {
      const float want = reference(nz);
      ASSERT_EQ(share(nz), want) << "normal z " << nz << ", rock slope " << deg << " degrees";
      ++checked;
      inside += want > 0.0f && want < 1.0f ? 1 : 0;
    };
    for (int k = 0; k <= 200000; ++k) check(-1.0f + 2.0f * float(k) / 200000.0f);
    // Every float within 2,000 ulps of each band edge.
    for (const float edge : {std::cos(rock * 0.7f), std::cos(rock * 1.3f)}) {
      float nz = edge;
      for (int k = 0; k < 2000; ++k) nz = std::nextafter(nz, -2.0f);
      for (int k = 0; k < 4000; ++k, nz = std::nextafter(nz, 2.0f)) check(nz);
    }
    EXPECT_GT(inside, 1000u);  // the band itself was sampled
    EXPECT_GT(checked, 200000u);
  }
  // A rock slope out of range is refused, not shaded by a band that means nothing.
  Heightfield hf(4, 4, 10.0);
  for (const float deg : {0.0f, -5.0f, 95.0f}) {
    TextureOptions o;
    o.rock_slope_deg = deg;
    EXPECT_THROW(terrainTexture(hf, o), Error) << deg;
  }
}
}  // namespace
}  // namespace farfield::terrain
