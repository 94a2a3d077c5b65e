// LOD-sprite drawn by the CDLOD terrain on the GPU (LodSpriteOptions::gpu_high, gpu_low; llvmpipe in CI, 128x128
// frames, the small test fractal): high frames and keyframes are CDLOD frames pixel for pixel, the sprite frame waits
// for nothing, and keyframes rendered ahead late (predict_late) are drawn in slices that together are the whole
// keyframe, and taken in time, so that no frame draws a whole keyframe.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/gl_counters.h"
#include "farfield/gpu/render_target.h"
#include "farfield/image/metrics.h"
#include "farfield/terrain/gpu_lod.h"
#include "farfield/terrain/lod_sprite.h"
#include "terrain_gl_scene.h"

namespace farfield::terrain {
namespace {

using test::choicePath;
using test::kSky;
using test::makeCamera;
using test::spritesPay;
using test::Scene;
using test::testFractal;

// LOD-sprite's options with its high-resolution LOD drawn by a CDLOD terrain, on the tests' sky.
LodSpriteOptions cdlodOptions(GpuLodTerrain& gpu_lod) {
  LodSpriteOptions options;
  options.sky_color = kSky;
  options.gpu_high = &gpu_lod;
  return options;
}

// ... with the sprite frame on the GPU too (gpu_low), choosing by `cost`, which must outlive the options.
LodSpriteOptions gpuSpriteOptions(GpuLodTerrain& gpu_lod, const TerrainCost& cost) {
  LodSpriteOptions options = cdlodOptions(gpu_lod);
  options.gpu_low = true;
  options.cost = &cost;
  return options;
}

// LodSpriteOptions::gpu_high: the high LOD is the CDLOD terrain's. Where its frames are predicted cheap, every frame
// is the CDLOD frame, pixel for pixel; where they are expensive, the sprite path is taken and each keyframe is the
// CDLOD terrain drawn at the keyframe's camera. Without a CDLOD cost model the choice is refused.
TEST(LodSpriteGL, TheGpuHighLodDrawsHighFramesAndKeyframes) {
  Scene scene(testFractal());
  GpuLodTerrain gpu_lod(scene.hf, scene.texture, CdlodOptions{8, 16, 0.2f});
  const std::vector<Camera> cameras = choicePath(scene.hf, 16);
  LodSpriteOptions options = cdlodOptions(gpu_lod);
  gpu::RenderTarget frame(128, 128), expected(128, 128);

  TerrainCost cheap;  // sprite frames cost 2 draws, CDLOD frames nothing
  cheap.frame.ms_per_draw = 3.0;
  cheap.gpu_high = gpu::CostModel{};
  cheap.gpu_high->base_ms = 0.5;
  options.cost = &cheap;
  {
    LodSpriteRenderer sprite(*scene.lod, *scene.renderer, 128, 128, options);
    for (size_t f = 0; f < cameras.size(); ++f) {
      frame.clear(kSky);
      LodSpriteFrameInfo info;
      sprite.render(cameras[f], frame, &info);
      EXPECT_EQ(info.path, TerrainPath::High) << "frame " << f;
      EXPECT_DOUBLE_EQ(info.predicted_high_ms, 0.5) << "frame " << f;
      EXPECT_EQ(info.high_triangles % (2 * 8 * 8), 0u) << "CDLOD patches";
      expected.clear(kSky);
      gpu_lod.draw(cameras[f], options.high_error, expected);
      EXPECT_EQ(frame.readColor().pixels(), expected.readColor().pixels()) << "frame " << f;
    }
  }

  TerrainCost expensive = cheap;  // now the CDLOD frames cost a lot
  expensive.gpu_high->base_ms = 50.0;
  expensive.frame.ms_per_draw = 0.1;
  options.cost = &expensive;
  LodSpriteRenderer sprite(*scene.lod, *scene.renderer, 128, 128, options);
  size_t keyframes = 0;
  for (size_t f = 0; f < cameras.size(); ++f) {
    frame.clear(kSky);
    LodSpriteFrameInfo info;
    sprite.render(cameras[f], frame, &info);
    if (info.source != SpriteSource::Fresh) continue;
    ++keyframes;
    EXPECT_GT(info.keyframe_triangles, 0u);
    EXPECT_EQ(info.keyframe_triangles % (2 * 8 * 8), 0u);
    const Camera& key = *sprite.spriteCamera();
    gpu::RenderTarget key_expected(key.width, key.height);
    key_expected.clear(kSky);
    gpu_lod.draw(key, options.high_error, key_expected);
    EXPECT_EQ(sprite.spriteTarget()->readColor().pixels(), key_expected.readColor().pixels()) << "frame " << f;
  }
  EXPECT_GE(keyframes, 1u);
  EXPECT_GE(sprite.counters().frames - sprite.counters().high_frames, cameras.size() / 2);

  TerrainCost without = cheap;
  without.gpu_high.reset();
  options.cost = &without;
  EXPECT_THROW(LodSpriteRenderer(*scene.lod, *scene.renderer, 128, 128, options), Error);
}

// The sprite frame on the GPU too (gpu_low): a keyframe is a CDLOD frame whose depth stays on the GPU, a sprite frame
// is one CDLOD draw tested against it, and no frame waits for the GPU; the frames stay close to the CDLOD high
// frames, the metric over the CDLOD mesh trips along the path, and the choice predicts sprite frames by gpu_sprite.
TEST(LodSpriteGL, TheSpriteFrameOnTheGpuWaitsForNothing) {
  Scene scene(testFractal());
  GpuLodTerrain gpu_lod(scene.hf, scene.texture, CdlodOptions{8, 16, 0.2f});
  const std::vector<Camera> cameras = choicePath(scene.hf, 24);
  TerrainCost cost = spritesPay();  // the sprite path once a sprite has lasted
  LodSpriteOptions options = gpuSpriteOptions(gpu_lod, cost);
  LodSpriteRenderer sprite(*scene.lod, *scene.renderer, 128, 128, options);
  const bool counting = gpu::installGlCounters();
  gpu::RenderTarget frame(128, 128), expected(128, 128);
  double worst_psnr = 1e9;
  size_t sprite_frames = 0;
  for (size_t f = 0; f < cameras.size(); ++f) {
    frame.clear(kSky);
    LodSpriteFrameInfo info;
    const gpu::GlCounters before = gpu::glCounters();
    const gpu::FrameStats stats = sprite.render(cameras[f], frame, &info);
    const gpu::GlCounters used = gpu::glCounters() - before;
    EXPECT_DOUBLE_EQ(info.predicted_sprite_ms, 0.25) << "frame " << f;
    if (info.path == TerrainPath::Sprite) {
      ++sprite_frames;
      EXPECT_TRUE(sprite.spriteDepth()->empty());
    }
    EXPECT_EQ(stats.draw_calls, info.source == SpriteSource::Fresh ? 2u : 1u) << "frame " << f;
    EXPECT_EQ(info.low_triangles % (2 * 8 * 8), 0u) << "CDLOD patches";
    if (counting) {
      EXPECT_EQ(used.syncs, 0u) << "frame " << f;
    }
    if (f > 0) {
      EXPECT_GT(info.quadrants, 100u) << "frame " << f;
    }
    expected.clear(kSky);
    gpu_lod.draw(cameras[f], options.high_error, expected);
    worst_psnr = std::min(worst_psnr, image::psnr(frame.readColor(), expected.readColor()));
  }
  std::printf("%zu keyframes in %zu frames, %zu sprite frames; worst PSNR against the CDLOD high frame %.1f dB\n",
              sprite.counters().fresh_keyframes, cameras.size(), sprite_frames, worst_psnr);
  // The first keyframe is virtual (no sprite lifetime measured yet: the high frame wins); then sprites.
  EXPECT_GE(sprite_frames, cameras.size() * 3 / 4);
  EXPECT_GE(sprite.counters().fresh_keyframes, 2u);
  EXPECT_LT(sprite.counters().fresh_keyframes, cameras.size() / 2);
  EXPECT_GT(worst_psnr, 25.0);

  // Where sprite frames cost as much as the high LOD, no sprite can pay: every frame is the high LOD, and the error
  // metric is not run (no quadrant evaluated).
  TerrainCost even = cost;
  even.gpu_sprite->base_ms = 50.0;
  LodSpriteOptions no_gain = options;
  no_gain.cost = &even;
  LodSpriteRenderer high_only(*scene.lod, *scene.renderer, 128, 128, no_gain);
  for (size_t f = 0; f < 6; ++f) {
    frame.clear(kSky);
    LodSpriteFrameInfo info;
    high_only.render(cameras[f], frame, &info);
    EXPECT_EQ(info.path, TerrainPath::High) << "frame " << f;
    EXPECT_EQ(info.quadrants, 0u) << "frame " << f;
  }
  EXPECT_EQ(high_only.counters().fresh_keyframes, 0u);

  LodSpriteOptions bad = options;
  bad.gpu_high = nullptr;
  bad.cost = nullptr;
  EXPECT_THROW(LodSpriteRenderer(*scene.lod, *scene.renderer, 128, 128, bad), Error);
  TerrainCost no_sprite_model = cost;
  no_sprite_model.gpu_sprite.reset();
  bad = options;
  bad.cost = &no_sprite_model;
  EXPECT_THROW(LodSpriteRenderer(*scene.lod, *scene.renderer, 128, 128, bad), Error);
}

// The choice's closed loop (LodSpriteRenderer::measured): where the model says sprites pay (0.25 against 50 ms) but
// the measured frames, reported two frames late, say a sprite frame costs 60 ms and a high frame 1 ms, the renderer
// turns to the high LOD within a few frames and stays there, its factors the measured ones; the same renderer with no
// time reported keeps drawing sprites.
TEST(LodSpriteGL, MeasuredFramesCorrectTheChoice) {
  Scene scene(testFractal());
  GpuLodTerrain gpu_lod(scene.hf, scene.texture, CdlodOptions{8, 16, 0.2f});
  const std::vector<Camera> cameras = choicePath(scene.hf, 24);
  TerrainCost cost = spritesPay();  // high 50 ms, sprite 0.25 ms by the model
  LodSpriteOptions options = gpuSpriteOptions(gpu_lod, cost);
  options.correction.min_ratio = 0.001;
  options.correction.max_ratio = 1000.0;
  gpu::RenderTarget frame(128, 128);
  auto measuredMs = [](const LodSpriteFrameInfo& info) {
    switch (info.kind) {
      case TerrainFrameKind::High: return 1.0;
      case TerrainFrameKind::Sprite: return 60.0;
      case TerrainFrameKind::Keyframe: return 70.0;
      case TerrainFrameKind::Slice: return 65.0;
    }
    return 0.0;
  };
  for (const bool report : {false, true}) {
    LodSpriteRenderer sprite(*scene.lod, *scene.renderer, 128, 128, options);
    std::vector<TerrainPath> paths;
    for (const Camera& camera : cameras) {
      frame.clear(kSky);
      LodSpriteFrameInfo info;
      sprite.render(camera, frame, &info);
      EXPECT_EQ(info.frame, paths.size() + 1);
      paths.push_back(info.path);
      if (report) {
        EXPECT_TRUE(sprite.measured(info.frame, measuredMs(info)));
      }
    }
    const size_t sprites = size_t(std::count(paths.begin(), paths.end(), TerrainPath::Sprite));
    if (!report) {
      EXPECT_GE(sprites, cameras.size() * 3 / 4);
      EXPECT_DOUBLE_EQ(sprite.costCorrection().factor(TerrainFrameKind::Sprite), 1.0);
      continue;
    }
    EXPECT_NEAR(sprite.costCorrection().factor(TerrainFrameKind::High), 1.0 / 50.0, 1e-9);
    EXPECT_NEAR(sprite.costCorrection().factor(TerrainFrameKind::Sprite), 60.0 / 0.25, 1e-9);
    for (size_t f = cameras.size() / 2; f < cameras.size(); ++f)
      EXPECT_EQ(paths[f], TerrainPath::High) << "frame " << f;
    EXPECT_LT(sprites, cameras.size() / 3);
  }
}

// predict_late on the GPU in 4 slices, choosing by `cost`.
LodSpriteOptions lateSlicedOptions(GpuLodTerrain& gpu_lod, const TerrainCost& cost) {
  LodSpriteOptions options = cdlodOptions(gpu_lod);
  options.gpu_low = true;
  options.predict = true;
  options.predict_late = true;
  options.predict_chunks = 4;
  options.cost = &cost;
  return options;
}

// LOD-sprite with lateSlicedOptions over the test fractal's CDLOD terrain, 128 x 128.
struct LateSlicedRun {
  // reuse_coverage: LodSpriteOptions::reuse_coverage.
  explicit LateSlicedRun(const TerrainCost& model, double reuse_coverage = LodSpriteOptions{}.reuse_coverage)
      : cost(model),
        options(withReuseCoverage(lateSlicedOptions(gpu_lod, cost), reuse_coverage)),
        sprite(*scene.lod, *scene.renderer, 128, 128, options) {}
  static LodSpriteOptions withReuseCoverage(LodSpriteOptions o, double reuse_coverage) {
    o.reuse_coverage = reuse_coverage;
    return o;
  }
  Scene scene{testFractal()};
  GpuLodTerrain gpu_lod{scene.hf, scene.texture, CdlodOptions{8, 16, 0.2f}};
  TerrainCost cost;
  LodSpriteOptions options;
  LodSpriteRenderer sprite;
  float top = scene.hf.maxHeight();
};

// The straight, steady flight of the keyframes-ahead tests (x = 300 + 24 f at frame f), and one frame of it.
Camera flightCamera(float top, float x) { return makeCamera(Vec3(x, 300, top + 700), Vec3(x + 100, 1500, 0)); }
LodSpriteFrameInfo flightFrame(LodSpriteRenderer& sprite, gpu::RenderTarget& frame, float top, float x) {
  frame.clear(kSky);
  LodSpriteFrameInfo info;
  sprite.render(flightCamera(top, x), frame, &info);
  return info;
}

// predict_late on the GPU: along a straight, steady flight, each keyframe after the first is rendered ahead in slices
// (no frame draws a whole keyframe, each draws at most one slice) and taken before the sprite trips; a keyframe made of
// slices is the CDLOD frame at its camera pixel for pixel (the terrain's selections for other bounds and cameras,
// made in between, do not change it), and every frame stays within the error threshold and close to the CDLOD frame.
TEST(LodSpriteGL, KeyframesRenderedAheadOnTheGpuAreDrawnInSlicesAndTakenInTime) {
  LateSlicedRun late(spritesPay());  // a keyframe is many sprite frames, so it takes all 4 slices
  LodSpriteRenderer& sprite = late.sprite;
  const LodSpriteOptions& options = late.options;
  const float top = late.top;
  gpu::RenderTarget frame(128, 128), expected(128, 128);
  double worst_psnr = 1e9;
  uint64_t slice_max = 0;
  size_t first_fresh = 0, slices = 0, checked = 0;
  for (size_t f = 0; f < 90; ++f) {
    const Camera camera = flightCamera(top, 300.0f + 24.0f * float(f));
    frame.clear(kSky);
    LodSpriteFrameInfo info;
    sprite.render(camera, frame, &info);
    if (info.source == SpriteSource::Fresh && first_fresh == 0) first_fresh = f;
    if (first_fresh > 0 && f > first_fresh) {
      EXPECT_EQ(info.keyframe_triangles, 0u) << "frame " << f << ": a whole keyframe";
    }
    if (info.ahead_triangles > 0) {
      ++slices;
      slice_max = std::max(slice_max, info.ahead_triangles);
    }
    EXPECT_LE(info.error_px, options.epsilon + 1e-9) << "frame " << f;
    if (std::getenv("FF_TERRAIN_DUMP"))
      std::printf("frame %zu %s error %.3f ahead %lu\n", f, spriteSourceName(info.source), info.error_px,
                  (unsigned long)info.ahead_triangles);
    if (info.source == SpriteSource::Predicted) {
      const Camera& key = *sprite.spriteCamera();
      gpu::RenderTarget key_expected(key.width, key.height);
      key_expected.clear(kSky);
      late.gpu_lod.draw(key, options.high_error, key_expected);
      EXPECT_EQ(sprite.spriteTarget()->readColor().pixels(), key_expected.readColor().pixels()) << "frame " << f;
      ++checked;
    }
    expected.clear(kSky);
    late.gpu_lod.draw(camera, options.high_error, expected);
    worst_psnr = std::min(worst_psnr, image::psnr(frame.readColor(), expected.readColor()));
  }
  const LodSpriteCounters& c = sprite.counters();
  std::printf("%zu fresh, %zu rendered ahead (%zu used, %zu dropped), %zu slice frames, largest slice %lu "
              "triangles; worst PSNR against the CDLOD high frame %.1f dB\n",
              c.fresh_keyframes, c.predicted_rendered, c.predicted_used, c.predicted_discarded, slices,
              (unsigned long)slice_max, worst_psnr);
  EXPECT_GT(first_fresh, 0u) << "the first keyframe is taken when it pays, after a high frame or more";
  EXPECT_EQ(c.fresh_keyframes, 1u);
  EXPECT_GE(c.predicted_used, 2u);
  EXPECT_EQ(checked, c.predicted_used);
  EXPECT_GE(slices, c.predicted_rendered * 2) << "each keyframe rendered ahead is spread over frames";
  EXPECT_GT(worst_psnr, 25.0);
}

// predict_late where a high frame costs little more than a sprite frame (1.2 against 1 ms by the model, a keyframe
// 2.2): the first switch from the high LOD waits for a keyframe rendered ahead in slices with the high frames before
// it, so that no frame of the flight draws a whole keyframe (where high frames are dear, the test above, the first
// keyframe is drawn whole at the switch).
TEST(LodSpriteGL, WhereHighFramesAreCheapTheSwitchWaitsForAKeyframeRenderedAhead) {
  TerrainCost cost = spritesPay();
  cost.gpu_high->base_ms = 1.2;
  cost.gpu_sprite->base_ms = 1.0;
  LateSlicedRun late(cost);
  LodSpriteRenderer& sprite = late.sprite;
  const LodSpriteOptions& options = late.options;
  const float top = late.top;
  gpu::RenderTarget frame(128, 128);
  size_t first_sprite = 0, slices_before = 0;
  for (size_t f = 0; f < 90; ++f) {
    const LodSpriteFrameInfo info = flightFrame(sprite, frame, top, 300.0f + 24.0f * float(f));
    EXPECT_EQ(info.keyframe_triangles, 0u) << "frame " << f << ": a whole keyframe";
    EXPECT_LE(info.error_px, options.epsilon + 1e-9) << "frame " << f;
    if (info.path == TerrainPath::Sprite && first_sprite == 0) {
      first_sprite = f;
      EXPECT_EQ(info.source, SpriteSource::Predicted);
      EXPECT_TRUE(info.switched);
    }
    if (first_sprite == 0 && info.ahead_slices > 0) {
      EXPECT_EQ(info.path, TerrainPath::High) << "frame " << f;
      ++slices_before;
    }
  }
  const LodSpriteCounters& c = sprite.counters();
  ASSERT_GT(first_sprite, 0u) << "sprites pay along the flight";
  EXPECT_GE(slices_before, 2u) << "the first keyframe's slices drawn with high frames";
  EXPECT_EQ(c.fresh_keyframes, 0u);
  EXPECT_EQ(c.switches, 1u);
  EXPECT_GE(c.predicted_used, 2u);
}

// predict_late: a frame that takes a keyframe rendered ahead measures that keyframe's error alone, not the current
// sprite's too, where the keyframe has less error than the current sprite had in the frame before; every other sprite
// frame measures the current sprite once.
TEST(LodSpriteGL, AKeyframeRenderedAheadIsTakenWithOneMeasure) {
  LateSlicedRun late(spritesPay());
  gpu::RenderTarget frame(128, 128);
  size_t early_takes = 0;
  for (size_t f = 0; f < 90; ++f) {
    const size_t before = late.sprite.errorCounters().measures;
    const LodSpriteFrameInfo info = flightFrame(late.sprite, frame, late.top, 300.0f + 24.0f * float(f));
    const size_t measures = late.sprite.errorCounters().measures - before;
    if (info.path != TerrainPath::Sprite || info.source == SpriteSource::Fresh) continue;
    EXPECT_EQ(measures, 1u) << "frame " << f << " " << spriteSourceName(info.source);
    if (info.source == SpriteSource::Predicted && !info.keyframe_due) {
      ++early_takes;
      EXPECT_LT(info.error_px, info.trigger_error_px) << "frame " << f;
    }
  }
  EXPECT_GE(early_takes, 2u);
}

// A trip that catches a keyframe rendered ahead with half of its slices drawn: the camera jumps ahead by twelve frames
// at once, faster than the schedule saw. Returns the trip's frame (keyframe_due false: no trip), and the fresh
// keyframes drawn before it and in all through `fresh_before` and `fresh_after`.
LodSpriteFrameInfo tripAfterAJump(LateSlicedRun& late, size_t& fresh_before, size_t& fresh_after) {
  gpu::RenderTarget frame(128, 128);
  float x = 300.0f;
  size_t run = 0;
  LodSpriteFrameInfo trip;
  for (size_t f = 0; f < 120; ++f) {
    x += 24.0f;
    const bool jump = run == 2;  // two slices of the four drawn
    if (jump) {
      x += 12.0f * 24.0f;
      fresh_before = late.sprite.counters().fresh_keyframes;
    }
    const LodSpriteFrameInfo info = flightFrame(late.sprite, frame, late.top, x);
    run = info.ahead_slices > 0 && late.sprite.counters().predicted_used > 0 ? run + 1 : 0;
    if (jump) {
      trip = info;
      break;
    }
  }
  fresh_after = late.sprite.counters().fresh_keyframes;
  return trip;
}

// The trip's last slices are drawn in its frame and the keyframe is taken, where a whole fresh keyframe was drawn
// before (on the 16,385^2 flight, keyframes one to three slices short of 8-11).
TEST(LodSpriteGL, ATripFinishesAKeyframeRenderedAheadInsteadOfDrawingAFreshOne) {
  LateSlicedRun late(spritesPay());  // a keyframe is many sprite frames, so it takes all 4 slices
  size_t fresh_before = 0, fresh_after = 0;
  const LodSpriteFrameInfo info = tripAfterAJump(late, fresh_before, fresh_after);
  ASSERT_TRUE(info.keyframe_due) << "no keyframe was rendered ahead after the first predicted one, or no trip";
  EXPECT_EQ(info.source, SpriteSource::Predicted) << spriteSourceName(info.source);
  EXPECT_EQ(info.keyframe_triangles, 0u) << "no whole keyframe";
  EXPECT_EQ(info.ahead_slices, 2u) << "its last two slices";
  EXPECT_LE(info.error_px, late.options.epsilon);
  EXPECT_EQ(late.sprite.counters().predicted_finished, 1u);
  EXPECT_EQ(fresh_after, fresh_before);
}

// "Covers the view" at a trip: a keyframe rendered ahead that covers the view at least as well as the sprite it
// replaces is taken, even where it covers less of it than at its own viewpoint (on the 16,385^2 flight's turns,
// 0.80-0.88 of the low-resolution nodes against 0.88-0.94 at creation, each refusal a whole keyframe of 95-100 ms).
// Here no keyframe can pass the test against its share at creation (reuse_coverage 1.5): the trip still takes the
// one rendered ahead, which was extrapolated to the camera's path and covers the new view better than the old sprite.
TEST(LodSpriteGL, AtATripAKeyframeRenderedAheadThatCoversTheViewAsWellAsTheOldSpriteIsTaken) {
  LateSlicedRun late(spritesPay(), 1.5);
  size_t fresh_before = 0, fresh_after = 0;
  const LodSpriteFrameInfo info = tripAfterAJump(late, fresh_before, fresh_after);
  ASSERT_TRUE(info.keyframe_due) << "no keyframe was rendered ahead after the first predicted one, or no trip";
  EXPECT_EQ(info.source, SpriteSource::Predicted) << spriteSourceName(info.source);
  EXPECT_EQ(info.keyframe_triangles, 0u) << "no whole keyframe";
  EXPECT_LE(info.error_px, late.options.epsilon);
  EXPECT_EQ(fresh_after, fresh_before);
  EXPECT_EQ(fresh_after, 1u) << "only the first keyframe drawn whole";
}

// predict_late with the magnification bound, approaching the terrain head-on: the magnification grows as the inverse
// of the distance, faster every frame, so a rate measured since the sprite was taken saw trips one to three frames
// before they came (the 16,385^2 flight's descent: the keyframe rendered ahead was then caught with slices left, or
// ready for a viewpoint the camera had not reached and covering too little of the view, and a whole keyframe was
// drawn). With the last frame's rate where it is faster, no frame after the first keyframe draws a whole keyframe.
TEST(LodSpriteGL, KeyframesRenderedAheadKeepUpWithAMagnificationThatGrowsFasterEveryFrame) {
  Scene scene(testFractal());
  GpuLodTerrain gpu_lod(scene.hf, scene.texture, CdlodOptions{8, 16, 0.2f});
  const TerrainCost cost = spritesPay();
  LodSpriteOptions options = lateSlicedOptions(gpu_lod, cost);
  options.max_magnification = 1.3;
  options.predict_chunks = 16;  // as the paged flight: slices as many as the frames left before the trip allow
  LodSpriteRenderer sprite(*scene.lod, *scene.renderer, 128, 128, options);
  const Vec3 target(1280.0f, 1280.0f, scene.hf.sample(1280.0, 1280.0));
  const Vec3 start(1280.0f, -1200.0f, scene.hf.maxHeight() + 900.0f);
  gpu::RenderTarget frame(128, 128);
  size_t first_fresh = 0, whole_after = 0;
  for (int f = 0; f < 45; ++f) {
    const Camera camera = makeCamera(start + (target - start) * (0.02f * float(f)), target);
    frame.clear(kSky);
    LodSpriteFrameInfo info;
    sprite.render(camera, frame, &info);
    if (std::getenv("FF_TERRAIN_DUMP"))
      std::printf("frame %d %s error %.3f magnification %.3f ahead %lu slices %zu whole %lu\n", f,
                  spriteSourceName(info.source), info.error_px, info.magnification,
                  (unsigned long)info.ahead_triangles, info.ahead_slices, (unsigned long)info.keyframe_triangles);
    if (info.keyframe_triangles > 0) {
      if (first_fresh == 0) first_fresh = size_t(f);
      else ++whole_after;
    }
    if (info.path == TerrainPath::Sprite) {
      EXPECT_LE(info.magnification, options.max_magnification) << "frame " << f;
    }
  }
  const LodSpriteCounters& c = sprite.counters();
  std::printf("%zu fresh, %zu rendered ahead (%zu used, %zu finished at a trip, %zu dropped)\n", c.fresh_keyframes,
              c.predicted_rendered, c.predicted_used, c.predicted_finished, c.predicted_discarded);
  ASSERT_GT(first_fresh, 0u);
  EXPECT_GE(c.predicted_used, 3u) << "the approach must take several keyframes for the test to mean much";
  EXPECT_EQ(whole_after, 0u);
  EXPECT_EQ(c.fresh_keyframes, 1u);
}

// LodSpriteOptions::max_magnification: approaching the terrain head-on, equation 2 alone lets the sprite be magnified
// (its texels cover more than a pixel: it blurs) while theta stays small; with the bound a keyframe is taken before
// the sprite is magnified past it, and the frames are nearer the CDLOD high frames.
TEST(LodSpriteGL, BoundedMagnificationTakesKeyframesBeforeTheSpriteBlurs) {
  Scene scene(testFractal());
  GpuLodTerrain gpu_lod(scene.hf, scene.texture, CdlodOptions{8, 16, 0.2f});
  TerrainCost cost = spritesPay();
  LodSpriteOptions options = gpuSpriteOptions(gpu_lod, cost);
  LodSpriteOptions bounded = options;
  bounded.max_magnification = 1.3;
  LodSpriteRenderer paper(*scene.lod, *scene.renderer, 128, 128, options);
  LodSpriteRenderer sharp(*scene.lod, *scene.renderer, 128, 128, bounded);
  const Vec3 target(1280.0f, 1280.0f, scene.hf.sample(1280.0, 1280.0));
  const Vec3 start(1280.0f, -1200.0f, scene.hf.maxHeight() + 900.0f);
  gpu::RenderTarget frame(128, 128), expected(128, 128);
  double mean_paper = 0.0, mean_sharp = 0.0, most_paper = 1.0, most_sharp = 1.0;
  for (int f = 0; f < 40; ++f) {
    const Camera camera = makeCamera(start + (target - start) * (0.018f * float(f)), target);
    expected.clear(kSky);
    gpu_lod.draw(camera, options.high_error, expected);
    const image::ColorImage high = expected.readColor();
    LodSpriteFrameInfo a, b;
    frame.clear(kSky);
    paper.render(camera, frame, &a);
    mean_paper += std::min(image::psnr(frame.readColor(), high), 99.0) / 40.0;
    frame.clear(kSky);
    sharp.render(camera, frame, &b);
    mean_sharp += std::min(image::psnr(frame.readColor(), high), 99.0) / 40.0;
    if (a.path == TerrainPath::Sprite) most_paper = std::max(most_paper, a.magnification);
    if (b.path == TerrainPath::Sprite) {
      most_sharp = std::max(most_sharp, b.magnification);
      EXPECT_LE(b.magnification, bounded.max_magnification) << "frame " << f;
    }
  }
  std::printf("equation 2 alone: %zu keyframes, sprite magnified %.2fx at most, mean PSNR %.1f dB; bounded to %.1fx: "
              "%zu keyframes, %.2fx at most, mean PSNR %.1f dB\n",
              paper.counters().fresh_keyframes, most_paper, mean_paper, bounded.max_magnification,
              sharp.counters().fresh_keyframes, most_sharp, mean_sharp);
  EXPECT_GT(most_paper, bounded.max_magnification) << "the path must magnify the sprite for the test to mean much";
  EXPECT_GT(sharp.counters().fresh_keyframes, paper.counters().fresh_keyframes);
  EXPECT_GT(mean_sharp, mean_paper + 0.5);
  LodSpriteOptions bad = bounded;
  bad.max_magnification = 0.9;
  EXPECT_THROW(LodSpriteRenderer(*scene.lod, *scene.renderer, 128, 128, bad), Error);
}

}  // namespace
}  // namespace farfield::terrain
