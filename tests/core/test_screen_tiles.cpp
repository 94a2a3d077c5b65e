// tileCover against a brute-force pixel mask: every pixel of every region covered, once; every tile touching a region.
#include "farfield/core/screen_tiles.h"

#include <gtest/gtest.h>

#include <random>

#include "farfield/core/error.h"

namespace farfield {
namespace {

TEST(ScreenTiles, CoverHoldsEveryRegionPixelOnceAndOnlyTilesNearRegions) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 40; ++trial) {
    const int w = 37 + int(rng() % 300), h = 23 + int(rng() % 300), tile = 1 + int(rng() % 24);
    std::vector<glm::ivec4> regions;
    const int n = int(rng() % 12);
    for (int i = 0; i < n; ++i) {
      const int x0 = int(rng() % unsigned(w + 40)) - 20, y0 = int(rng() % unsigned(h + 40)) - 20;
      regions.emplace_back(x0, y0, x0 + int(rng() % 90) - 5, y0 + int(rng() % 90) - 5);  // some empty or outside
    }
    const std::vector<glm::ivec4> cover = tileCover(regions, w, h, tile);
    std::vector<int> inside(size_t(w) * size_t(h), 0), count(size_t(w) * size_t(h), 0);
    for (const glm::ivec4& r : regions)
      for (int y = std::max(r.y, 0); y < std::min(r.w, h); ++y)
        for (int x = std::max(r.x, 0); x < std::min(r.z, w); ++x) inside[size_t(y) * size_t(w) + size_t(x)] = 1;
    for (const glm::ivec4& c : cover) {
      ASSERT_TRUE(c.x >= 0 && c.y >= 0 && c.z <= w && c.w <= h && c.x < c.z && c.y < c.w);
      EXPECT_EQ(c.x % tile, 0);
      EXPECT_EQ(c.y % tile, 0);
      for (int y = c.y; y < c.w; ++y)
        for (int x = c.x; x < c.z; ++x) ++count[size_t(y) * size_t(w) + size_t(x)];
      // Each tile of the rectangle holds some region pixel.
      for (int ty = c.y; ty < c.w; ty += tile)
        for (int tx = c.x; tx < c.z; tx += tile) {
          bool any = false;
          for (int y = ty; y < std::min(ty + tile, h) && !any; ++y)
            for (int x = tx; x < std::min(tx + tile, w) && !any; ++x)
              any = inside[size_t(y) * size_t(w) + size_t(x)] != 0;
          EXPECT_TRUE(any) << "tile at " << tx << "," << ty << " touches no region";
        }
    }
    for (size_t i = 0; i < inside.size(); ++i) {
      EXPECT_LE(count[i], 1) << "pixel " << i << " covered twice";
      if (inside[i]) {
        EXPECT_EQ(count[i], 1) << "region pixel " << i << " not covered";
      }
    }
  }
  EXPECT_TRUE(tileCover({}, 10, 10, 4).empty());
  EXPECT_THROW(tileCover({}, 0, 10, 4), Error);
  EXPECT_THROW(tileCover({}, 10, 10, 0), Error);
}

}  // namespace
}  // namespace farfield
