// The tiled-terrain experiment end to end on a small fractal: the paged LOD matches the whole grid's on the checked
// frames, the pager stays within its budget, the per-tile sprite comparison runs, the files are written, and bad
// options are refused.
#include "farfield/eval/terrain_tiles.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "support/expect_error.h"
#include "support/test_support.h"

namespace farfield::eval {
namespace {

TerrainTilesOptions smallRun(const std::string& name) {
  TerrainTilesOptions o;
  o.dem = "fractal:257:4:relief=600";
  o.out_dir = test::scratchDir(name).string();
  o.block = 16;
  o.tile_blocks = 4;
  o.budget_mb = 0.25;
  o.frames = 30;
  o.width = o.height = 128;
  o.check_stride = 5;
  o.sprite_tile_cells = 64;
  return o;
}

TEST(TerrainTiles, PagedLodMatchesTheWholeGridWithinTheBudget) {
  const TerrainTilesOptions o = smallRun("terrain_tiles_run");
  const TerrainTilesResult r = runTerrainTiles(o);
  EXPECT_EQ(r.check_mismatches, 0u);
  const std::filesystem::path out(o.out_dir);
  for (const char* f : {"tiles.json", "tiles.md", "tiles_frames.csv", "terrain.tiles"})
    EXPECT_TRUE(std::filesystem::exists(out / f)) << f;
  std::ifstream in(out / "tiles.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_LE(j["peak_resident_bytes"].get<size_t>(), j["budget_bytes"].get<size_t>());
  EXPECT_GT(j["all_tiles_full_resolution_bytes"].get<size_t>(), j["budget_bytes"].get<size_t>());
  EXPECT_GT(j["evictions"].get<size_t>(), 0u);
  EXPECT_EQ(j["checked_frames"].get<size_t>(), 6u);
  EXPECT_GT(j["whole_keyframes"].get<size_t>(), 0u);
  EXPECT_GT(j["tile_sprite_refreshes"].get<size_t>(), 0u);
  EXPECT_NE(r.markdown.find("sprites per tile"), std::string::npos);
}

TEST(TerrainTiles, BadOptionsAreRefused) {
  TerrainTilesOptions o = smallRun("terrain_tiles_bad");
  o.frames = 1;
  test::expectErrorMentions([&] { runTerrainTiles(o); }, {"--frames"});
  o = smallRun("terrain_tiles_bad");
  o.budget_mb = 0.001;
  test::expectErrorMentions([&] { runTerrainTiles(o); }, {"terrain.tiles", "budget"});
  o = smallRun("terrain_tiles_bad");
  o.dem = "fractal:300";
  test::expectErrorMentions([&] { runTerrainTiles(o); }, {"fractal"});
}

}  // namespace
}  // namespace farfield::eval
