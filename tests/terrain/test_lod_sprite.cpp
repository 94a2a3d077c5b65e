// LOD-sprite on the GPU (llvmpipe in CI; 128x128 frames, small terrains): keyframe visibility behind a ridge
// (equation 3), the frame at the keyframe viewpoint against the high-resolution frame, keyframe decisions, and
// section 5's keyframe cache and keyframes rendered ahead.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/gl_counters.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/terrain_renderer.h"
#include "farfield/image/metrics.h"
#include "farfield/image/png_io.h"
#include "farfield/terrain/fractal.h"
#include "farfield/terrain/keyframe_visibility.h"
#include "farfield/terrain/lod_sprite.h"
#include "farfield/terrain/quadtree_lod.h"
#include "farfield/terrain/terrain_texture.h"
#include "support/test_support.h"
#include "terrain_gl_scene.h"

namespace farfield::terrain {
namespace {

using test::kSky;
using test::makeCamera;
using test::choicePath;
using test::Scene;
using test::testFractal;

// Flat ground at 0 with a 200 m ridge along row 32 (y = 320 m) of a 65x65 grid of 10 m cells.
Heightfield ridgeTerrain() {
  Heightfield hf(65, 65, 10.0);
  hf.source = "ridge";
  for (int j = 0; j < 65; ++j)
    for (int i = 0; i < 65; ++i) hf.at(i, j) = float(200.0 * std::exp(-std::pow((j - 32) / 2.0, 2.0)));
  return hf;
}

// Independent occlusion: does the segment eye -> p pass below the terrain anywhere (sampled densely)?
bool occludedByTerrain(const Heightfield& hf, const Vec3& eye, const Vec3& p) {
  for (int s = 1; s < 2000; ++s) {
    const Vec3 q = glm::mix(eye, p, float(s) / 2000.0f);
    if (q.x < 0 || q.y < 0 || q.x > hf.extentX() || q.y > hf.extentY()) continue;
    if (glm::length(q - p) < 15.0f) break;  // the vertex's own neighbourhood
    if (q.z < hf.sample(q.x, q.y) - 1.0f) return true;
  }
  return false;
}

TEST(LodSprite, TriangleBehindRidgeIsNotVisibleAndInFrontIs) {
  Scene scene(ridgeTerrain());
  const Camera key = makeCamera(Vec3(320, -200, 60), Vec3(320, 400, 0));
  LodSpriteOptions options;
  options.low_error = 16.0f;
  options.sky_color = kSky;
  LodSpriteRenderer sprite(*scene.lod, *scene.renderer, key.width, key.height, options);
  gpu::RenderTarget frame(key.width, key.height);
  frame.clear(kSky);
  LodSpriteFrameInfo info;
  sprite.render(key, frame, &info);
  ASSERT_EQ(info.source, SpriteSource::Fresh);
  ASSERT_NE(sprite.spriteDepth(), nullptr);

  KeyframeVisibility visibility;
  visibility.reset(*scene.lod, *sprite.spriteCamera(), sprite.spriteDepth(), options.visibility);
  const LodMesh low = scene.lod->build(key, LodSettings{options.low_error, true, false});
  auto inImage = [&](uint32_t v) {
    float w = 0.0f;
    const Vec3 s = key.project(scene.lod->position(v), &w);
    return w > 0 && s.x > 2 && s.y > 2 && s.x < key.width - 2 && s.y < key.height - 2;
  };
  size_t behind = 0, front = 0;
  for (size_t t = 0; t < low.triangleCount(); ++t) {
    const uint32_t v[3] = {low.indices[3 * t], low.indices[3 * t + 1], low.indices[3 * t + 2]};
    if (!inImage(v[0]) || !inImage(v[1]) || !inImage(v[2])) continue;
    int min_row = 1 << 30, max_row = -1;
    for (uint32_t k : v) {
      min_row = std::min(min_row, int(k / 65u));
      max_row = std::max(max_row, int(k / 65u));
    }
    if (min_row >= 38) {
      // Setup check, independent of the z-buffer: the terrain really hides these vertices.
      for (uint32_t k : v) ASSERT_TRUE(occludedByTerrain(scene.hf, key.eye, scene.lod->position(k)));
      EXPECT_FALSE(visibility.triangleVisible(v[0], v[1], v[2])) << "triangle " << t << " behind the ridge";
      ++behind;
    } else if (max_row <= 26) {
      for (uint32_t k : v) ASSERT_FALSE(occludedByTerrain(scene.hf, key.eye, scene.lod->position(k)));
      EXPECT_TRUE(visibility.triangleVisible(v[0], v[1], v[2])) << "triangle " << t << " in front of the ridge";
      ++front;
    }
  }
  EXPECT_GT(behind, 0u);
  EXPECT_GT(front, 0u);
  // The renderer's own classification of this frame agrees: some triangles were drawn with the original texture.
  EXPECT_LT(info.visible_triangles, info.low_triangles);
  EXPECT_GT(info.visible_triangles, 0u);
}

TEST(LodSprite, AtTheKeyframeViewpointMatchesHighResolution) {
  Scene scene(testFractal());
  const float top = scene.hf.maxHeight();
  // Looking down onto the terrain, no horizon: the silhouette against the sky is where the low-resolution mesh
  // differs from the high-resolution one whatever the texture (the paper's Figure 6 shows that band).
  const Camera camera = makeCamera(Vec3(1280, 700, top + 1200), Vec3(1280, 1300, 0));
  const image::ColorImage high = scene.renderLod(camera, 1.0f);
  const image::ColorImage low = scene.renderLod(camera, 4.0f);
  size_t sky = 0;
  for (const image::Rgba8& p : high.pixels()) sky += (p == image::Rgba8(158, 189, 224, 255)) ? 1 : 0;
  ASSERT_EQ(sky, 0u) << "the view should show terrain only";

  LodSpriteOptions options;
  options.high_error = 1.0f;
  options.low_error = 4.0f;  // about 1500 triangles at 512x512 scale down to a few hundred at 128x128
  options.sky_color = kSky;
  LodSpriteRenderer sprite(*scene.lod, *scene.renderer, camera.width, camera.height, options);
  gpu::RenderTarget frame(camera.width, camera.height);
  frame.clear(kSky);
  LodSpriteFrameInfo info;
  sprite.render(camera, frame, &info);
  const image::ColorImage lod_sprite = frame.readColor();
  EXPECT_EQ(info.source, SpriteSource::Fresh);
  EXPECT_EQ(info.error_px, 0.0);
  EXPECT_LT(info.low_triangles, info.keyframe_triangles);
  if (std::getenv("FF_TERRAIN_DUMP")) {  // for looking at the frames by hand
    const auto dir = farfield::test::scratchDir("terrain_keyframe_view");
    image::writePng((dir / "high.png").string(), high);
    image::writePng((dir / "low.png").string(), low);
    image::writePng((dir / "lod_sprite.png").string(), lod_sprite);
    image::writePng((dir / "sprite.png").string(), sprite.spriteTarget()->readColor());
  }
  const double psnr_sprite = image::psnr(high, lod_sprite);
  const double psnr_low = image::psnr(high, low);
  EXPECT_GE(psnr_sprite, 35.0) << "low-resolution alone: " << psnr_low;
  EXPECT_GT(psnr_sprite, psnr_low);
}

TEST(LodSprite, NovelViewsStayCloserToHighResolutionThanLowResolution) {
  Scene scene(testFractal());
  const float top = scene.hf.maxHeight();
  LodSpriteOptions options;
  options.epsilon = 1.0;
  options.sky_color = kSky;
  options.low_error = 4.0f;
  LodSpriteRenderer sprite(*scene.lod, *scene.renderer, 128, 128, options);
  gpu::RenderTarget frame(128, 128);
  double sum_sprite = 0.0, sum_low = 0.0;
  size_t kept = 0;
  for (int f = 0; f < 8; ++f) {
    const Camera camera = makeCamera(Vec3(1280 + 6.0f * f, 700 + 10.0f * f, top + 1200), Vec3(1280 + 6.0f * f, 1300, 0));
    frame.clear(kSky);
    LodSpriteFrameInfo info;
    sprite.render(camera, frame, &info);
    kept += info.source == SpriteSource::Kept;
    const image::ColorImage high = scene.renderLod(camera, 1.0f);
    const double ps = image::psnr(high, frame.readColor()), pl = image::psnr(high, scene.renderLod(camera, 4.0f));
    if (std::getenv("FF_TERRAIN_DUMP")) std::printf("frame %d %s sprite %.2f low %.2f\n", f, spriteSourceName(info.source), ps, pl);
    sum_sprite += ps;
    sum_low += pl;
  }
  EXPECT_GT(kept, 0u);  // small steps reuse the sprite
  EXPECT_GT(sum_sprite, sum_low);
}

TEST(LodSprite, NewKeyframeWhenTheErrorReachesTheThreshold) {
  Scene scene(testFractal());
  const float top = scene.hf.maxHeight();
  LodSpriteOptions options;
  options.epsilon = 1.0;
  options.sky_color = kSky;
  LodSpriteRenderer sprite(*scene.lod, *scene.renderer, 128, 128, options);
  gpu::RenderTarget frame(128, 128);
  const Camera a = makeCamera(Vec3(1280, 300, top + 900), Vec3(1280, 1500, 0));
  LodSpriteFrameInfo info;
  sprite.render(a, frame, &info);
  EXPECT_EQ(info.source, SpriteSource::Fresh);
  sprite.render(a, frame, &info);  // same viewpoint: zero error, sprite kept
  EXPECT_EQ(info.source, SpriteSource::Kept);
  EXPECT_NEAR(info.error_px, 0.0, 1e-6);
  // Independent expectation from the metric itself: move until equation 2 says the sprite is stale.
  Camera b = a;
  for (int step = 1; step < 200; ++step) {
    b.eye = a.eye + Vec3(10.0f * step, 0, 0);
    b.at = a.at + Vec3(10.0f * step, 0, 0);
    const LodMesh low = scene.lod->build(b, LodSettings{options.low_error, true, true});
    const SpriteError e = spriteError(*scene.lod, low.quadrants, a.eye, b.eye);
    if (keyframeDue(e, pixelAngle(b), options.epsilon)) break;
  }
  sprite.render(b, frame, &info);
  EXPECT_EQ(info.source, SpriteSource::Fresh);
  EXPECT_GE(info.trigger_error_px, options.epsilon);
  EXPECT_EQ(sprite.counters().fresh_keyframes, 2u);
}

TEST(LodSprite, CacheReusesKeyframesWhenTheViewerComesBack) {
  Scene scene(testFractal());
  const float top = scene.hf.maxHeight();
  auto camera = [&](float x) { return makeCamera(Vec3(x, 300, top + 900), Vec3(x, 1500, 0)); };
  auto run = [&](int cache_size) {
    LodSpriteOptions options;
    options.sky_color = kSky;
    options.cache_size = cache_size;
    LodSpriteRenderer sprite(*scene.lod, *scene.renderer, 128, 128, options);
    gpu::RenderTarget frame(128, 128);
    for (int pass = 0; pass < 2; ++pass)
      for (int f = 0; f <= 30; ++f) sprite.render(camera(900.0f + 25.0f * (pass == 0 ? f : 30 - f)), frame);
    return sprite.counters();
  };
  const LodSpriteCounters plain = run(1), cached = run(8);
  EXPECT_EQ(plain.cache_hits, 0u);
  EXPECT_GT(cached.cache_hits, 0u);
  EXPECT_LT(cached.fresh_keyframes, plain.fresh_keyframes);
}

TEST(LodSprite, KeyframesRenderedAheadAreUsed) {
  Scene scene(testFractal());
  const float top = scene.hf.maxHeight();
  LodSpriteOptions options;
  options.sky_color = kSky;
  options.predict = true;
  options.predict_chunks = 3;
  LodSpriteRenderer sprite(*scene.lod, *scene.renderer, 128, 128, options);
  gpu::RenderTarget frame(128, 128);
  size_t ahead = 0;
  for (int f = 0; f < 60; ++f) {
    const float x = 700.0f + 20.0f * f;
    LodSpriteFrameInfo info;
    sprite.render(makeCamera(Vec3(x, 300, top + 900), Vec3(x, 1500, 0)), frame, &info);
    ahead += info.ahead_triangles;
    EXPECT_LE(info.error_px, options.epsilon + 1e-9);
    if (std::getenv("FF_TERRAIN_DUMP")) std::printf("frame %d %s error %.3f trigger %.3f ahead %lu\n", f, spriteSourceName(info.source), info.error_px, info.trigger_error_px, (unsigned long)info.ahead_triangles);
  }
  EXPECT_GT(sprite.counters().predicted_used, 0u);
  EXPECT_GT(ahead, 0u);
  // Straight, steady motion: predictions are good, so few keyframes have to be rendered at once.
  EXPECT_LT(sprite.counters().fresh_keyframes, sprite.counters().predicted_used);
}

}  // namespace
}  // namespace farfield::terrain

namespace farfield::terrain {
namespace {

// path_choice.h in the renderer: a machine where the sprite frame (two draw calls) costs more than the high LOD
// (one) never takes the sprite path, and its frames are the high LOD's, pixel for pixel; the error metric still
// trips where the render-free simulation says.
TEST(LodSpriteGL, ChoiceDrawsTheHighLodWhenTheSpriteCostsMore) {
  Scene scene(testFractal());
  TerrainCost cost;
  cost.frame.base_ms = 1.0;
  cost.frame.ms_per_draw = 3.0;
  LodSpriteOptions options;
  options.sky_color = kSky;
  options.cost = &cost;
  LodSpriteRenderer sprite(*scene.lod, *scene.renderer, 128, 128, options);
  const std::vector<Camera> cameras = choicePath(scene.hf, 12);
  const std::vector<uint8_t> trips = simulateKeyframes(*scene.lod, cameras, options.low_error, options.epsilon);
  gpu::RenderTarget frame(128, 128);
  for (size_t f = 0; f < cameras.size(); ++f) {
    frame.clear(kSky);
    LodSpriteFrameInfo info;
    sprite.render(cameras[f], frame, &info);
    EXPECT_EQ(info.path, TerrainPath::High) << "frame " << f;
    EXPECT_EQ(info.source, SpriteSource::None) << "frame " << f;
    EXPECT_EQ(info.keyframe_due, trips[f] != 0) << "frame " << f;
    EXPECT_GT(info.predicted_sprite_ms, info.predicted_high_ms) << "frame " << f;
    const image::ColorImage high = scene.renderLod(cameras[f], options.high_error);
    EXPECT_EQ(frame.readColor().pixels(), high.pixels()) << "frame " << f;
  }
  EXPECT_EQ(sprite.counters().fresh_keyframes, 0u);
  EXPECT_EQ(sprite.counters().high_frames, cameras.size());
  EXPECT_GE(sprite.counters().virtual_keyframes, 2u);  // the metric ran: it tripped along the path
}

// ...and where the high LOD is expensive: the run starts on the high LOD (no sprite lifetime known: a keyframe is
// assumed to serve one frame, which never pays), takes a keyframe as soon as a measured lifetime or the virtual
// keyframe's age makes one pay, and from then on every frame takes the sprite path, with a new keyframe exactly where
// equation 2, recomputed here from the last keyframe's eye, reaches the threshold.
TEST(LodSpriteGL, ChoiceTakesTheSpriteWhenTheHighLodIsExpensive) {
  Scene scene(testFractal());
  TerrainCost cost;
  cost.frame.base_ms = 1.0;
  cost.frame.ms_per_mtriangle = 1e6;
  LodSpriteOptions options;
  options.sky_color = kSky;
  options.cost = &cost;
  LodSpriteRenderer sprite(*scene.lod, *scene.renderer, 128, 128, options);
  const std::vector<Camera> cameras = choicePath(scene.hf, 24);
  gpu::RenderTarget frame(128, 128);
  bool started = false;  // the first keyframe was taken (at a trip, or by a switch)
  size_t keyframes_after_start = 0;
  Vec3 key_eye(0.0f);
  for (size_t f = 0; f < cameras.size(); ++f) {
    frame.clear(kSky);
    LodSpriteFrameInfo info;
    const LodMesh low = scene.lod->build(cameras[f], LodSettings{options.low_error, true, true});
    const bool due = started && keyframeDue(spriteError(*scene.lod, low.quadrants, key_eye, cameras[f].eye),
                                            pixelAngle(cameras[f]), options.epsilon);
    sprite.render(cameras[f], frame, &info);
    if (!started && info.source == SpriteSource::Fresh) {
      started = true;
      EXPECT_GE(f, 1u) << "with no lifetime known the first frame draws the high LOD";
    } else if (started) {
      EXPECT_FALSE(info.switched) << "frame " << f;
      EXPECT_EQ(info.source, due ? SpriteSource::Fresh : SpriteSource::Kept) << "frame " << f;
      keyframes_after_start += due;
    }
    EXPECT_EQ(info.path, started ? TerrainPath::Sprite : TerrainPath::High) << "frame " << f;
    if (info.source == SpriteSource::Fresh) key_eye = sprite.spriteCamera()->eye;
  }
  EXPECT_TRUE(started);
  EXPECT_GE(keyframes_after_start, 2u);  // the path trips the metric several times
  EXPECT_EQ(sprite.counters().fresh_keyframes, keyframes_after_start + 1);
}

// A switch: a viewer that holds still never trips the metric, so the first (virtual) keyframe would last forever;
// its age alone must make a real keyframe pay, after which the sprite path is taken.
TEST(LodSpriteGL, ChoiceSwitchesToTheSpriteWhenTheVirtualKeyframeLastsLongEnough) {
  Scene scene(testFractal());
  TerrainCost cost;
  cost.frame.base_ms = 1.0;
  cost.frame.ms_per_mtriangle = 1e6;
  LodSpriteOptions options;
  options.sky_color = kSky;
  options.cost = &cost;
  LodSpriteRenderer sprite(*scene.lod, *scene.renderer, 128, 128, options);
  const Camera still = choicePath(scene.hf, 1).front();
  gpu::RenderTarget frame(128, 128);
  std::vector<LodSpriteFrameInfo> infos(6);
  for (LodSpriteFrameInfo& info : infos) sprite.render(still, frame, &info);
  EXPECT_EQ(infos[0].path, TerrainPath::High);
  EXPECT_TRUE(infos[0].keyframe_due);
  size_t first_sprite = infos.size();
  for (size_t f = 1; f < infos.size(); ++f) {
    EXPECT_FALSE(infos[f].keyframe_due) << "frame " << f;  // the viewer does not move
    if (infos[f].path == TerrainPath::Sprite && first_sprite == infos.size()) first_sprite = f;
  }
  ASSERT_LT(first_sprite, infos.size());
  EXPECT_TRUE(infos[first_sprite].switched);
  EXPECT_EQ(infos[first_sprite].source, SpriteSource::Fresh);
  // Independent check of when: at the switch's age one keyframe plus sprite frames beat as many high frames, and one
  // frame earlier they did not.
  const LodSpriteFrameInfo& s = infos[first_sprite];
  const double age = double(first_sprite);
  EXPECT_LT(s.predicted_keyframe_ms + (age - 1.0) * s.predicted_sprite_ms, age * s.predicted_high_ms);
  EXPECT_GE(s.predicted_keyframe_ms + (age - 2.0) * s.predicted_sprite_ms, (age - 1.0) * s.predicted_high_ms);
  for (size_t f = first_sprite + 1; f < infos.size(); ++f) EXPECT_EQ(infos[f].source, SpriteSource::Kept);
  EXPECT_EQ(sprite.counters().switches, 1u);
}

}  // namespace
}  // namespace farfield::terrain
