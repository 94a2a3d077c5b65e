// The terrain cost model's calibration (terrain/terrain_cost.h; GL: headless llvmpipe, a 129x129 fractal, 64x64
// frames): one sample per view, size, threshold and draw kind, a read-back term that is measured, bad options named.
// No assertion on times themselves (speed is the benchmark's business).
#include "farfield/terrain/terrain_cost.h"

#include <gtest/gtest.h>

#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/terrain/fractal.h"
#include "farfield/terrain/terrain_texture.h"

namespace farfield::terrain {
namespace {

Camera view(Vec3 eye, Vec3 at) {
  Camera c;
  c.eye = eye;
  c.at = at;
  c.width = c.height = 64;
  c.fov_y = float(degToRad(60.0));
  c.near_plane = 1.0f;
  c.far_plane = 50000.0f;
  return c;
}

TEST(TerrainCostGL, FitsOneSamplePerWorkloadAndMeasuresTheReadBack) {
  gpu::sharedHeadlessContext().makeCurrent();
  FractalOptions f;
  f.size = 129;
  f.seed = 4;
  f.cell_size = 20.0;
  const Heightfield hf = fractalTerrain(f);
  const QuadtreeLod lod(hf);
  const image::ColorImage texture = terrainTexture(hf);
  Vec2 scale, offset;
  texCoordTransform(hf, scale, offset);
  gpu::TerrainRenderer renderer(lod.positions(), texture, scale, offset);
  TerrainCostOptions o;
  o.views = {view(Vec3(500, 200, 900), Vec3(1300, 1500, 0)), view(Vec3(2000, 300, 600), Vec3(1200, 2000, 0))};
  o.keyframe_width = o.keyframe_height = 80;
  o.pixel_errors = {1.0f, 8.0f};
  o.repeats = 1;
  const TerrainCost cost = calibrateTerrainCost(lod, renderer, o);
  // sizes x views x thresholds x (textured, sprite in 1 call, sprite in 15 calls)
  EXPECT_EQ(cost.frame.samples, 2u * 2u * 2u * 3u);
  EXPECT_GT(cost.readback_ms_per_mpixel, 0.0);
  EXPECT_GT(cost.frameMs(1e5, 1, 64, 64), 0.0);
  EXPECT_GE(cost.frameMs(1e6, 1, 64, 64), cost.frameMs(1e3, 1, 64, 64));
  EXPECT_TRUE(cost.toJson()["frame"].contains("ms_per_mtriangle"));
  EXPECT_FALSE(cost.gpu_high.has_value());
  EXPECT_FALSE(cost.toJson().contains("gpu_high"));

  // With the CDLOD terrain: its frames too, one sample per size, view and threshold.
  GpuLodTerrain gpu_lod(hf, texture, CdlodOptions{8, 16, 0.2f});
  TerrainCostOptions with_gpu = o;
  with_gpu.gpu_high = &gpu_lod;
  const TerrainCost both = calibrateTerrainCost(lod, renderer, with_gpu);
  ASSERT_TRUE(both.gpu_high.has_value());
  EXPECT_EQ(both.gpu_high->samples, 2u * 2u * 2u);
  EXPECT_EQ(both.frame.samples, cost.frame.samples);
  EXPECT_GT(both.gpuHighMs(1e5, 64, 64), 0.0);
  EXPECT_TRUE(both.toJson().contains("gpu_high"));

  TerrainCostOptions bad = o;
  bad.views.clear();
  EXPECT_THROW(calibrateTerrainCost(lod, renderer, bad), Error);
  bad = o;
  bad.pixel_errors = {0.0f};
  EXPECT_THROW(calibrateTerrainCost(lod, renderer, bad), Error);
  bad = o;
  bad.repeats = 0;
  EXPECT_THROW(calibrateTerrainCost(lod, renderer, bad), Error);
  bad = o;
  bad.sprite_calls.clear();
  EXPECT_THROW(calibrateTerrainCost(lod, renderer, bad), Error);
  bad.sprite_calls = {1, -1};
  EXPECT_THROW(calibrateTerrainCost(lod, renderer, bad), Error);
}

}  // namespace
}  // namespace farfield::terrain
