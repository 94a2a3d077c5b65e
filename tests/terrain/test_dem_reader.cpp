// Rasters read by windows (DemReader): every window holds what the whole raster's load gives its points, nodata
// holes included; a tile cache written window by window is the file written from the whole grid; the cache's
// overview is the grid at its step; bad windows and damaged rasters name the file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "farfield/terrain/dem_io.h"
#include "farfield/terrain/heightfield.h"
#include "farfield/terrain/tile_cache.h"
#include "support/expect_error.h"
#include "support/test_support.h"
#include "terrain/test_raster.h"
#include "terrain/tiled_test_terrain.h"

namespace farfield::terrain {
namespace {

// A 321 x 225 north-up GeoTIFF of a smooth surface with three nodata holes: a single point, a 9 x 7 hole and a
// 200 x 150 one whose middle lies farther than kNodataFillRings steps from any data.
std::string holedRaster(const std::string& name, int& w, int& h) {
  w = 321;
  h = 225;
  const double nodata = -9999.0;
  std::vector<double> v(size_t(w) * size_t(h));
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c)
      v[size_t(r) * size_t(w) + size_t(c)] = 500.0 + 80.0 * std::sin(c * 0.05) * std::cos(r * 0.07) + 0.3 * c;
  v[size_t(10) * size_t(w) + 300] = nodata;
  for (int r = 200; r < 207; ++r)
    for (int c = 20; c < 29; ++c) v[size_t(r) * size_t(w) + size_t(c)] = nodata;
  for (int r = 40; r < 190; ++r)
    for (int c = 60; c < 260; ++c) v[size_t(r) * size_t(w) + size_t(c)] = nodata;
  const double gt[6] = {400000.0, 30.0, 0.0, 3800000.0, 0.0, -30.0};
  const std::string path = (farfield::test::scratchDir(name) / "holed.tif").string();
  test::writeRaster(path, "GTiff", GDT_Float32, w, h, v, &nodata, gt);
  return path;
}

TEST(DemReader, WindowsHoldWhatTheWholeRasterGivesTheirPoints) {
  int w = 0, h = 0;
  const std::string path = holedRaster("dem_reader_windows", w, h);
  const Heightfield whole = loadDem(path);
  ASSERT_EQ(whole.width, w);
  ASSERT_EQ(whole.height, h);
  EXPECT_EQ(whole.nodata_count, 1u + 63u + 30000u);
  // The big hole's middle is beyond the fill's reach: the lowest valid height there, the same everywhere.
  const float lowest = [&] {
    float m = 1e30f;
    for (size_t k = 0; k < whole.size(); ++k)
      if (!whole.nodata[k]) m = std::min(m, whole.heights[k]);
    return m;
  }();
  EXPECT_EQ(whole.at(160, h - 1 - 115), lowest);
  const DemReader reader(path);
  EXPECT_EQ(reader.nodataCount(), whole.nodata_count);
  EXPECT_EQ(reader.header().cell_x, 30.0);
  // Windows inside the big hole, across its rim, over the small holes, at the raster's edges, the whole raster.
  const int windows[][4] = {{100, 80, 40, 40}, {40, 20, 90, 70}, {10, 15, 30, 20}, {290, 205, 31, 20},
                            {0, 0, 321, 225}, {250, 0, 71, 64}, {0, 150, 64, 75}};
  for (const auto& win : windows) {
    const Heightfield part = reader.read(win[0], win[1], win[2], win[3]);
    const Heightfield expected = whole.crop(win[0], win[1], win[2], win[3]);
    ASSERT_EQ(part.width, expected.width);
    size_t differ = 0;
    for (size_t k = 0; k < part.size(); ++k) differ += part.heights[k] != expected.heights[k] ? 1 : 0;
    EXPECT_EQ(differ, 0u) << "window at (" << win[0] << ", " << win[1] << ")";
    EXPECT_EQ(part.nodata_count, expected.nodata_count);
    EXPECT_EQ(part.geo_origin, expected.geo_origin);
  }
}

TEST(DemReader, WindowsOutsideTheRasterNameTheFile) {
  int w = 0, h = 0;
  const std::string path = holedRaster("dem_reader_bad_window", w, h);
  const DemReader reader(path);
  farfield::test::expectErrorMentions([&] { reader.read(300, 0, 30, 10); }, {path, "outside", "321x225"});
  farfield::test::expectErrorMentions([&] { reader.read(0, -1, 10, 10); }, {path, "outside"});
  DemLoadOptions small;
  small.max_grid_points = 1000;
  const DemReader capped(path, small);
  farfield::test::expectErrorMentions([&] { capped.read(0, 0, 40, 40); }, {path, "window of 40x40"});
  EXPECT_NO_THROW(capped.read(0, 0, 20, 20));
}

TEST(DemReader, ARasterWithoutDataIsAnErrorForAnyWindow) {
  const double nodata = -1.0;
  const double gt[6] = {0.0, 10.0, 0.0, 0.0, 0.0, -10.0};
  const std::string path = (farfield::test::scratchDir("dem_reader_empty") / "empty.tif").string();
  test::writeRaster(path, "GTiff", GDT_Float32, 20, 20, std::vector<double>(400, nodata), &nodata, gt);
  const DemReader reader(path);
  farfield::test::expectErrorMentions([&] { reader.read(2, 2, 5, 5); }, {path, "every grid point is nodata"});
}

std::vector<char> fileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(DemReader, ATileCacheWrittenWindowByWindowIsTheOneWrittenFromTheWholeGrid) {
  int w = 0, h = 0;
  const std::string path = holedRaster("dem_reader_cache", w, h);
  const auto dir = std::filesystem::path(path).parent_path();
  const std::string from_whole = (dir / "whole.tiles").string(), from_windows = (dir / "windows.tiles").string();
  TileCache::write(cropForBlocks(loadDem(path), 64), 64, 2, from_whole);
  TileCache::write(DemReader(path), 64, 2, from_windows);
  const std::vector<char> a = fileBytes(from_whole), b = fileBytes(from_windows);
  EXPECT_GT(a.size(), 100000u);
  EXPECT_TRUE(a == b) << a.size() << " against " << b.size() << " bytes";
  const TileCache cache(from_windows);
  EXPECT_EQ(cache.layout().width, 321);   // 5 blocks of 64, and one point
  EXPECT_EQ(cache.layout().height, 193);  // 3 blocks of 64: cropped from 225, centred
}

TEST(DemReader, AWrittenDemReadsBackTheSameHeightsAndPlace) {
  Heightfield hf = test::tiledTestFractal(3);
  hf.geo_origin = DVec2(412345.0, 3765432.0);
  const std::string path = (farfield::test::scratchDir("dem_write") / "fractal.tif").string();
  writeDem(hf, path);
  const Heightfield back = loadDem(path);
  ASSERT_EQ(back.width, hf.width);
  ASSERT_EQ(back.height, hf.height);
  EXPECT_TRUE(back.heights == hf.heights);
  EXPECT_EQ(back.cell_x, hf.cell_x);
  EXPECT_EQ(back.cell_y, hf.cell_y);
  EXPECT_NEAR(back.geo_origin.x, hf.geo_origin.x, 1e-6);
  EXPECT_NEAR(back.geo_origin.y, hf.geo_origin.y, 1e-6);
  EXPECT_EQ(back.nodata_count, 0u);
  farfield::test::expectErrorMentions([&] { writeDem(hf, "/nonexistent-dir/x.tif"); }, {"/nonexistent-dir/x.tif"});
}

TEST(TileCache, TheOverviewIsTheGridAtItsStep) {
  const Heightfield hf = test::tiledTestFractal();
  const TileCache cache(test::writeTestCache(hf, "tile_cache_overview"));
  for (int step : {1, 2, 8}) {
    const Heightfield o = cache.overview(step);
    ASSERT_EQ(o.width, (hf.width - 1) / step + 1);
    ASSERT_EQ(o.height, (hf.height - 1) / step + 1);
    EXPECT_EQ(o.cell_x, hf.cell_x * step);
    size_t differ = 0;
    for (int j = 0; j < o.height; ++j)
      for (int i = 0; i < o.width; ++i) differ += o.at(i, j) != hf.at(i * step, j * step) ? 1 : 0;
    EXPECT_EQ(differ, 0u) << "step " << step;
  }
  farfield::test::expectErrorMentions([&] { cache.overview(3); }, {cache.path(), "step 3"});
  farfield::test::expectErrorMentions([&] { cache.overview(16); }, {cache.path(), "step 16"});
}

}  // namespace
}  // namespace farfield::terrain
