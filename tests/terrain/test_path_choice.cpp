// The per-frame choice between the high LOD and the LOD-sprite path (terrain/path_choice.h), no GL: on constructed
// cost profiles the chosen path is the cheaper one, by brute-force summing the frame costs of both paths over the
// sprite's lifetime; and the expected lifetime is the median of recent lifetimes.
#include "farfield/terrain/path_choice.h"

#include <gtest/gtest.h>

#include <random>

#include "farfield/terrain/terrain_cost.h"

namespace farfield::terrain {
namespace {

// Total time of the next `life` frames on each path, frame by frame: the sprite path's first frame renders the
// keyframe (and draws itself from it), the others draw the sprite; the high path draws the high LOD every frame.
double spritePathTotal(const PathCosts& c, int life) {
  double t = 0.0;
  for (int f = 0; f < life; ++f) t += f == 0 ? c.keyframe_ms : c.sprite_ms;
  return t;
}
double highPathTotal(const PathCosts& c, int life) {
  double t = 0.0;
  for (int f = 0; f < life; ++f) t += c.high_ms;
  return t;
}

// Costs of a frame from a constructed machine profile, as LodSpriteRenderer predicts them (lod_sprite.cpp).
PathCosts costsOf(const TerrainCost& cost, double high_tris, double low_tris, int w, int h, int kw, int kh) {
  PathCosts p;
  p.high_ms = cost.frameMs(high_tris, 1, w, h);
  p.sprite_ms = cost.frameMs(low_tris, 2, w, h);
  p.keyframe_ms = cost.frameMs(high_tris * kw * kh / (double(w) * h), 1, kw, kh) + cost.readbackMs(kw, kh) +
                  p.sprite_ms;
  return p;
}

TEST(PathChoice, PicksTheCheaperPathOnRandomProfiles) {
  std::mt19937 rng(18);
  std::uniform_real_distribution<double> base(0.5, 20.0), per_mtri(1.0, 400.0), per_draw(0.0, 2.0),
      per_mpix(0.0, 20.0), readback(0.0, 40.0), high_tris(1e3, 5e6), low_tris(200.0, 5e3);
  std::uniform_int_distribution<int> lifetime(1, 80);
  int sprite_chosen = 0, high_chosen = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    TerrainCost cost;
    cost.frame.base_ms = base(rng);
    cost.frame.ms_per_mtriangle = per_mtri(rng);
    cost.frame.ms_per_draw = per_draw(rng);
    cost.frame.ms_per_mpixel = per_mpix(rng);
    cost.readback_ms_per_mpixel = readback(rng);
    const PathCosts c = costsOf(cost, high_tris(rng), low_tris(rng), 512, 512, 614, 614);
    const int life = lifetime(rng);
    const TerrainPath chosen = choosePath(c, false, double(life));
    const double sprite = spritePathTotal(c, life), high = highPathTotal(c, life);
    if (chosen == TerrainPath::Sprite) {
      ++sprite_chosen;
      EXPECT_LT(sprite, high) << "trial " << trial;
    } else {
      ++high_chosen;
      EXPECT_LE(high, sprite * (1.0 + 1e-12)) << "trial " << trial;
    }
    // A valid sprite: one frame each.
    const TerrainPath kept = choosePath(c, true, 0.0);
    EXPECT_EQ(kept == TerrainPath::Sprite, c.sprite_ms < c.high_ms) << "trial " << trial;
  }
  // Both answers occur: the test exercises the decision, not one constant.
  EXPECT_GT(sprite_chosen, 300);
  EXPECT_GT(high_chosen, 300);
}

// The two situations of docs/BENCHMARKS.md. A small DEM on llvmpipe: a frame costs about 5 ms whatever it draws, the
// 1 px LOD is 19k triangles: a keyframe (larger target, z-buffer read back, then the frame) never pays for itself
// over a 5-frame sprite life. A large DEM: the 1 px LOD has millions of triangles: the sprite wins at once.
TEST(PathChoice, SmallTerrainDrawsHighLargeTerrainTakesTheSprite) {
  TerrainCost llvmpipe;
  llvmpipe.frame.base_ms = 5.0;
  llvmpipe.frame.ms_per_mtriangle = 50.0;
  llvmpipe.frame.ms_per_mpixel = 4.0;
  llvmpipe.frame.ms_per_draw = 0.2;
  llvmpipe.readback_ms_per_mpixel = 8.0;
  const PathCosts small = costsOf(llvmpipe, 19'000, 1'500, 512, 512, 614, 614);
  EXPECT_EQ(choosePath(small, false, 5.0), TerrainPath::High);
  EXPECT_GT(spritePathTotal(small, 5), highPathTotal(small, 5));
  const PathCosts large = costsOf(llvmpipe, 3'000'000, 1'500, 512, 512, 614, 614);
  EXPECT_EQ(choosePath(large, false, 5.0), TerrainPath::Sprite);
  EXPECT_EQ(choosePath(large, true, 0.0), TerrainPath::Sprite);
  // One frame of life never pays for a keyframe.
  EXPECT_EQ(choosePath(large, false, 1.0), TerrainPath::High);
  // A valid sprite that costs more to draw than the high LOD (two draw calls against one, same triangles).
  TerrainCost draws;
  draws.frame.base_ms = 1.0;
  draws.frame.ms_per_draw = 3.0;
  const PathCosts c = costsOf(draws, 1'000, 1'000, 512, 512, 614, 614);
  EXPECT_EQ(choosePath(c, true, 0.0), TerrainPath::High);
}

TEST(PathChoice, LifetimeIsTheMedianOfRecentLifetimes) {
  EXPECT_EQ(spriteLifetimeEstimate({}, 1.0), 1.0);
  EXPECT_EQ(spriteLifetimeEstimate({7}, 1.0), 7.0);
  EXPECT_EQ(spriteLifetimeEstimate({9, 2, 40}, 1.0), 9.0);
  EXPECT_EQ(spriteLifetimeEstimate({4, 10, 2, 6}, 1.0), 5.0);
}

}  // namespace
}  // namespace farfield::terrain
