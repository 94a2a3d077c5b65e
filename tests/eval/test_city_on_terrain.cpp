// A city and a terrain in one frame (eval/city_on_terrain_mode.h): the terrain's heights are the city's ground, and
// the frame is the depth composite of the city drawn alone and the terrain drawn alone (GL: headless llvmpipe).
#include "farfield/eval/city_on_terrain_mode.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>

#include "farfield/core/error.h"
#include "farfield/eval/frame_runner.h"
#include "farfield/eval/terrain_modes.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/context.h"
#include "farfield/terrain/fractal.h"
#include "farfield/terrain/terrain_data.h"
#include "support/test_support.h"

namespace farfield::eval {
namespace {

const char* const kSpec = "fractal:129:6:relief=300";
constexpr float kScale = 0.5f;

// The city's ground as `farfield gen city --terrain kSpec --terrain-scale kScale` makes it (apps/farfield/
// city_terrain.cpp), computed here from the raw fractal.
struct Ground {
  terrain::Heightfield raw = terrain::fractalTerrain(terrain::parseFractalSpec(kSpec));
  double cx = 0.5 * raw.extentX(), cy = 0.5 * raw.extentY();
  float base = raw.sample(cx, cy);
  float at(Vec2 p) const { return kScale * (raw.sample(cx + double(p.x), cy + double(p.y)) - base); }
};

TEST(CityOnTerrain, TheTerrainsHeightsAreTheCitysGround) {
  terrain::TerrainLoadOptions load;
  load.block = 32;
  load.centred_scale = kScale;
  const auto data = terrain::TerrainData::load(kSpec, load);
  const Ground ground;
  size_t checked = 0;
  for (int j = 0; j < data->hf.height; j += 7)
    for (int i = 0; i < data->hf.width; i += 5) {
      const Vec3 p = data->lod->position(uint32_t(i) + uint32_t(j) * uint32_t(data->hf.width));
      const Vec2 city(float(double(p.x) - data->source_centre.x), float(double(p.y) - data->source_centre.y));
      ASSERT_NEAR(p.z, ground.at(city), 1e-3f) << i << ", " << j;
      ++checked;
    }
  EXPECT_GT(checked, 300u);
  terrain::TerrainLoadOptions bad;
  bad.centred_scale = -1.0f;
  EXPECT_THROW(terrain::TerrainData::load(kSpec, bad), Error);
}

// A small plain city laid on the fractal as `gen city --terrain kSpec --terrain-scale kScale` lays it, with a fresh
// terrain run (the GL context current).
gen::City cityOnTheFractal(int blocks, uint64_t seed) {
  gpu::sharedHeadlessContext().makeCurrent();
  registerTerrainModes();
  currentTerrainRun().reset();
  const auto ground = std::make_shared<Ground>();
  gen::CityOptions co;
  co.blocks = blocks;
  co.seed = seed;
  co.detail = 0;
  co.ground = [ground](Vec2 p) { return ground->at(p); };
  co.ground_cell = 15.0f;
  return gen::generateCity(co);
}

// The camera of the composite checks: from above the city's edge, looking across it to the terrain beyond.
Camera acrossTheCity(const gen::City& city) {
  const Box3 b = city.scene.bounds();
  Camera camera;
  camera.eye = Vec3(b.lo.x - 60.0f, b.lo.y - 60.0f, b.hi.z + 120.0f);
  camera.at = Vec3(b.hi.x + 400.0f, b.hi.y + 400.0f, 0.0f);
  camera.width = 160;
  camera.height = 96;
  camera.near_plane = 1.0f;
  camera.far_plane = 20000.0f;
  return camera;
}

// The composite frame against the city alone (culled) and the terrain alone (drawn by draw_terrain into a cleared
// target with the terrain's camera): each pixel the nearer of the two, away from near-ties.
void expectTheNearerOfBoth(ModeRunResources& res, CityOnTerrainMode& composite, const Camera& camera,
                           const std::function<void(const Camera&, gpu::RenderTarget&)>& draw_terrain) {
  FrameRunner runner(res.renderer, res.target);
  runner.run(composite, camera, 0);
  const image::ColorImage both = res.target.readColor();

  auto culled = createMode("culled", res.context);
  culled->prepare(res.context);
  runner.run(*culled, camera, 0);
  const image::ColorImage city_only = res.target.readColor();
  const image::DepthImage city_depth = res.target.readDepth();

  gpu::RenderTarget alone(camera.width, camera.height);
  alone.clear(res.renderer.light().sky_color);
  draw_terrain(composite.terrainCamera(camera), alone);
  const image::ColorImage terrain_only = alone.readColor();
  const image::DepthImage terrain_depth = alone.readDepth();

  size_t compared = 0, differ = 0, terrain_wins = 0, city_wins = 0;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const float dc = city_depth.at(x, y), dt = terrain_depth.at(x, y);
      // Reversed Z: the larger depth is nearer. Near-ties (the city's ground over the terrain at the hole's edge,
      // where the composite biases the terrain away) are left out.
      if (dc > 0.0f && dt > 0.0f &&
          std::abs(camera.linearDepth(dc) - camera.linearDepth(dt)) < 0.02f * camera.linearDepth(dc))
        continue;
      const bool terrain_nearer = dt > dc;
      (terrain_nearer ? terrain_wins : city_wins) += 1;
      const image::Rgba8 expected = terrain_nearer ? terrain_only.at(x, y) : city_only.at(x, y);
      differ += both.at(x, y) == expected ? 0 : 1;
      ++compared;
    }
  EXPECT_GT(compared, size_t(camera.width * camera.height) * 9 / 10);
  EXPECT_GT(terrain_wins, compared / 20) << "the terrain beyond the city should show";
  EXPECT_GT(city_wins, compared / 20);
  EXPECT_LE(differ, compared / 100) << differ << " of " << compared;
  std::printf("%s: %zu pixels compared, terrain nearer on %zu, city on %zu, %zu differ\n", composite.name().c_str(),
              compared, terrain_wins, city_wins, differ);
}

TEST(CityOnTerrainGL, TheFrameIsTheNearerOfTheCityAndTheTerrain) {
  const gen::City city = cityOnTheFractal(12, 4);
  ModeRunResources res(city.scene, 160, 96, {{"terrain", kSpec}, {"terrain_scale", "0.5"}});
  const Camera camera = acrossTheCity(city);
  auto composite = std::make_unique<CityOnTerrainMode>("high", "culled");
  composite->prepare(res.context);
  EXPECT_FALSE(composite->hole().empty());
  const TerrainRun& run = *currentTerrainRun();
  expectTheNearerOfBoth(res, *composite, camera, [&](const Camera& moved, gpu::RenderTarget& alone) {
    terrain::LodMesh mesh;
    terrain::renderLodFrame(*run.data->lod, *run.renderer, moved, terrain::LodSettings{run.high_error, true, false},
                            alone, mesh, composite->hole());
  });

  // The terrain's camera sees a terrain point where the city's camera sees the same point in the city's frame.
  const terrain::TerrainData& data = *run.data;
  const Camera moved = composite->terrainCamera(camera);
  for (int j = 0; j < data.hf.height; j += 16)
    for (int i = 0; i < data.hf.width; i += 16) {
      const Vec3 p = data.lod->position(uint32_t(i) + uint32_t(j) * uint32_t(data.hf.width));
      const Vec3 in_city(float(double(p.x) - data.source_centre.x), float(double(p.y) - data.source_centre.y), p.z);
      const Vec3 a = moved.project(p), c = camera.project(in_city);
      // Points far off screen project to thousands of pixels: float precision scales with them.
      EXPECT_NEAR(a.x, c.x, 0.05f + 1e-4f * std::abs(c.x));
      EXPECT_NEAR(a.y, c.y, 0.05f + 1e-4f * std::abs(c.y));
    }
  // The hole lies inside the city's ground.
  const Box3 g = city.scene.object(1).world_bounds;
  ASSERT_EQ(city.scene.object(1).name, "ground");
  const terrain::GridRect& h = composite->hole();
  for (int k = 0; k < 4; ++k) {
    const Vec3 p = data.lod->position(uint32_t((k & 1) ? h.x1 : h.x0) +
                                      uint32_t((k & 2) ? h.y1 : h.y0) * uint32_t(data.hf.width));
    EXPECT_GT(double(p.x) - data.source_centre.x, double(g.lo.x));
    EXPECT_LT(double(p.x) - data.source_centre.x, double(g.hi.x));
    EXPECT_GT(double(p.y) - data.source_centre.y, double(g.lo.y));
    EXPECT_LT(double(p.y) - data.source_centre.y, double(g.hi.y));
  }
  currentTerrainRun().reset();
}

// The CDLOD terrain on the GPU under the city: the same composite, its hole left out by the fragment shader.
TEST(CityOnTerrainGL, TheGpuTerrainFrameIsTheNearerOfTheCityAndTheTerrain) {
  const gen::City city = cityOnTheFractal(12, 4);
  ModeRunResources res(city.scene, 160, 96, {{"terrain", kSpec}, {"terrain_scale", "0.5"}});
  const Camera camera = acrossTheCity(city);
  CityOnTerrainMode composite("high-gpu", "culled");
  composite.prepare(res.context);
  TerrainRun& run = *currentTerrainRun();
  expectTheNearerOfBoth(res, composite, camera, [&](const Camera& moved, gpu::RenderTarget& alone) {
    run.gpuLod().setHole(composite.hole());
    run.gpuLod().draw(moved, run.high_error, alone);
    run.gpuLod().clearHole();
  });
  // The hole leaves out the terrain under the city (the check above cannot tell: the city's ground wins there).
  gpu::RenderTarget alone(camera.width, camera.height);
  alone.clear(res.renderer.light().sky_color);
  run.gpuLod().draw(composite.terrainCamera(camera), run.high_error, alone);
  gpu::RenderTarget alone_hole(camera.width, camera.height);
  alone_hole.clear(res.renderer.light().sky_color);
  run.gpuLod().setHole(composite.hole());
  run.gpuLod().draw(composite.terrainCamera(camera), run.high_error, alone_hole);
  run.gpuLod().clearHole();
  const image::IdImage ids = alone.readIds(), ids_hole = alone_hole.readIds();
  size_t terrain_px = 0, terrain_px_hole = 0;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      terrain_px += ids.at(x, y) == 1 ? 1 : 0;
      terrain_px_hole += ids_hole.at(x, y) == 1 ? 1 : 0;
    }
  EXPECT_LT(terrain_px_hole + size_t(camera.width * camera.height) / 20, terrain_px) << "the hole leaves pixels out";
  currentTerrainRun().reset();
}

TEST(CityOnTerrainGL, TheLodSpriteTerrainChoosesPerFrameByCostsMeasuredAtPrepare) {
  const gen::City city = cityOnTheFractal(10, 5);
  // lod-sprite-gpu: the same with the CDLOD terrain's frames, its sprite frames fitted too.
  for (const char* technique : {"lod-sprite", "lod-sprite-gpu"}) {
    SCOPED_TRACE(technique);
    ModeRunResources res(city.scene, 96, 64, {{"terrain", kSpec}, {"terrain_scale", "0.5"}});
    CityOnTerrainMode mode(technique, "culled");
    mode.prepare(res.context);
    ASSERT_TRUE(currentTerrainRun()->cost.has_value());
    // Fitted from frames timed at prepare (the fit's r2 is left alone: on a frame this small the times are noise, and
    // a fit to the mean alone has r2 0).
    const terrain::TerrainCost& cost = *currentTerrainRun()->cost;
    EXPECT_GE(cost.frame.samples, 5u);
    EXPECT_GT(cost.frame.predict(1000.0, 1.0, 96.0 * 64.0), 0.0) << "a frame takes time";
    if (std::string(technique) == "lod-sprite-gpu") {
      ASSERT_TRUE(cost.gpu_high && cost.gpu_sprite);
      EXPECT_GE(cost.gpu_sprite->samples, 5u);
      EXPECT_GT(cost.gpuSpriteMs(1000.0, 96, 64), 0.0);
    }
    FrameRunner runner(res.renderer, res.target);
    const Box3 b = city.scene.bounds();
    for (size_t f = 0; f < 8; ++f) {
      Camera camera;
      camera.eye = Vec3(b.lo.x + 5.0f * float(f), b.lo.y - 50.0f, b.hi.z + 100.0f);
      camera.at = Vec3(b.hi.x + 300.0f, b.hi.y + 300.0f, 0.0f);
      camera.width = 96;
      camera.height = 64;
      camera.near_plane = 1.0f;
      camera.far_plane = 20000.0f;
      runner.run(mode, camera, f);
    }
    // With the choice, the run starts on the high LOD (no sprite lifetime is known yet); always-sprite would not.
    EXPECT_GE(mode.info().at("terrain_high_frames"), 1.0);
    // The runner's measured frames reach the choice's cost correction, two frames late: frames 0-5 of the 8.
    EXPECT_EQ(mode.info().at("terrain_correction_measurements"), 6.0);
    currentTerrainRun().reset();
  }
}

TEST(CityOnTerrainGL, ACityMadeOnAnotherTerrainIsRefused) {
  gpu::sharedHeadlessContext().makeCurrent();
  registerTerrainModes();
  currentTerrainRun().reset();
  gen::CityOptions co;  // flat: no terrain under it
  co.blocks = 10;
  co.seed = 2;
  co.detail = 0;
  const gen::City city = gen::generateCity(co);
  ModeRunResources res(city.scene, 64, 48, {{"terrain", kSpec}, {"terrain_scale", "0.5"}});
  CityOnTerrainMode mode("lod-sprite", "culled");
  try {
    mode.prepare(res.context);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("gen city --terrain"), std::string::npos) << e.what();
  }
  currentTerrainRun().reset();
}

}  // namespace
}  // namespace farfield::eval
