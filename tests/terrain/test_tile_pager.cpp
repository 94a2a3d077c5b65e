// Tiles page within the budget: over a flythrough the resident bytes never exceed it (and a budget below one tile
// is refused), tiles are loaded and evicted, and the mesh stays the whole grid's.
#include <gtest/gtest.h>

#include <algorithm>

#include "farfield/terrain/quadtree_lod.h"
#include "farfield/terrain/tile_pager.h"
#include "farfield/terrain/tiled_lod.h"
#include "support/expect_error.h"
#include "terrain/tiled_test_terrain.h"

namespace farfield::terrain {
namespace {

TEST(TilePager, ResidentBytesStayWithinTheBudgetOverAFlythrough) {
  const Heightfield hf = test::tiledTestFractal(3);
  const QuadtreeLod whole(hf, 16);
  const TileCache cache(test::writeTestCache(hf, "tile_pager_budget"));
  size_t largest = 0, all = 0;
  for (int ty = 0; ty < 4; ++ty)
    for (int tx = 0; tx < 4; ++tx) {
      largest = std::max(largest, cache.residentBytes(tx, ty, 1));
      all += cache.residentBytes(tx, ty, 1);
    }
  const size_t budget = largest * 5 / 2;  // two and a half full-resolution tiles of sixteen
  TilePager pager(cache, budget);
  const float ex = float(hf.extentX()), ey = float(hf.extentY()), top = hf.maxHeight();
  LodSettings settings;
  size_t max_resident = 0;
  for (int f = 0; f < 40; ++f) {
    const float s = float(f) / 39.0f;
    const Vec3 eye(ex * (0.05f + 0.9f * s), ey * (0.1f + 0.8f * s * s), top + 60.0f);
    const Camera camera = test::tiledTestCamera(eye, eye + Vec3(ex * 0.3f, ey * 0.25f, -150.0f));
    LodMesh tiled;
    buildTiledLod(pager, camera, settings, tiled);
    const TilePagerStats& st = pager.stats();
    max_resident = std::max(max_resident, st.resident_bytes);
    ASSERT_LE(st.resident_bytes, budget) << "frame " << f;
    ASSERT_LE(st.peak_resident_bytes, budget) << "frame " << f;
    if (f % 13 == 0) {  // paging does not change the mesh (without culling, test_tiled_lod.cpp has the rest)
      LodSettings all = settings;
      all.cull = false;
      LodMesh uncut;
      buildTiledLod(pager, camera, all, uncut);
      EXPECT_EQ(uncut.indices.size(), whole.build(camera, all).indices.size());
      ASSERT_LE(pager.stats().resident_bytes, budget);
    }
  }
  const TilePagerStats& st = pager.stats();
  EXPECT_LT(budget, all);  // the budget could not hold the terrain at full resolution
  EXPECT_GT(st.loads, 16u);
  EXPECT_GT(st.evictions, 0u);
  EXPECT_GT(st.hits, 0u);
  EXPECT_GT(max_resident, budget / 2);
  EXPECT_EQ(st.loads, st.hits == st.requests ? 0u : st.loads);
  EXPECT_LE(st.loads + st.hits, st.requests);
}

TEST(TilePager, ABudgetBelowOneTileIsRefused) {
  const Heightfield hf = test::tiledTestFractal(3);
  const TileCache cache(test::writeTestCache(hf, "tile_pager_small"));
  farfield::test::expectErrorMentions([&] { TilePager pager(cache, cache.residentBytes(1, 1, 1) - 1); },
                                      {"terrain.tiles", "budget", "cannot hold one tile"});
}

TEST(TilePager, AFinerStepReplacesACoarserTile) {
  const Heightfield hf = test::tiledTestFractal(3);
  const TileCache cache(test::writeTestCache(hf, "tile_pager_step"));
  TilePager pager(cache, size_t(1) << 30);
  EXPECT_EQ(pager.acquire(1, 1, 4).grid.step, 4);
  EXPECT_EQ(pager.acquire(1, 1, 8).grid.step, 4);  // a finer tile serves a coarser request
  EXPECT_EQ(pager.stats().hits, 1u);
  EXPECT_EQ(pager.acquire(1, 1, 1).grid.step, 1);
  EXPECT_EQ(pager.stats().loads, 2u);
  EXPECT_EQ(pager.stats().resident_tiles, 1u);
  EXPECT_EQ(pager.stats().resident_bytes, cache.residentBytes(1, 1, 1));
}

}  // namespace
}  // namespace farfield::terrain
