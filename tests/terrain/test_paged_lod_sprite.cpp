// LOD-sprite over the CDLOD terrain paged from a tile cache (terrain/paged_gpu_lod.h, lod_sprite.h's renderer on a
// GpuLodTerrain alone, no quadtree): equation 3 on the GPU takes its normals from the pages and the overview as the
// whole grid's takes them from its heights; the error metric reads the held pages' heights; keyframes are the paged
// terrain's frames; no frame waits for the GPU. Needs a GL context (llvmpipe is enough).
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/gl_counters.h"
#include "farfield/image/metrics.h"
#include "farfield/terrain/gpu_lod.h"
#include "farfield/terrain/lod_sprite.h"
#include "farfield/terrain/paged_gpu_lod.h"
#include "farfield/terrain/sprite_error.h"
#include "farfield/terrain/terrain_texture.h"
#include "terrain/terrain_gl_scene.h"
#include "terrain/tiled_test_terrain.h"

namespace farfield::terrain {
namespace {

const Vec4 kSky(0.62f, 0.74f, 0.88f, 1.0f);
const CdlodOptions kLod{8, 16, 0.2f};

// A low flight across the test fractal (4 x 4 tiles of 64 cells), 160 x 160 frames.
std::vector<Camera> flight(const Heightfield& hf, int frames, float step) {
  std::vector<Camera> cameras;
  for (int f = 0; f < frames; ++f) {
    const float x = 300.0f + step * float(f);
    Camera c = test::tiledTestCamera(Vec3(x, 300.0f, hf.maxHeight() + 250.0f),
                                     Vec3(x + 800.0f, 3500.0f, hf.minHeight()));
    c.width = c.height = 160;
    cameras.push_back(c);
  }
  return cameras;
}

// The share of terrain pixels (not sky) that took the sprite, when the keyframe drawn at `key` is recoloured magenta
// and the terrain at `camera` is drawn under the 4 px bound as a sprite frame against it.
double spriteShare(GpuLodTerrain& terrain, const Camera& key, const Camera& camera) {
  gpu::RenderTarget keyframe(key.width, key.height), frame(camera.width, camera.height);
  keyframe.clear(kSky);
  terrain.draw(key, 1.0f, keyframe);
  const float magenta[4] = {1.0f, 0.0f, 1.0f, 1.0f};
  glClearNamedFramebufferfv(keyframe.framebuffer(), GL_COLOR, 0, magenta);
  gpu::CdlodSprite sprite;
  sprite.colour = &keyframe.colorTexture();
  sprite.depth = &keyframe.depthTexture();
  sprite.camera = key;
  terrain.renderer().setSprite(sprite);
  frame.clear(kSky);
  terrain.draw(camera, 4.0f, frame);
  terrain.renderer().clearSprite();
  const image::ColorImage image = frame.readColor();
  size_t ground = 0, taken = 0;
  const image::Rgba8 sky(uint8_t(std::lround(kSky.r * 255)), uint8_t(std::lround(kSky.g * 255)),
                         uint8_t(std::lround(kSky.b * 255)), 255);
  for (const image::Rgba8& p : image.pixels()) {
    if (p.r == sky.r && p.g == sky.g && p.b == sky.b) continue;
    ++ground;
    taken += p.r == 255 && p.g == 0 && p.b == 255 ? 1 : 0;
  }
  return ground ? double(taken) / double(ground) : 0.0;
}

// Equation 3 per vertex on a paged terrain: at the keyframe's own viewpoint and from a viewpoint moved aside, as many
// terrain pixels take the sprite as on the whole grid (the pages' normals are the grid's, the overview's a coarser
// estimate of them). At its own viewpoint not all do: the 4 px mesh's vertices stand off the 1 px keyframe's surface
// by more than the thickness in places, on either terrain.
TEST(PagedLodSpriteGL, VerticesVisibleInTheKeyframeTakeTheSpriteAsOnTheWholeGrid) {
  gpu::sharedHeadlessContext().makeCurrent();
  const Heightfield hf = test::tiledTestFractal();
  const TileCache cache(test::writeTestCache(hf, "paged_lod_sprite_visible"));
  PagedGpuLodOptions o;
  o.lod = kLod;
  PagedGpuLodTerrain paged(cache, o);
  GpuLodTerrain whole(hf, terrainTexture(hf), kLod);
  const std::vector<Camera> cameras = flight(hf, 40, 100.0f);
  for (const size_t k : {size_t(0), size_t(20), size_t(39)}) {
    const Camera& key = cameras[k];
    Camera aside = key;
    aside.eye += Vec3(250.0f, -150.0f, 80.0f);
    const double paged_own = spriteShare(paged, key, key), whole_own = spriteShare(whole, key, key);
    const double paged_aside = spriteShare(paged, key, aside), whole_aside = spriteShare(whole, key, aside);
    std::printf("view %zu: sprite taken at its own viewpoint %.3f paged / %.3f whole, aside %.3f / %.3f\n", k,
                paged_own, whole_own, paged_aside, whole_aside);
    EXPECT_GT(paged_own, 0.7) << "view " << k;
    EXPECT_NEAR(paged_own, whole_own, 0.02) << "view " << k;
    EXPECT_LT(paged_aside, paged_own) << "view " << k << ": moved aside, some of the view was hidden in the keyframe";
    EXPECT_NEAR(paged_aside, whole_aside, 0.05) << "view " << k;
  }
}

// The heights LOD-sprite's metric reads: a held page's are the grid's exactly; elsewhere the overview's.
TEST(PagedLodSpriteGL, GridHeightsComeFromTheHeldPagesThenTheOverview) {
  gpu::sharedHeadlessContext().makeCurrent();
  const Heightfield hf = test::tiledTestFractal();
  const TileCache cache(test::writeTestCache(hf, "paged_lod_sprite_heights"));
  PagedGpuLodOptions o;
  o.lod = kLod;
  o.keep_heights = true;
  o.prefetch_frames = 0;
  PagedGpuLodTerrain paged(cache, o);
  const Camera camera = flight(hf, 1, 0.0f).front();
  gpu::RenderTarget target(camera.width, camera.height);
  const GpuLodFrame f = paged.draw(camera, 1.0f, target);
  ASSERT_GT(f.pages_needed, 0u);
  size_t exact = 0, approximate = 0;
  double worst = 0.0;
  for (int j = 0; j < hf.height; j += 3)
    for (int i = 0; i < hf.width; i += 3) {
      const float h = paged.gridHeight(i, j);
      if (h == hf.at(i, j)) {
        ++exact;
      } else {
        ++approximate;
        worst = std::max(worst, double(std::abs(h - hf.at(i, j))));
      }
    }
  std::printf("%zu grid points exact, %zu from the overview (largest difference %.1f m)\n", exact, approximate, worst);
  // The flight starts over the south-west tiles: those held give their points exactly, the others not all.
  EXPECT_EQ(paged.gridHeight(10, 10), hf.at(10, 10));
  EXPECT_EQ(paged.gridHeight(64, 64), hf.at(64, 64));  // a corner shared by four tiles
  EXPECT_GT(exact, 0u);
  EXPECT_GT(approximate, 0u);
  EXPECT_LT(worst, double(hf.maxHeight() - hf.minHeight()));
  // The overview's points are exact wherever they are.
  const int step = paged.overviewStep();
  for (int j = 0; j < hf.height; j += step)
    for (int i = 0; i < hf.width; i += step) ASSERT_FLOAT_EQ(paged.gridHeight(i, j), hf.at(i, j)) << i << ", " << j;
  EXPECT_FLOAT_EQ(paged.gridHeight(-5, 1000), hf.at(0, hf.height - 1));  // clamped to the grid
}

// LOD-sprite wholly on the paged terrain: sprite frames where they pay, keyframes that are the paged terrain's frames
// at their cameras, no wait in any frame, frames close to the paged high frames and to the whole grid's LOD-sprite
// frames, and about as many keyframes as on the whole grid (the metric over the held pages' heights).
TEST(PagedLodSpriteGL, RunsWhollyOnThePagedTerrain) {
  gpu::sharedHeadlessContext().makeCurrent();
  const Heightfield hf = test::tiledTestFractal();
  const TileCache cache(test::writeTestCache(hf, "paged_lod_sprite_run"));
  PagedGpuLodOptions o;
  o.lod = kLod;
  o.keep_heights = true;
  o.prefetch_frames = 6;
  PagedGpuLodTerrain paged(cache, o);
  GpuLodTerrain whole(hf, terrainTexture(hf), kLod);
  TerrainCost cost = test::spritesPay();
  LodSpriteOptions options;
  options.sky_color = kSky;
  options.gpu_low = true;
  options.cost = &cost;
  LodSpriteRenderer on_pages(paged, 160, 160, options);
  LodSpriteRenderer on_grid(whole, 160, 160, options);
  const bool counting = gpu::installGlCounters();
  const std::vector<Camera> cameras = flight(hf, 60, 40.0f);
  gpu::RenderTarget frame(160, 160), reference(160, 160), high(160, 160);
  double worst_high = 1e9, worst_grid = 1e9;
  size_t sprite_frames = 0, checked = 0;
  for (size_t f = 0; f < cameras.size(); ++f) {
    const Camera& c = cameras[f];
    frame.clear(kSky);
    LodSpriteFrameInfo info;
    const gpu::GlCounters before = gpu::glCounters();
    on_pages.render(c, frame, &info);
    paged.prefetch(c, options.high_error);
    if (counting) {
      EXPECT_EQ((gpu::glCounters() - before).syncs, 0u) << "frame " << f;
    }
    sprite_frames += info.path == TerrainPath::Sprite ? 1 : 0;
    EXPECT_LE(info.error_px, options.epsilon + 1e-9) << "frame " << f;
    if (info.source == SpriteSource::Fresh) {
      const Camera& key = *on_pages.spriteCamera();
      gpu::RenderTarget key_expected(key.width, key.height);
      key_expected.clear(kSky);
      paged.draw(key, options.high_error, key_expected);
      EXPECT_EQ(on_pages.spriteTarget()->readColor().pixels(), key_expected.readColor().pixels()) << "frame " << f;
      ++checked;
    }
    const image::ColorImage got = frame.readColor();
    reference.clear(kSky);
    on_grid.render(c, reference);
    high.clear(kSky);
    paged.draw(c, options.high_error, high);
    worst_high = std::min(worst_high, image::psnr(got, high.readColor()));
    worst_grid = std::min(worst_grid, image::psnr(got, reference.readColor()));
  }
  const LodSpriteCounters& p = on_pages.counters();
  const LodSpriteCounters& g = on_grid.counters();
  std::printf("paged: %zu keyframes, %zu sprite frames of %zu; whole grid: %zu keyframes; worst PSNR against the paged "
              "high frame %.1f dB, against the whole grid's LOD-sprite frame %.1f dB\n",
              p.fresh_keyframes, sprite_frames, cameras.size(), g.fresh_keyframes, worst_high, worst_grid);
  EXPECT_GE(sprite_frames, cameras.size() * 3 / 4);
  EXPECT_GE(p.fresh_keyframes, 2u);
  EXPECT_EQ(checked, p.fresh_keyframes);
  EXPECT_LE(std::max(p.fresh_keyframes, g.fresh_keyframes) - std::min(p.fresh_keyframes, g.fresh_keyframes), 1u);
  EXPECT_GT(worst_high, 25.0);
  EXPECT_GT(worst_grid, 25.0);

  // Without the CPU-side sprite frame's quadtree, the sprite frame must be the GPU's; and the metric needs the pages'
  // heights.
  LodSpriteOptions cpu_low = options;
  cpu_low.gpu_low = false;
  EXPECT_THROW(LodSpriteRenderer(paged, 160, 160, cpu_low), Error);
  PagedGpuLodOptions without = o;
  without.keep_heights = false;
  PagedGpuLodTerrain overview_only(cache, without);
  EXPECT_THROW(LodSpriteRenderer(overview_only, 160, 160, options), Error);
}

}  // namespace
}  // namespace farfield::terrain
