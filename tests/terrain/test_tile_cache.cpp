// Tile cache: tiles read back hold the grid's heights and the whole grid's LOD errors; coarse steps subsample them;
// stepFor only coarsens where no finer vertex can be active; damaged files give errors naming the file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "farfield/terrain/quadtree_lod.h"
#include "farfield/terrain/tile_cache.h"
#include "support/expect_error.h"
#include "terrain/tiled_test_terrain.h"

namespace farfield::terrain {
namespace {

TEST(TileCache, TilesHoldTheGridsHeightsAndErrors) {
  const Heightfield hf = test::tiledTestFractal();
  const QuadtreeLod whole(hf, 16);
  const TileCache cache(test::writeTestCache(hf, "tile_cache_read"));
  EXPECT_EQ(cache.layout().tilesX(), 4);
  EXPECT_EQ(cache.layout().tilesY(), 4);
  for (int step : {1, 4}) {
    const TileGrid g = cache.read(2, 1, step);
    EXPECT_EQ(g.origin, IVec2(2 * 64 - 16, 64 - 16));
    for (int j = 0; j < g.hf.height; ++j)
      for (int i = 0; i < g.hf.width; ++i) {
        const size_t v = hf.index(g.origin.x + i * step, g.origin.y + j * step);
        ASSERT_EQ(g.hf.at(i, j), hf.heights[v]);
        // Inside the tile (not its apron) the errors are the whole grid's exactly.
        const int x = i * step - 16, y = j * step - 16;
        if (x >= 0 && y >= 0 && x <= 64 && y <= 64) {
          ASSERT_EQ(g.error[g.hf.index(i, j)], whole.objectError(uint32_t(v)));
          ASSERT_EQ(g.radius[g.hf.index(i, j)], whole.radius(uint32_t(v)));
        }
      }
  }
}

TEST(TileCache, StepForKeepsEveryActiveVertex) {
  const Heightfield hf = test::tiledTestFractal();
  const QuadtreeLod whole(hf, 16);
  const TileCache cache(test::writeTestCache(hf, "tile_cache_step"));
  int coarse = 0;
  for (const Camera& camera : test::tiledTestCameras(hf))
    for (int ty = 0; ty < 4; ++ty)
      for (int tx = 0; tx < 4; ++tx) {
        const double lambda = QuadtreeLod::pixelsPerRadian(camera);
        const int step = cache.stepFor(tx, ty, camera.eye, lambda, 1.0f);
        if (step == 1) continue;
        ++coarse;
        // Brute force: no active vertex of the tile lies off the step's grid, nor any of their children.
        for (int y = ty * 64; y <= ty * 64 + 64; ++y)
          for (int x = tx * 64; x <= tx * 64 + 64; ++x) {
            if (x % (2 * step) == 0 && y % (2 * step) == 0) continue;  // on a grid coarse enough for the children
            ASSERT_FALSE(whole.active(uint32_t(hf.index(x, y)), camera.eye, lambda, 1.0f))
                << "tile " << tx << "," << ty << " step " << step << " vertex " << x << "," << y;
          }
      }
  EXPECT_GT(coarse, 10);
}

TEST(TileCache, DamagedFilesNameTheFile) {
  const Heightfield hf = test::tiledTestFractal();
  const std::string path = test::writeTestCache(hf, "tile_cache_damaged");
  const auto size = std::filesystem::file_size(path);
  const std::string cut = path + ".cut";
  for (uintmax_t keep : {uintmax_t(0), uintmax_t(5), uintmax_t(40), uintmax_t(100), size / 2, size - 1}) {
    std::filesystem::copy_file(path, cut, std::filesystem::copy_options::overwrite_existing);
    std::filesystem::resize_file(cut, keep);
    farfield::test::expectErrorMentions([&] { TileCache c(cut); }, {cut});
  }
  std::filesystem::copy_file(path, cut, std::filesystem::copy_options::overwrite_existing);
  {
    std::fstream f(cut, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(12);
    const int32_t bad = 100;
    f.write(reinterpret_cast<const char*>(&bad), 4);
  }
  farfield::test::expectErrorMentions([&] { TileCache c(cut); }, {cut, "inconsistent"});
  farfield::test::expectErrorMentions([&] { TileCache c(path + ".missing"); }, {".missing", "cannot open"});

  // A flipped byte in a tile's data: the index still reads, the tile does not (at full resolution; a coarse step
  // that skips the row does not see it).
  std::filesystem::copy_file(path, cut, std::filesystem::copy_options::overwrite_existing);
  const TileCache good(path);
  {
    std::fstream f(cut, std::ios::in | std::ios::out | std::ios::binary);
    const auto at = std::streamoff(good.info(2, 1).offset + 97 * 4 + 3);  // row 1 of the heights
    f.seekg(at);
    char c = 0;
    f.read(&c, 1);
    c = char(c ^ 0x10);
    f.seekp(at);
    f.write(&c, 1);
  }
  const TileCache damaged(cut);
  EXPECT_NO_THROW(damaged.read(1, 1, 1));
  EXPECT_NO_THROW(damaged.read(2, 1, 2));
  farfield::test::expectErrorMentions([&] { damaged.read(2, 1, 1); }, {cut, "tile (2, 1)", "row 1", "heights", "checksum"});
}

}  // namespace
}  // namespace farfield::terrain
