// The tiled-terrain experiment end to end on a small fractal: the paged LOD matches the whole grid's on the checked
// frames, the pager stays within its budget, the per-tile sprite comparison runs, the files are written, and bad
// options are refused.
#include "farfield/eval/terrain_tiles.h"

#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "farfield/terrain/fractal.h"
#include "farfield/terrain/terrain_data.h"
#include "support/expect_error.h"
#include "support/test_support.h"
#include "terrain/test_raster.h"

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

// A DEM file is read into the cache tile by tile and the flythrough planned on the cache's overview: per frame the
// same LOD as the run that holds the whole grid (the check forces that), and drawn from GPU patches in budget.
TEST(TerrainTilesGL, ADemFileIsStreamedAndDrawnFromPagedPatches) {
  const terrain::Heightfield hf = terrain::fractalTerrain(terrain::parseFractalSpec("fractal:257:4:relief=600"));
  std::vector<double> values(hf.size());
  for (int r = 0; r < hf.height; ++r)  // raster row 0 north
    for (int c = 0; c < hf.width; ++c) values[size_t(r) * size_t(hf.width) + size_t(c)] = hf.at(c, hf.height - 1 - r);
  const double gt[6] = {500000.0, hf.cell_x, 0.0, 4000000.0, 0.0, -hf.cell_y};
  const std::string dem = (test::scratchDir("terrain_tiles_dem") / "dem.tif").string();
  terrain::test::writeRaster(dem, "GTiff", GDT_Float32, hf.width, hf.height, values, nullptr, gt);

  TerrainTilesOptions o = smallRun("terrain_tiles_streamed");
  o.dem = dem;
  o.check_stride = 0;
  o.sprite_tile_cells = 0;
  o.render = true;
  o.gpu_lod = false;  // the quadtree LOD per tile (--cpu-lod)
  o.budget_mb = 0.5;  // tiles come with their positions and texture until drawn
  o.gpu_budget_mb = 1.0;
  o.sample_stride = 10;
  runTerrainTiles(o);
  TerrainTilesOptions w = smallRun("terrain_tiles_whole");
  w.dem = dem;
  w.sprite_tile_cells = 0;
  runTerrainTiles(w);

  auto json = [](const std::string& dir) {
    std::ifstream in(std::filesystem::path(dir) / "tiles.json");
    return nlohmann::json::parse(in);
  };
  const nlohmann::json s = json(o.out_dir), h = json(w.out_dir);
  EXPECT_TRUE(s["streamed"].get<bool>());
  EXPECT_FALSE(h["streamed"].get<bool>());
  EXPECT_EQ(s["grid"], h["grid"]);
  EXPECT_EQ(s["triangles_mean"].get<double>(), h["triangles_mean"].get<double>());
  EXPECT_EQ(s["triangles_max"].get<size_t>(), h["triangles_max"].get<size_t>());
  const nlohmann::json& r = s["render"];
  EXPECT_GT(r["triangles_mean"].get<double>(), 100.0);
  EXPECT_GT(r["patch_loads"].get<size_t>(), 0u);
  EXPECT_LE(r["gpu_peak_bytes"].get<size_t>(), r["gpu_budget_bytes"].get<size_t>());
  EXPECT_GT(r["whole_grid_gpu_bytes"].get<size_t>(), 0u);
  for (const char* f : {"frame_00000.png", "frame_00010.png", "frame_00020.png"})
    EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(o.out_dir) / "frames" / f)) << f;
  EXPECT_GT(s["process_peak_rss"].get<size_t>(), 0u);
}

// --render (the CDLOD terrain, the default): paged from the same cache, it draws every frame, under its GPU budget, and
// reports its pages.
TEST(TerrainTilesGL, TheCdlodTerrainIsDrawnFromPagesOfTheCache) {
  TerrainTilesOptions o = smallRun("terrain_tiles_cdlod");
  o.check_stride = 0;
  o.sprite_tile_cells = 0;
  o.render = true;
  EXPECT_TRUE(o.gpu_lod);  // the default
  o.gpu_budget_mb = 2.0;
  o.sample_stride = 10;
  runTerrainTiles(o);
  std::ifstream in(std::filesystem::path(o.out_dir) / "tiles.json");
  const nlohmann::json r = nlohmann::json::parse(in)["render"];
  EXPECT_EQ(r["lod"].get<std::string>(), "cdlod");
  EXPECT_GT(r["triangles_mean"].get<double>(), 100.0);
  EXPECT_GE(r["page_layers"].get<int>(), 1);
  EXPECT_LE(r["pages_peak"].get<size_t>(), size_t(r["page_layers"].get<int>()));
  EXPECT_GT(r["page_loads_waited_for"].get<size_t>() + r["pages_prefetched"].get<size_t>(), 0u);
  EXPECT_LE(r["gpu_bytes"].get<size_t>(), size_t(3) << 20);  // 2 MiB of pages, the overview and the patch
  for (const char* f : {"frame_00000.png", "frame_00010.png", "frame_00020.png"})
    EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(o.out_dir) / "frames" / f)) << f;
  o.render = false;
  o.gpu_lod = false;
  test::expectErrorMentions([&] { runTerrainTiles(o); }, {"--cpu-lod", "--render"});
}

// --lod-sprite: every frame drawn a second time as LOD-sprite on the same paged terrain, timed apart; its frames,
// their paths and their PSNR against the CDLOD frames are written, and the run's summary counts them.
TEST(TerrainTilesGL, LodSpriteRunsOnThePagedTerrainBesideItsCdlodFrames) {
  TerrainTilesOptions o = smallRun("terrain_tiles_lod_sprite");
  o.check_stride = 0;
  o.sprite_tile_cells = 0;
  o.render = true;
  o.lod_sprite = true;
  o.psnr_stride = 5;
  runTerrainTiles(o);
  const std::filesystem::path out(o.out_dir);
  std::ifstream in(out / "tiles.json");
  const nlohmann::json s = nlohmann::json::parse(in)["render"]["lod_sprite"];
  const size_t frames = size_t(o.frames);
  EXPECT_EQ(s["sprite_frames"].get<size_t>() + s["high_frames"].get<size_t>(), frames);
  EXPECT_GT(s["fresh_keyframes"].get<size_t>(), 0u);
  EXPECT_EQ(s["psnr_vs_cdlod_frames"].get<size_t>(), (frames + 4) / 5);
  EXPECT_GT(s["psnr_vs_cdlod_min_db"].get<double>(), 20.0);
  EXPECT_LE(s["psnr_vs_cdlod_mean_db"].get<double>(), 99.0);  // capped where a frame is the CDLOD frame itself
  EXPECT_GT(s["frame_ms_mean"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(s["speedup_vs_cdlod_mean"].get<double>(),
                   s["cdlod"]["frame_ms_mean"].get<double>() / s["frame_ms_mean"].get<double>());
  EXPECT_TRUE(s["cost"].contains("gpu_sprite"));
  // Own CPU time: counted (the GL counters are installed by the run), a part of the frame's time.
  for (const nlohmann::json& own : {s["own_cpu_ms"], s["cdlod"]["own_cpu_ms"]}) {
    EXPECT_GE(own["median"].get<double>(), 0.0);
    EXPECT_LE(own["median"].get<double>(), own["p95"].get<double>());
  }
  EXPECT_LT(s["own_cpu_ms"]["median"].get<double>(), s["frame_ms_median"].get<double>());
  std::ifstream csv(out / "lod_sprite_frames.csv");
  std::string line;
  size_t rows = 0, compared = 0;
  std::getline(csv, line);
  EXPECT_EQ(line, "frame,cdlod_ms,lod_sprite_ms,cdlod_own_cpu_ms,lod_sprite_own_cpu_ms,path,source,triangles,error_px,"
                  "magnification,page_loads,ahead_triangles,ahead_slices,keyframe_triangles,psnr_vs_cdlod");
  size_t loads = 0, keyframe_frames = 0;
  while (std::getline(csv, line)) {
    ++rows;
    compared += line.back() != ',' ? 1 : 0;
    // page_loads, ahead_triangles, ahead_slices, keyframe_triangles: the 11th to 14th columns.
    size_t at = 0;
    for (int column = 0; column < 10; ++column) at = line.find(',', at) + 1;
    std::array<size_t, 4> v{};
    for (size_t& x : v) {
      x = std::stoul(line.substr(at, line.find(',', at) - at));
      at = line.find(',', at) + 1;
    }
    loads += v[0];
    EXPECT_EQ(v[1] > 0, v[2] > 0) << line;  // triangles of a keyframe rendered ahead only with its slices
    keyframe_frames += v[3] > 0 ? 1 : 0;
  }
  EXPECT_GE(keyframe_frames, 1u) << "the first keyframe is drawn whole";
  EXPECT_EQ(rows, frames);
  EXPECT_EQ(loads, s["page_loads_waited_for"].get<size_t>());
  EXPECT_LE(s["frames_that_waited_for_pages"].get<size_t>(), loads);
  EXPECT_EQ(compared, s["psnr_vs_cdlod_frames"].get<size_t>());
  for (const char* f : {"lod_sprite_00000.png", "lod_sprite_diff_00000.png"})
    EXPECT_TRUE(std::filesystem::exists(out / "frames" / f)) << f;
  o.gpu_lod = false;
  test::expectErrorMentions([&] { runTerrainTiles(o); }, {"--lod-sprite", "--cpu-lod"});
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
