// Tiles page within the budget: over a flythrough the resident bytes never exceed it (and a budget below one tile
// is refused), tiles are loaded and evicted, and the mesh stays the whole grid's.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <span>
#include <vector>

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

// Prefetched tiles hold what acquire() would read, are taken without a read, and count against the budget from
// the request; a prefetch does not evict the tiles the last frame used.
TEST(TilePager, PrefetchedTilesAreTakenWithoutAReadWithinTheBudget) {
  const Heightfield hf = test::tiledTestFractal(3);
  const TileCache cache(test::writeTestCache(hf, "tile_pager_prefetch"));
  const size_t tile = cache.residentBytes(1, 1, 1);
  const size_t budget = tile * 6;
  TilePager pager(cache, budget);
  // The last frame used two tiles.
  pager.acquire(0, 0, 1);
  pager.acquire(3, 3, 1);
  std::vector<TileRequest> all, fits;
  size_t room = budget - cache.residentBytes(0, 0, 1) - cache.residentBytes(3, 3, 1);
  for (int ty = 0; ty < 4; ++ty)
    for (int tx = 0; tx < 4; ++tx) {
      all.push_back({tx, ty, 1});
      const bool held = (tx == 0 && ty == 0) || (tx == 3 && ty == 3);
      if (!held && cache.residentBytes(tx, ty, 1) <= room) {
        fits.push_back(all.back());
        room -= cache.residentBytes(tx, ty, 1);
      }
    }
  ASSERT_GE(fits.size(), 4u);
  ASSERT_LT(fits.size(), 14u);
  pager.prefetch(all);
  EXPECT_LE(pager.stats().resident_bytes, budget);
  EXPECT_EQ(pager.stats().prefetch_dropped, 14u - fits.size());  // the held two are not asked for again
  // Those that fitted are taken without a read of acquire()'s, and hold what it would read.
  TilePager reference(cache, size_t(1) << 30);
  for (const TileRequest& r : fits) {
    const TerrainTile& t = pager.acquire(r.tx, r.ty, r.step);
    EXPECT_TRUE(t.prefetched);
    const TerrainTile& u = reference.acquire(r.tx, r.ty, r.step);
    EXPECT_TRUE(t.grid.hf.heights == u.grid.hf.heights);
    EXPECT_TRUE(t.lod->objectErrors() == u.lod->objectErrors());
  }
  EXPECT_EQ(pager.stats().loads, 2u);  // the last frame's two
  EXPECT_EQ(pager.stats().prefetched, fits.size());
  EXPECT_EQ(pager.stats().prefetch_hits, fits.size());
  // The last frame's tiles were kept.
  pager.acquire(0, 0, 1);
  pager.acquire(3, 3, 1);
  EXPECT_EQ(pager.stats().loads, 2u);
  EXPECT_EQ(pager.stats().evictions, 0u);
  EXPECT_LE(pager.stats().peak_resident_bytes, budget);
  // A tile left out is still read on demand, evicting the least recently used.
  const TileRequest out = *std::find_if(all.begin() + 1, all.end(), [&](const TileRequest& r) {
    return !(r.tx == 3 && r.ty == 3) &&
           std::none_of(fits.begin(), fits.end(), [&](const TileRequest& f) { return f.tx == r.tx && f.ty == r.ty; });
  });
  pager.acquire(out.tx, out.ty, 1);
  EXPECT_EQ(pager.stats().loads, 3u);
  EXPECT_LE(pager.stats().peak_resident_bytes, budget);
}

// Over a flythrough with prefetch after each frame, the mesh is the one without it, within the budget.
TEST(TilePager, PrefetchAlongAFlythroughKeepsTheMeshAndTheBudget) {
  const Heightfield hf = test::tiledTestFractal(5);
  const TileCache cache(test::writeTestCache(hf, "tile_pager_prefetch_flight"));
  const size_t budget = cache.residentBytes(1, 1, 1) * 4;
  TilePager ahead(cache, budget), plain(cache, budget);
  const float ex = float(hf.extentX()), ey = float(hf.extentY()), top = hf.maxHeight();
  LodSettings settings;
  for (int f = 0; f < 30; ++f) {
    const float s = float(f) / 29.0f;
    const Vec3 eye(ex * (0.05f + 0.9f * s), ey * (0.2f + 0.6f * s), top + 80.0f);
    const Camera camera = test::tiledTestCamera(eye, eye + Vec3(ex * 0.3f, ey * 0.2f, -150.0f));
    LodMesh a, b;
    buildTiledLod(ahead, camera, settings, a);
    buildTiledLod(plain, camera, settings, b);
    ASSERT_EQ(a.indices, b.indices) << "frame " << f;
    const Camera next = test::tiledTestCamera(eye + Vec3(ex * 0.031f, ey * 0.021f, 0.0f),
                                              eye + Vec3(ex * 0.331f, ey * 0.221f, -150.0f));
    const std::vector<TileRequest> r = tilesInView(cache, next, settings);
    ahead.prefetch(r);
    ASSERT_LE(ahead.stats().resident_bytes, budget);
  }
  EXPECT_GT(ahead.stats().prefetch_hits, 0u);
  EXPECT_LT(ahead.stats().loads, plain.stats().loads);
  EXPECT_LE(ahead.stats().peak_resident_bytes, budget);
}

// A preparer's work is done on every tile loaded, on demand or ahead, and its bytes count against the budget.
TEST(TilePager, APreparersWorkAndBytesComeWithEveryTile) {
  const Heightfield hf = test::tiledTestFractal(3);
  const TileCache cache(test::writeTestCache(hf, "tile_pager_preparer"));
  const size_t extra = 1000;
  TilePager pager(cache, size_t(1) << 30);
  pager.setPreparer({[](const TerrainTile& t) {
                       auto d = std::make_unique<TileDrawData>();
                       d->width = t.grid.hf.width;
                       return d;
                     },
                     [&](int, int, int) { return extra; }});
  const TerrainTile& a = pager.acquire(1, 2, 2);
  ASSERT_TRUE(a.draw);
  EXPECT_EQ(a.draw->width, a.grid.hf.width);
  EXPECT_EQ(pager.stats().resident_bytes, cache.residentBytes(1, 2, 2) + extra);
  const TileRequest r{2, 2, 1};
  pager.prefetch(std::span(&r, 1));
  const TerrainTile& b = pager.acquire(2, 2, 1);
  EXPECT_TRUE(b.prefetched);
  ASSERT_TRUE(b.draw);
  EXPECT_EQ(b.draw->width, b.grid.hf.width);
  EXPECT_EQ(pager.stats().resident_bytes, cache.residentBytes(1, 2, 2) + cache.residentBytes(2, 2, 1) + 2 * extra);
  // Released once used: the bytes go with it.
  pager.releaseDrawData(2, 2);
  EXPECT_FALSE(pager.acquire(2, 2, 1).draw);
  EXPECT_EQ(pager.stats().resident_bytes, cache.residentBytes(1, 2, 2) + cache.residentBytes(2, 2, 1) + extra);
  // A budget that holds a tile but not what the preparer adds is refused.
  TilePager tight(cache, cache.residentBytes(1, 1, 1));
  farfield::test::expectErrorMentions(
      [&] { tight.setPreparer({[](const TerrainTile&) { return std::make_unique<TileDrawData>(); },
                               [](int, int, int) { return size_t(1); }}); },
      {"terrain.tiles", "ready to draw"});
}

// A tile the worker cannot read is reported by the acquire() that needs it, naming the file.
TEST(TilePager, ADamagedTileFoundByThePrefetchIsAnErrorOfItsAcquire) {
  const Heightfield hf = test::tiledTestFractal(3);
  const std::string path = test::writeTestCache(hf, "tile_pager_prefetch_damaged");
  const TileCache cache(path);
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(std::streamoff(cache.info(2, 1).offset + 40));
    const char junk[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    f.write(junk, sizeof junk);
  }
  TilePager pager(cache, size_t(1) << 30);
  const TileRequest r{2, 1, 1};
  pager.prefetch(std::span(&r, 1));
  farfield::test::expectErrorMentions([&] { pager.acquire(2, 1, 1); }, {path, "tile (2, 1)", "checksum"});
  EXPECT_EQ(pager.stats().resident_bytes, 0u);
}

}  // namespace
}  // namespace farfield::terrain
