// The terrain modes (eval/terrain_modes.h) as `farfield bench` runs them: registered by name, loading the terrain from
// the mode options (GL: headless llvmpipe, 96x96 frames, a 65x65 fractal), and rejecting bad mode options.
#include "farfield/eval/terrain_modes.h"

#include <gtest/gtest.h>

#include "farfield/core/error.h"
#include "farfield/eval/bench.h"
#include "farfield/eval/frame_runner.h"
#include "farfield/eval/terrain_paths.h"
#include "farfield/gpu/context.h"
#include "farfield/terrain/gpu_lod.h"
#include "farfield/terrain/lod_sprite.h"
#include "farfield/terrain/terrain_data.h"
#include "farfield/terrain/terrain_texture.h"
#include "support/test_support.h"

namespace farfield::eval {
namespace {

TEST(TerrainModes, RegisteredByName) {
  registerTerrainModes();
  registerTerrainModes();  // idempotent
  for (const char* m : {"high", "low", "lod-sprite", "lod-sprite-predict", "lod-sprite-cache", "lod-sprite-gpu",
                        "lod-sprite-gpu-predict"}) {
    EXPECT_TRUE(hasMode(m)) << m;
    EXPECT_NE(modeDescription(m).find("terrain"), std::string::npos) << m;
  }
  SpriteVariant v = SpriteVariant::Paper;
  EXPECT_TRUE(spriteVariantOf("lod-sprite-cache", v));
  EXPECT_EQ(v, SpriteVariant::Cache);
  EXPECT_TRUE(spriteVariantOf("lod-sprite-predict", v));
  EXPECT_EQ(v, SpriteVariant::Predict);
  EXPECT_TRUE(spriteVariantOf("lod-sprite", v));
  EXPECT_EQ(v, SpriteVariant::Paper);
  EXPECT_FALSE(spriteVariantOf("high", v));
  bool gpu = true;
  EXPECT_TRUE(spriteVariantOf("lod-sprite-predict", v, &gpu));
  EXPECT_FALSE(gpu);
  EXPECT_TRUE(spriteVariantOf("lod-sprite-gpu-predict", v, &gpu));
  EXPECT_EQ(v, SpriteVariant::Predict);
  EXPECT_TRUE(gpu);
  TerrainRun run;
  run.high_error = 0.5f;
  run.low_error = 3.0f;
  const terrain::LodSpriteOptions o = spriteOptions(run, SpriteVariant::Cache, 2.0);
  EXPECT_EQ(o.epsilon, 2.0);
  EXPECT_EQ(o.high_error, 0.5f);
  EXPECT_EQ(o.low_error, 3.0f);
  EXPECT_EQ(o.cache_size, 8);
  EXPECT_FALSE(o.predict);
  EXPECT_TRUE(spriteOptions(run, SpriteVariant::Predict, 1.0).predict);
  EXPECT_FALSE(spriteOptions(run, SpriteVariant::Predict, 1.0).predict_late);
  EXPECT_EQ(spriteOptions(run, SpriteVariant::Paper, 1.0).cache_size, 1);
}

// On the GPU (a CDLOD terrain given): the sprite frame too, and for the Predict variant keyframes rendered ahead late,
// with the per-frame choice kept.
TEST(TerrainModesGL, TheGpuVariantsDrawTheSpriteFrameOnTheGpu) {
  gpu::sharedHeadlessContext().makeCurrent();
  const std::unique_ptr<terrain::TerrainData> data = terrain::TerrainData::load("fractal:65:2");
  terrain::GpuLodTerrain cdlod(data->hf, terrain::terrainTexture(data->hf));
  TerrainRun run;
  const terrain::LodSpriteOptions g = spriteOptions(run, SpriteVariant::Predict, 1.0, &cdlod);
  EXPECT_TRUE(g.gpu_low && g.predict && g.predict_late);
  EXPECT_EQ(g.predict_chunks, 16);
  EXPECT_EQ(g.gpu_high, &cdlod);
  const terrain::LodSpriteOptions p = spriteOptions(run, SpriteVariant::Paper, 1.0, &cdlod);
  EXPECT_TRUE(p.gpu_low);
  EXPECT_FALSE(p.predict);
}

struct Terrain {
  std::unique_ptr<terrain::TerrainData> data = terrain::TerrainData::load("fractal:65:2");
  scene::Scene scene = data->fullResolutionScene();
  gen::CameraPath path = [this] {
    terrain::FlythroughOptions o;
    o.frames = 12;
    return flythroughCameraPath(data->hf, o);
  }();
  BenchOptions options(std::map<std::string, std::string> mode_options) const {
    const ClipPlanes planes = terrainClipPlanes(data->hf, path);
    BenchOptions o;
    o.modes = {"high", "low", "lod-sprite"};
    o.width = o.height = 96;
    o.samples = 0;
    o.near_plane = planes.near_plane;
    o.far_plane = planes.far_plane;
    o.mode_options = std::move(mode_options);
    return o;
  }
};

TEST(TerrainModesGL, LoadTheTerrainFromTheModeOptions) {
  registerTerrainModes();
  currentTerrainRun().reset();
  const Terrain t;
  const BenchResult r = runBench(gpu::sharedHeadlessContext(), t.scene, t.path,
                                 t.options({{"terrain", "fractal:65:2"}, {"epsilon", "0.5"}, {"low_error", "6"}}));
  ASSERT_TRUE(currentTerrainRun());
  const TerrainRun& run = *currentTerrainRun();
  EXPECT_EQ(run.epsilon, 0.5);
  EXPECT_EQ(run.low_error, 6.0f);
  EXPECT_EQ(run.high_error, 1.0f);
  const ModeResult* sprite = r.mode("lod-sprite");
  ASSERT_NE(sprite, nullptr);
  EXPECT_EQ(sprite->info.at("epsilon_px"), 0.5);
  EXPECT_EQ(sprite->info.at("frames"), 12.0);  // the measured pass, not the warm-up frame too
  EXPECT_EQ(r.mode("low")->info.at("pixel_error"), 6.0);
  // The measured pass's keyframes are where the render-free simulation of the metric puts them.
  const BenchOptions o = t.options({});
  std::vector<Camera> cameras;
  for (size_t i : r.frame_indices) cameras.push_back(pathCamera(t.path, i, 96, 96, o.near_plane, o.far_plane));
  const auto keys = terrain::simulateKeyframes(*run.data->lod, cameras, 6.0f, 0.5);
  size_t simulated = 0;
  for (uint8_t k : keys) simulated += k;
  EXPECT_EQ(sprite->info.at("keyframes"), double(simulated));
  ASSERT_EQ(run.logs.at("lod-sprite").size(), 12u);
  // The low LOD draws fewer triangles than the high one.
  EXPECT_LT(r.mode("low")->mean_triangles, r.mode("high")->mean_triangles);
  currentTerrainRun().reset();
}

TEST(TerrainModesGL, HighTilesDrawsTheHighLodFromPagedTiles) {
  registerTerrainModes();
  currentTerrainRun().reset();
  const Terrain t;
  BenchOptions o = t.options({{"terrain", "fractal:65:2"}, {"tile_blocks", "1"}, {"tile_budget_mb", "1"}});
  o.modes = {"high", "high-tiles"};
  const BenchResult r = runBench(gpu::sharedHeadlessContext(), t.scene, t.path, o);
  const ModeResult* tiles = r.mode("high-tiles");
  ASSERT_NE(tiles, nullptr);
  // The same mesh as `high` but for triangles outside the frustum (test_tiled_lod.cpp has the exact checks).
  EXPECT_NEAR(tiles->mean_triangles, r.mode("high")->mean_triangles, 0.1 * r.mode("high")->mean_triangles + 10.0);
  EXPECT_GT(tiles->info.at("tile_loads"), 0.0);
  EXPECT_LE(tiles->info.at("tile_peak_resident_bytes"), tiles->info.at("tile_budget_bytes"));
  // Drawn from GPU patches paged under their own budget.
  EXPECT_GT(tiles->info.at("patch_loads"), 0.0);
  EXPECT_LE(tiles->info.at("patch_peak_gpu_bytes"), tiles->info.at("patch_gpu_budget_bytes"));
  currentTerrainRun().reset();
}

TEST(TerrainModesGL, BadModeOptionsNameTheKey) {
  registerTerrainModes();
  const Terrain t;
  for (const auto& [key, value] : std::vector<std::pair<std::string, std::string>>{
           {"epsilon", "-1"}, {"high_error", "x"}, {"low_error", "0"}}) {
    currentTerrainRun().reset();
    try {
      runBench(gpu::sharedHeadlessContext(), t.scene, t.path, t.options({{"terrain", "fractal:65:2"}, {key, value}}));
      ADD_FAILURE() << key << "=" << value << ": no error";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind("--mode-option " + key + ":", 0), 0u) << e.what();
    }
  }
  currentTerrainRun().reset();
  EXPECT_THROW(runBench(gpu::sharedHeadlessContext(), t.scene, t.path, t.options({})), Error);  // no terrain=
  currentTerrainRun().reset();
}

}  // namespace
}  // namespace farfield::eval
