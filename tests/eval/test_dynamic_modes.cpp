// eval/dynamic_modes.h (GL): on a small forest the billboard, dynamic-shade, dynamic-schaufler, layered and warp
// modes run frames of a short walk through the harness's frame runner and each frame stays close to the
// full-geometry frame; bad options and a scene without trees are errors naming them.
#include "farfield/eval/dynamic_modes.h"

#include <gtest/gtest.h>

#include "farfield/core/error.h"
#include "farfield/eval/frame_runner.h"
#include "farfield/eval/impostor_mode.h"
#include "farfield/gen/vegetation.h"
#include "farfield/gpu/context.h"
#include "farfield/image/metrics.h"

namespace farfield::eval {
namespace {

// An 80 m forest of small trees (60 leaf triangles each).
scene::Scene smallForest(int trees, uint64_t seed) {
  gen::ForestOptions fo;
  fo.size = 80.0f;
  fo.trees = trees;
  fo.tree.leaves = 60;
  fo.seed = seed;
  return gen::generateForest(fo);
}

TEST(DynamicModesGl, RunOnAForestCloseToTheFullFrames) {
  registerImpostorModes();
  const scene::Scene forest = smallForest(30, 4);
  gpu::sharedHeadlessContext().makeCurrent();
  ModeRunResources run(forest, 160, 96, {{"error_px", "4"}, {"warp_interval", "3"}, {"audit", "50"}});
  FrameRunner runner(run.renderer, run.target);
  gpu::RenderTarget reference(160, 96);
  for (const std::string name : {"billboard", "dynamic-shade", "dynamic-schaufler", "layered", "warp"}) {
    std::unique_ptr<Mode> mode = createMode(name, run.context);
    mode->prepare(run.context);
    double worst = 99.0;
    for (size_t k = 0; k < 5; ++k) {
      Camera cam;
      cam.width = 160;
      cam.height = 96;
      cam.eye = Vec3(-60.0f + 2.0f * float(k), -60.0f, 25.0f);
      cam.at = Vec3(0, 0, 0);
      runner.run(*mode, cam, k);
      const image::ColorImage got = run.target.readColor();
      run.renderer.render(cam, run.gpu_scene.drawItems(), reference);
      worst = std::min(worst, image::psnr(got, reference.readColor()));
    }
    std::printf("%s: worst PSNR %.1f dB over 5 frames\n", name.c_str(), worst);
    // The warp forward-splats pixels: a leaf cloud magnified by the motion keeps cracks the second image misses.
    EXPECT_GT(worst, name == "warp" ? 18.0 : 26.0) << name;
    const std::map<std::string, double> info = mode->info();
    EXPECT_TRUE(info.count("regenerations_per_frame")) << name;
  }
  ModeContext bad = run.context;
  bad.options["billboard_kind"] = "conical";
  EXPECT_THROW(createMode("billboard", bad), Error);
  scene::Scene treeless = forest;
  for (scene::Object& o : treeless.objects) o.name = "bush";
  ModeRunResources bare(treeless, 64, 64, {});
  EXPECT_THROW(createMode("billboard", bare.context)->prepare(bare.context), Error);
}

// The image cache's geometry drawn by the GPU-driven frame (geometry=gpu, the default): its frames are its CPU path's
// without occlusion culling (the same images, the same regenerations, the geometry culled and drawn by the GPU), and
// a frame that regenerates no image waits for nothing, where the CPU path's occlusion culling reads depth back.
TEST(DynamicModesGl, TheImageCacheOnTheGpuDrawsWhatItsCpuPathDraws) {
  registerImpostorModes();
  const scene::Scene forest = smallForest(30, 4);
  gpu::sharedHeadlessContext().makeCurrent();
  // pay_back off and no t_max: every invalid image is regenerated, whatever each run's fitted cost model says.
  const std::map<std::string, std::string> common{{"error_px", "4"}, {"pay_back", "off"}};
  auto with = [&](std::map<std::string, std::string> more) {
    more.insert(common.begin(), common.end());
    return more;
  };
  for (const std::string name : {"dynamic-shade", "layered"}) {
    SCOPED_TRACE(name);
    ModeRunResources on_gpu(forest, 160, 96, common);
    ModeRunResources on_cpu(forest, 160, 96, with({{"geometry", "cpu"}, {"occlusion", "off"}}));
    ModeRunResources occluded(forest, 160, 96, with({{"geometry", "cpu"}}));
    std::unique_ptr<Mode> g = createMode(name, on_gpu.context), c = createMode(name, on_cpu.context),
                          o = createMode(name, occluded.context);
    g->prepare(on_gpu.context);
    c->prepare(on_cpu.context);
    o->prepare(occluded.context);
    FrameRunner run_g(on_gpu.renderer, on_gpu.target), run_c(on_cpu.renderer, on_cpu.target),
        run_o(occluded.renderer, occluded.target);
    double worst = 99.0;
    for (size_t k = 0; k < 6; ++k) {
      SCOPED_TRACE("frame " + std::to_string(k));
      Camera cam;
      cam.width = 160;
      cam.height = 96;
      // Each eye twice: the second frame finds every image valid and regenerates none.
      cam.eye = Vec3(-60.0f + 6.0f * float(k / 2), -60.0f, 25.0f);
      cam.at = Vec3(0, 0, 0);
      const FrameRecord fg = run_g.run(*g, cam, k);
      const image::ColorImage got = on_gpu.target.readColor();
      run_c.run(*c, cam, k);
      const FrameRecord fo = run_o.run(*o, cam, k);
      worst = std::min(worst, image::psnr(got, on_cpu.target.readColor()));
      ASSERT_TRUE(fg.counted && fo.counted);
      if (k % 2 == 1) {
        EXPECT_FALSE(g->info().count("regenerations_at_frame_" + std::to_string(k)));
        EXPECT_EQ(fg.syncs, 0u);
        EXPECT_GE(fo.syncs, 1u);
      }
    }
    std::printf("%s on the GPU: worst PSNR %.1f dB against its CPU path\n", name.c_str(), worst);
    EXPECT_GT(worst, 50.0);
    const std::map<std::string, double> gi = g->info(), ci = c->info();
    EXPECT_EQ(gi.at("geometry_gpu"), 1.0);
    EXPECT_EQ(ci.at("geometry_gpu"), 0.0);
    EXPECT_GT(gi.at("gpu_triangles"), 0.0);  // the geometry went through the GPU culler
    EXPECT_GT(gi.at("regenerations_per_frame"), 0.0);
    for (const char* key : {"regenerations_per_frame", "images_per_frame", "invalid_as_geometry_per_frame"})
      EXPECT_EQ(gi.at(key), ci.at(key)) << key;
  }
}

// The billboard mode's geometry is occlusion-culled like the culled mode's, on the GPU (the default) or the CPU: exact,
// so its frames equal the frames drawn without it, from eyes among the trees where near trunks and crowns hide others.
TEST(DynamicModesGl, BillboardOcclusionCullingLeavesTheFrameAsItWas) {
  registerImpostorModes();
  const scene::Scene forest = smallForest(60, 6);
  gpu::sharedHeadlessContext().makeCurrent();
  for (const char* geometry : {"gpu", "cpu"}) {
    SCOPED_TRACE(geometry);
    ModeRunResources on(forest, 160, 96, {{"error_px", "2"}, {"geometry", geometry}});
    ModeRunResources off(forest, 160, 96, {{"error_px", "2"}, {"geometry", geometry}, {"occlusion", "off"}});
    std::unique_ptr<Mode> with = createMode("billboard", on.context), without = createMode("billboard", off.context);
    with->prepare(on.context);
    without->prepare(off.context);
    FrameRunner run_on(on.renderer, on.target), run_off(off.renderer, off.target);
    for (size_t k = 0; k < 4; ++k) {
      Camera cam;
      cam.width = 160;
      cam.height = 96;
      cam.eye = Vec3(-30.0f + 12.0f * float(k), -20.0f, 3.0f);
      cam.at = Vec3(0, 20, 3);
      run_on.run(*with, cam, k);
      run_off.run(*without, cam, k);
      EXPECT_EQ(on.target.readColor().pixels(), off.target.readColor().pixels()) << "frame " << k;
    }
    const std::map<std::string, double> info = with->info();
    const std::string key = std::string(geometry) == "gpu" ? "gpu_occlusion_culled" : "occlusion_hidden_items_per_frame";
    ASSERT_TRUE(info.count(key)) << key;
    EXPECT_GT(info.at(key), 0.0);  // not vacuous: something was behind the near trees
    EXPECT_EQ(with->info().at("geometry_gpu"), std::string(geometry) == "gpu" ? 1.0 : 0.0);
    if (std::string(geometry) == "cpu") EXPECT_FALSE(without->info().count(key));
    else EXPECT_EQ(without->info().at(key), 0.0);
    std::printf("billboard occlusion (%s): %.1f hidden a frame\n", geometry, info.at(key));
  }
}

}  // namespace
}  // namespace farfield::eval
