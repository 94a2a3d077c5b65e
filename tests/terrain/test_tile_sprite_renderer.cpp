// LOD-sprite with a sprite per tile on the GPU (llvmpipe in CI; 128x128 frames, a 129x129 fractal in 4 x 4 tiles):
// frames against the high- and low-resolution LOD, keyframes taken per tile, and the region a sprite covers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "farfield/core/error.h"

#include "farfield/image/metrics.h"
#include "farfield/image/png_io.h"
#include "farfield/terrain/keyframe_visibility.h"
#include "farfield/terrain/tile_sprite_renderer.h"
#include "support/test_support.h"
#include "terrain_gl_scene.h"

namespace farfield::terrain {
namespace {

using test::kSky;
using test::makeCamera;
using test::Scene;
using test::testFractal;

TileSpriteRenderOptions tileOptions(int tile_cells) {
  TileSpriteRenderOptions o;
  o.tile_cells = tile_cells;
  o.epsilon = 1.0;
  o.high_error = 1.0f;
  o.low_error = 4.0f;
  o.sky_color = kSky;
  return o;
}

// The fractal seen from high above, looking down across it, and the first frame of 32-cell tiles there.
struct FirstFrame {
  Scene scene{testFractal()};
  Camera camera = makeCamera(Vec3(1280, 700, scene.hf.maxHeight() + 1200), Vec3(1280, 1300, 0));
  TileSpriteRenderer tiles{*scene.lod, *scene.renderer, camera.width, camera.height, tileOptions(32)};
  gpu::RenderTarget frame{camera.width, camera.height};
  TileSpriteRenderFrame info;
  FirstFrame() {
    frame.clear(kSky);
    tiles.render(camera, frame, &info);
  }
};

TEST(TileSpriteRenderer, AtTheKeyframeViewpointMatchesHighResolution) {
  FirstFrame first;
  Scene& scene = first.scene;
  const Camera& camera = first.camera;
  const TileSpriteRenderFrame& info = first.info;
  const image::ColorImage image = first.frame.readColor();
  const image::ColorImage high = scene.renderLod(camera, 1.0f), low = scene.renderLod(camera, 4.0f);
  if (std::getenv("FF_TERRAIN_DUMP")) {
    const auto dir = farfield::test::scratchDir("terrain_tile_keyframe_view");
    image::writePng((dir / "high.png").string(), high);
    image::writePng((dir / "tiles.png").string(), image);
    std::printf("tiles %zu refreshed %zu view-framed %zu low %llu sprite %llu; PSNR vs high %.2f dB, low %.2f\n",
                info.tiles_in_view, info.tiles_refreshed, info.tiles_view_framed,
                (unsigned long long)info.low_triangles, (unsigned long long)info.sprite_triangles,
                image::psnr(high, image), image::psnr(high, low));
  }
  // Every tile in view got its keyframe, and most low-resolution triangles take a sprite (the whole-frame sprite
  // textures 72% of them here: equation 3 fails at grazing angles).
  EXPECT_GT(info.tiles_in_view, 4u);
  EXPECT_EQ(info.tiles_refreshed, info.tiles_in_view);
  EXPECT_EQ(info.tiles_view_framed, 0u);  // every tile framed whole from this height
  EXPECT_GE(double(info.sprite_triangles), 0.8 * double(info.low_triangles));
  const double psnr_tiles = image::psnr(high, image), psnr_low = image::psnr(high, low);
  EXPECT_GE(psnr_tiles, 35.0) << "low-resolution alone: " << psnr_low;
  EXPECT_GT(psnr_tiles, psnr_low);
}

TEST(TileSpriteRenderer, KeptTileSpritesStayCloserToHighResolutionThanLowResolution) {
  Scene scene(testFractal());
  const float top = scene.hf.maxHeight();
  TileSpriteRenderer tiles(*scene.lod, *scene.renderer, 128, 128, tileOptions(32));
  gpu::RenderTarget frame(128, 128);
  double sum_tiles = 0.0, sum_low = 0.0;
  size_t kept = 0, refreshed_later = 0;
  for (int f = 0; f < 10; ++f) {
    const Camera camera =
        makeCamera(Vec3(1280 + 6.0f * f, 700 + 12.0f * f, top + 1200), Vec3(1280 + 6.0f * f, 1300 + 12.0f * f, 0));
    frame.clear(kSky);
    TileSpriteRenderFrame info;
    tiles.render(camera, frame, &info);
    if (f > 0) {
      kept += info.tiles_in_view - info.tiles_refreshed;
      refreshed_later += info.tiles_refreshed;
    }
    EXPECT_LT(info.max_tile_error_px, 1.0);
    const image::ColorImage high = scene.renderLod(camera, 1.0f);
    sum_tiles += image::psnr(high, frame.readColor());
    sum_low += image::psnr(high, scene.renderLod(camera, 4.0f));
  }
  EXPECT_GT(kept, 0u);  // small steps keep most tiles' sprites
  EXPECT_GT(kept, refreshed_later);
  EXPECT_EQ(tiles.counters().frames, 10u);
  EXPECT_GT(sum_tiles, sum_low);
}

TEST(TileSpriteRenderer, ATileSpriteTexturesOnlyTrianglesInsideItsRegion) {
  FirstFrame first;
  Scene& scene = first.scene;
  const Camera& camera = first.camera;
  const TileSpriteRenderer& tiles = first.tiles;
  const LodMesh low = scene.lod->build(camera, LodSettings{4.0f, true, false});
  const uint32_t w = uint32_t(scene.hf.width);
  size_t checked = 0, outside = 0;
  for (int ty = 0; ty < tiles.tilesY(); ++ty)
    for (int tx = 0; tx < tiles.tilesX(); ++tx) {
      TileSpriteRenderer::SpriteView view{};
      if (!tiles.sprite(IVec2(tx, ty), view)) continue;
      // Equation 3 against the tile's z-buffer, with and without its region, for every vertex of the low mesh.
      KeyframeVisibility inside, anywhere;
      inside.reset(*scene.lod, *view.camera, view.depth, VisibilityOptions{}, &view.region);
      anywhere.reset(*scene.lod, *view.camera, view.depth, VisibilityOptions{});
      for (uint32_t v : low.indices) {
        const bool in = view.region.contains(int(v % w), int(v / w));
        EXPECT_EQ(inside.vertexVisible(v), in && anywhere.vertexVisible(v));
        outside += (!in && anywhere.vertexVisible(v)) ? 1 : 0;
        ++checked;
      }
      // The region holds the whole tile.
      EXPECT_LE(view.region.x0, tx * 32);
      EXPECT_LE(view.region.y0, ty * 32);
      EXPECT_GE(view.region.x1, std::min(scene.hf.width - 1, (tx + 1) * 32));
      EXPECT_GE(view.region.y1, std::min(scene.hf.height - 1, (ty + 1) * 32));
    }
  EXPECT_GT(checked, 0u);
  EXPECT_GT(outside, 0u) << "some vertex outside a region would pass equation 3 alone";
}

TEST(TileSpriteRenderer, ATileUnderALowEyeTakesTheFramesView) {
  Scene scene(testFractal());
  const float ground = scene.hf.sample(1290.0, 1270.0);
  const Camera camera = makeCamera(Vec3(1290, 1270, ground + 60), Vec3(1290, 2200, ground - 200));
  TileSpriteRenderer tiles(*scene.lod, *scene.renderer, camera.width, camera.height, tileOptions(32));
  gpu::RenderTarget frame(camera.width, camera.height);
  frame.clear(kSky);
  TileSpriteRenderFrame info;
  tiles.render(camera, frame, &info);
  // The tile under the eye reaches behind it: its keyframe is the frame's own view, widened.
  EXPECT_GT(info.tiles_view_framed, 0u);
  EXPECT_LT(info.tiles_view_framed, info.tiles_refreshed);
  const image::ColorImage high = scene.renderLod(camera, 1.0f), low = scene.renderLod(camera, 4.0f);
  EXPECT_GT(image::psnr(high, frame.readColor()), image::psnr(high, low));
  // Turning the view past the margin refreshes those sprites even with the eye still.
  Camera turned = camera;
  turned.at = Vec3(2200, 1270, ground - 200);
  frame.clear(kSky);
  TileSpriteRenderFrame after;
  tiles.render(turned, frame, &after);
  EXPECT_GT(after.tiles_view_framed, 0u);
}

TEST(TileSpriteRenderer, ReleasedTargetsKeptForReuseStayFew) {
  // Every pass over new viewpoints releases its sprites, of sizes that vary with the view: only a few are kept.
  Scene scene(testFractal());
  const float top = scene.hf.maxHeight();
  TileSpriteRenderer tiles(*scene.lod, *scene.renderer, 128, 128, tileOptions(32));
  gpu::RenderTarget frame(128, 128);
  size_t most = 0;
  for (int pass = 0; pass < 12; ++pass) {
    const float a = 0.5f * float(pass);
    const Camera camera = makeCamera(Vec3(1280 + 900 * std::cos(a), 1280 + 900 * std::sin(a), top + 300 + 80 * pass),
                                     Vec3(1280, 1280, 0));
    frame.clear(kSky);
    tiles.render(camera, frame);
    tiles.reset();
    most = std::max(most, tiles.spareTargets());
  }
  EXPECT_GT(most, 0u);
  EXPECT_LE(most, 16u);
}

// The per-frame choice on constructed cost profiles, over a moving view: where the high LOD is cheapest every frame
// draws it (pixel for pixel the high LOD, no keyframe); where it is expensive, the first frame draws it (its size is
// learnt from one frame) and every later one takes the tiles; where keyframes never pay (an enormous read back) no
// tile is ever rendered, however cheap a sprite frame would be.
TEST(TileSpriteRenderer, ChoicePicksTheCheaperPathOnConstructedCostProfiles) {
  Scene scene(testFractal());
  const float top = scene.hf.maxHeight();
  auto camera = [&](int f) {
    return makeCamera(Vec3(1280 + 6.0f * f, 700 + 12.0f * f, top + 1200), Vec3(1280 + 6.0f * f, 1300 + 12.0f * f, 0));
  };
  TerrainCost cheap_high, expensive_high, no_keyframes;
  cheap_high.frame.base_ms = 1.0;
  cheap_high.frame.ms_per_draw = 100.0;  // a draw per tile sprite costs more than the one draw of the high LOD
  expensive_high.frame.base_ms = 1.0;
  expensive_high.frame.ms_per_mtriangle = 1e6;
  no_keyframes = expensive_high;
  no_keyframes.readback_ms_per_mpixel = 1e12;
  for (const TerrainCost* cost : {&cheap_high, &expensive_high, &no_keyframes}) {
    TileSpriteRenderOptions o = tileOptions(32);
    o.cost = cost;
    o.max_carried_high = 0;  // a choice on every frame (carried runs: the next test)
    TileSpriteRenderer tiles(*scene.lod, *scene.renderer, 128, 128, o);
    gpu::RenderTarget frame(128, 128);
    size_t high_frames = 0;
    for (int f = 0; f < 8; ++f) {
      frame.clear(kSky);
      TileSpriteRenderFrame info;
      tiles.render(camera(f), frame, &info);
      const bool high_expected = f == 0 || cost != &expensive_high;
      EXPECT_EQ(info.path, high_expected ? TerrainPath::High : TerrainPath::Sprite) << "frame " << f;
      if (info.path == TerrainPath::High) {
        ++high_frames;
        EXPECT_EQ(info.tiles_refreshed, 0u);
        const image::ColorImage high = scene.renderLod(camera(f), 1.0f), image = frame.readColor();
        EXPECT_TRUE(std::equal(image.pixels().begin(), image.pixels().end(), high.pixels().begin(),
                               [](const image::Rgba8& a, const image::Rgba8& b) {
                                 return a.r == b.r && a.g == b.g && a.b == b.b;
                               }))
            << "frame " << f;
      }
      if (f > 0) {  // the frames' alternatives: the keyframes add to the sprite frame where tiles are due
        EXPECT_GT(info.predicted_high_ms, 0.0);
        if (info.tiles_due > 0) {
          EXPECT_GT(info.predicted_keyframe_ms, info.predicted_sprite_ms);
        } else {
          EXPECT_EQ(info.predicted_keyframe_ms, info.predicted_sprite_ms);
        }
      }
    }
    EXPECT_EQ(tiles.counters().high_frames, high_frames);
    EXPECT_EQ(tiles.counters().tile_keyframes > 0, cost == &expensive_high);
  }
}

// After each choice of the high LOD the next frames draw it without deciding, in runs of 1, 2, 4, ... up to
// max_carried_high frames, the same image as a decided high frame; a run ends, and the tiles are taken, within that
// many frames of the costs turning in their favour.
TEST(TileSpriteRenderer, ChoicesOfTheHighLodAreCarriedInDoublingRuns) {
  Scene scene(testFractal());
  const float top = scene.hf.maxHeight();
  auto camera = [&](int f) {
    return makeCamera(Vec3(1280 + 6.0f * f, 700 + 12.0f * f, top + 1200), Vec3(1280 + 6.0f * f, 1300 + 12.0f * f, 0));
  };
  TerrainCost cost;  // the high LOD cheap (a draw per tile sprite dear), then dear
  cost.frame.base_ms = 1.0;
  cost.frame.ms_per_draw = 100.0;
  TileSpriteRenderOptions o = tileOptions(32);
  o.cost = &cost;
  o.max_carried_high = 4;
  TileSpriteRenderer tiles(*scene.lod, *scene.renderer, 128, 128, o);
  gpu::RenderTarget frame(128, 128);
  // Frame 0 learns the high LOD's size; then decided frames start runs of 1, 2, 4, 4, ... carried frames.
  std::vector<bool> expected_carried{false, false, true, false, true, true, false, true, true, true, true, false};
  for (int run = 0; run < 2; ++run) expected_carried.insert(expected_carried.end(), {true, true, true, true, false});
  size_t carried = 0;
  for (size_t f = 0; f < expected_carried.size(); ++f) {
    frame.clear(kSky);
    TileSpriteRenderFrame info;
    tiles.render(camera(int(f)), frame, &info);
    ASSERT_EQ(info.path, TerrainPath::High) << "frame " << f;
    EXPECT_EQ(info.carried, expected_carried[f]) << "frame " << f;
    carried += info.carried;
    if (info.carried) {  // nothing decided: no tile counted, no prediction
      EXPECT_EQ(info.tiles_in_view, 0u);
      EXPECT_EQ(info.predicted_high_ms, 0.0);
    } else if (f > 0) {
      EXPECT_GT(info.tiles_in_view, 0u);
      EXPECT_GT(info.predicted_high_ms, 0.0);
    }
    if (f % 5 == 2) {  // carried or not, the frame is the high LOD's
      const image::ColorImage high = scene.renderLod(camera(int(f)), 1.0f), image = frame.readColor();
      EXPECT_GT(image::psnr(image, high), 60.0) << "frame " << f;
    }
  }
  EXPECT_EQ(tiles.counters().carried_high_frames, carried);
  EXPECT_EQ(tiles.counters().high_frames, expected_carried.size());
  // The high LOD turns dear: the first decided frame takes the tiles, at most max_carried_high frames later.
  cost.frame.ms_per_draw = 0.0;
  cost.frame.ms_per_mtriangle = 1e6;
  int waited = 0;
  for (int f = int(expected_carried.size());; ++f, ++waited) {
    ASSERT_LE(waited, o.max_carried_high);
    frame.clear(kSky);
    TileSpriteRenderFrame info;
    tiles.render(camera(f), frame, &info);
    if (info.path == TerrainPath::Sprite) break;
    EXPECT_TRUE(info.carried) << "frame " << f;
  }
  EXPECT_EQ(waited, 4);  // the run of 4 started by the last decided frame above
  // ... and a later choice of the high LOD starts again from a run of one frame.
  cost = TerrainCost{};
  cost.frame.base_ms = 1.0;
  cost.frame.ms_per_draw = 100.0;
  std::vector<bool> carried_after;
  for (int f = 0; f < 4; ++f) {
    frame.clear(kSky);
    TileSpriteRenderFrame info;
    tiles.render(camera(40 + f), frame, &info);
    carried_after.push_back(info.carried);
  }
  EXPECT_EQ(carried_after, (std::vector<bool>{false, true, false, true}));
}

TEST(TileSpriteRenderer, BadOptionsAreRefused) {
  Scene scene(testFractal());
  TileSpriteRenderOptions o = tileOptions(0);
  EXPECT_THROW(TileSpriteRenderer(*scene.lod, *scene.renderer, 64, 64, o), Error);
  o = tileOptions(32);
  o.epsilon = 0.0;
  EXPECT_THROW(TileSpriteRenderer(*scene.lod, *scene.renderer, 64, 64, o), Error);
  o = tileOptions(32);
  o.max_half_angle_deg = 90.0f;
  EXPECT_THROW(TileSpriteRenderer(*scene.lod, *scene.renderer, 64, 64, o), Error);
  o = tileOptions(32);
  o.max_carried_high = -1;
  EXPECT_THROW(TileSpriteRenderer(*scene.lod, *scene.renderer, 64, 64, o), Error);
  TileSpriteRenderer ok(*scene.lod, *scene.renderer, 64, 64, tileOptions(32));
  gpu::RenderTarget frame(32, 32);
  EXPECT_THROW(ok.render(makeCamera(Vec3(0, 0, 1000), Vec3(100, 100, 0), 32), frame), Error);
}

}  // namespace
}  // namespace farfield::terrain
