// The governed mode: a budget no frame can keep puts every frame at the coarsest level, and that frame is the scene
// rendered at the level's size and scaled up (checked against a full-geometry render at that size, scaled up on the
// CPU); a budget every frame keeps leaves the frame itself. Budgets far from any frame's time make the decisions
// independent of the machine's speed.
#include "farfield/eval/governed_mode.h"

#include <gtest/gtest.h>

#include <map>
#include <string>

#include "eval/eval_test_scenes.h"
#include "eval/mode_harness.h"
#include "farfield/core/error.h"
#include "farfield/eval/frame_runner.h"
#include "farfield/eval/parallax_error.h"
#include "farfield/gpu/context.h"
#include "farfield/scene/builtin.h"
#include "farfield/scene/bvh.h"

namespace farfield::eval {
namespace {

constexpr int kSize = 64;

struct Harness : test::ModeHarness {
  explicit Harness(std::optional<double> t_max_ms) : ModeHarness(kSize) {
    context.t_max_ms = t_max_ms;
    context.options["governor_scales"] = "1,0.5";
    context.options["governor_lod_px"] = "0";  // resolution levels only (builtin:cubes has nothing to simplify)
  }
  // Full geometry at size x size, its ids scaled up to kSize x kSize by nearest sampling as a blit samples: the
  // destination pixel x reads source pixel floor((x + 0.5) * size / kSize).
  image::IdImage referenceIds(const Camera& camera, int size) {
    Camera small = camera;
    small.width = small.height = size;
    gpu::RenderTarget t(size, size);
    renderer->render(small, gpu_scene->drawItems(), t);
    const image::IdImage ids = t.readIds();
    image::IdImage out(kSize, kSize);
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x)
        out.at(x, y) = ids.at(int((x + 0.5) * size / kSize), int((y + 0.5) * size / kSize));
    return out;
  }
};

size_t differingPixels(const image::IdImage& a, const image::IdImage& b) {
  size_t n = 0;
  for (size_t i = 0; i < a.pixelCount(); ++i) n += a.pixels()[i] != b.pixels()[i];
  return n;
}

size_t objectPixels(const image::IdImage& a) {
  size_t n = 0;
  for (uint32_t id : a.pixels()) n += id != 0;
  return n;
}

TEST(GovernedMode, ABudgetNoFrameKeepsDrawsTheCoarsestLevelScaledUp) {
  Harness h(1e-6);  // a nanosecond: every prediction is over it
  auto governed = h.make("governed");
  FrameRunner runner(*h.renderer, *h.target);
  const gen::CameraPath path = test::sideWalkPath(4);
  runner.run(*governed, pathCamera(path, 0, kSize, kSize), 0);  // warm-up: the calibration
  for (size_t i = 0; i < path.frames.size(); ++i) {
    SCOPED_TRACE("path frame " + std::to_string(i));
    const Camera camera = pathCamera(path, i, kSize, kSize);
    const FrameRecord f = runner.run(*governed, camera, i);
    EXPECT_EQ(f.governor_level, 1);
    EXPECT_DOUBLE_EQ(f.bound_scale, 2.0);  // half the resolution: the bound kept is twice the promised one
    EXPECT_GT(f.corrected_ms, 1e-6);
    EXPECT_EQ(f.syncs, 0u);
    const image::IdImage ids = h.target->readIds();
    const image::IdImage half = h.referenceIds(camera, kSize / 2);
    const image::IdImage same = h.referenceIds(camera, kSize);
    EXPECT_GT(objectPixels(ids), 200u);
    EXPECT_LE(differingPixels(ids, half), ids.pixelCount() / 200) << "not the half-size frame scaled up";
    EXPECT_GT(differingPixels(ids, same), differingPixels(ids, half));  // and not the full-size frame
  }
  const std::map<std::string, double> info = governed->info();
  EXPECT_EQ(info.at("governor_level_1_frames"), 5.0);  // the warm-up and the 4 frames
  EXPECT_EQ(info.at("governor_relaxed_frames"), 5.0);
  EXPECT_GT(info.at("governor_calibration_s"), 0.0);
}

TEST(GovernedMode, ABudgetEveryFrameKeepsLeavesTheFrameItself) {
  Harness h(1e9);
  auto governed = h.make("governed");
  auto culled = h.make("culled");
  FrameRunner runner(*h.renderer, *h.target);
  const gen::CameraPath path = test::sideWalkPath(4);
  runner.run(*governed, pathCamera(path, 0, kSize, kSize), 0);
  runner.run(*culled, pathCamera(path, 0, kSize, kSize), 0);
  for (size_t i = 0; i < path.frames.size(); ++i) {
    SCOPED_TRACE("path frame " + std::to_string(i));
    const Camera camera = pathCamera(path, i, kSize, kSize);
    const FrameRecord g = runner.run(*governed, camera, i);
    const image::IdImage governed_ids = h.target->readIds();
    const FrameRecord c = runner.run(*culled, camera, i);
    EXPECT_EQ(g.governor_level, 0);
    EXPECT_DOUBLE_EQ(g.bound_scale, 1.0);
    EXPECT_EQ(c.governor_level, -1);  // no governor
    EXPECT_EQ(differingPixels(governed_ids, h.target->readIds()), 0u);
    EXPECT_EQ(g.syncs, 0u);
  }
}

// With gpu_occlusion=auto the calibration draws every level with the occlusion test on and off, and each level's
// chooser starts from those times (no first frames with the test on waiting for a probe); the frames stay those of
// the test always on.
TEST(GovernedMode, WithOcclusionAutoEachLevelsChooserStartsFromTheCalibration) {
  Harness h(1e9);
  h.context.options["gpu_occlusion"] = "auto";
  auto governed = h.make("governed");
  h.context.options["gpu_occlusion"] = "on";
  auto culled = h.make("culled");
  FrameRunner runner(*h.renderer, *h.target);
  const gen::CameraPath path = test::sideWalkPath(4);
  runner.run(*governed, pathCamera(path, 0, kSize, kSize), 0);  // warm-up: the calibration
  runner.run(*culled, pathCamera(path, 0, kSize, kSize), 0);
  std::map<std::string, double> info = governed->info();
  EXPECT_EQ(info.at("gpu_occlusion_kinds"), 2.0);  // full size and half size
  EXPECT_EQ(info.at("gpu_occlusion_started"), 2.0);
  for (size_t i = 0; i < path.frames.size(); ++i) {
    SCOPED_TRACE("path frame " + std::to_string(i));
    const Camera camera = pathCamera(path, i, kSize, kSize);
    runner.run(*governed, camera, i);
    const image::IdImage governed_ids = h.target->readIds();
    runner.run(*culled, camera, i);
    EXPECT_EQ(differingPixels(governed_ids, h.target->readIds()), 0u);
  }
  info = governed->info();
  EXPECT_EQ(info.at("gpu_occlusion_probes"), 0.0);  // four frames: the first probe is 120 frames after the start
}

// A frame the governor expects near its budget has no room for a probe of the other occlusion variant: with a budget
// no level keeps, no probe in 140 frames (the first is due 120 frames after the calibration); with room, one.
TEST(GovernedMode, FramesNearTheBudgetProbeNoOcclusionVariant) {
  const gen::CameraPath path = test::sideWalkPath(140);
  for (const double t_max : {1e-3, 1e9}) {
    SCOPED_TRACE("t_max " + std::to_string(t_max));
    Harness h(t_max);
    h.context.options["gpu_occlusion"] = "auto";
    auto governed = h.make("governed");
    FrameRunner runner(*h.renderer, *h.target);
    for (size_t i = 0; i < path.frames.size(); ++i) runner.run(*governed, pathCamera(path, i, kSize, kSize), i);
    const std::map<std::string, double> info = governed->info();
    if (t_max < 1.0) EXPECT_EQ(info.at("gpu_occlusion_probes"), 0.0);
    else EXPECT_GE(info.at("gpu_occlusion_probes"), 1.0);
  }
}

// Spheres of 8,192 triangles in a row going away from the eye: the far ones are simplified under a few pixels.
scene::Scene spheres() {
  scene::Scene scene;
  scene.addMaterial(scene::Material{});
  const uint32_t mesh = scene.addMesh(scene::makeSphere(3.0f, 128, 64));
  for (int i = 0; i < 8; ++i) {
    scene::Object object;
    object.parts.push_back({mesh, 0});
    object.transform = glm::translate(Mat4(1.0f), Vec3(float(i % 2) * 8.0f - 4.0f, 15.0f + 20.0f * float(i), 0.0f));
    scene.addObject(std::move(object));
  }
  return scene;
}

TEST(GovernedMode, SimplifiedGeometryDrawsFewerTrianglesWithinItsBound) {
  constexpr int kBig = 256;
  test::ModeHarness h(kBig, spheres());
  h.context.arena_slot->simplified_levels = true;  // as a governed mode asks
  auto culled = h.make("culled");
  ASSERT_TRUE(culled->setGeometryErrorPx(0.0));
  FrameRunner runner(*h.renderer, *h.target);
  gen::PathFrame f;
  f.eye = Vec3(0.0f, 0.0f, 2.0f);
  f.at = Vec3(0.0f, 100.0f, 0.0f);
  f.up = Vec3(0.0f, 0.0f, 1.0f);
  f.fov_y = float(degToRad(40.0));
  gen::CameraPath path;
  path.frames = {f, f};
  const Camera camera = pathCamera(path, 0, kBig, kBig);
  std::vector<uint64_t> triangles;
  std::vector<image::IdImage> ids;
  for (double px : {0.0, 2.0}) {
    ASSERT_TRUE(culled->setGeometryErrorPx(px));
    runner.run(*culled, camera, 0);
    triangles.push_back(runner.run(*culled, camera, 1).triangles);
    ids.push_back(h.target->readIds());
  }
  EXPECT_LT(triangles[1], triangles[0] * 3 / 4) << triangles[0] << " -> " << triangles[1];
  const double parallax = frameParallaxPx(ids[0], ids[1], h.scene.objects.size());
  EXPECT_LE(parallax, 2.0);
  // A mode that does not draw through the arena says so.
  EXPECT_FALSE(h.make("culled-cpu")->setGeometryErrorPx(1.0));
}

TEST(GovernedMode, ImpostorBoundsComeFirstAndTheCoarsestLevelKeepsTheLargestOfEveryBound) {
  Harness h(1e-6);
  h.context.options["governor_impostor_px"] = "4,8";  // levels 1 and 2: the mode again under 4 and 8 px
  h.context.options["governor_lod_px"] = "0,2";
  auto governed = h.make("governed");
  FrameRunner runner(*h.renderer, *h.target);
  const gen::CameraPath path = test::sideWalkPath(2);
  runner.run(*governed, pathCamera(path, 0, kSize, kSize), 0);
  const FrameRecord f = runner.run(*governed, pathCamera(path, 1, kSize, kSize), 1);
  const std::map<std::string, double> info = governed->info();
  // Full, impostors under 4 and 8 px, 2 px geometry (with 8 px impostors), then half resolution (with both).
  ASSERT_EQ(info.at("governor_levels"), 5.0);
  EXPECT_EQ(info.at("governor_level_1_impostor_px"), 4.0);
  EXPECT_EQ(info.at("governor_level_2_impostor_px"), 8.0);
  EXPECT_EQ(info.at("governor_level_3_lod_px"), 2.0);
  EXPECT_EQ(info.at("governor_level_3_impostor_px"), 8.0);
  EXPECT_EQ(f.governor_level, 4);
  EXPECT_DOUBLE_EQ(f.bound_scale, 16.0);  // max(1 px promised, 8 px impostors, 2 px geometry) at half resolution
}

// An arena a mode of the run made before without simplified levels (the viewer's culled, selected first) stays: the
// governed mode over it has no simplified level and says so, and asking for one is an error; before any arena, it
// asks for them, and the arena made next has them.
TEST(GovernedMode, AnArenaMadeWithoutSimplifiedLevelsIsGovernedWithoutThem) {
  Harness h(10.0);
  h.context.options.erase("governor_lod_px");
  auto culled = h.make("culled");  // makes the run's arena, without simplified levels
  ASSERT_TRUE(h.context.arena_slot->arena);
  auto governed = h.make("governed");
  EXPECT_FALSE(h.context.arena_slot->simplified_levels) << "the arena made before still has none";
  EXPECT_EQ(governed->info().at("governor_levels"), 2.0) << "the frame itself and half the resolution only";
  h.context.options["governor_lod_px"] = "0,2";
  EXPECT_THROW(createMode("governed", h.context), Error);

  Harness fresh(10.0);
  fresh.context.options.erase("governor_lod_px");
  auto first = fresh.make("governed");
  EXPECT_TRUE(fresh.context.arena_slot->simplified_levels);
  EXPECT_EQ(first->info().at("governor_levels"), 5.0) << "0, 1, 2 and 4 px, then half the resolution";
}

TEST(GovernedMode, BadOptionsAreClearErrors) {
  Harness h(std::nullopt);
  EXPECT_THROW(createMode("governed", h.context), Error);  // no --tmax
  h.context.options["governor_t_max_ms"] = "12";           // ... or the option
  EXPECT_NO_THROW(createMode("governed", h.context));
  h.context.options.erase("governor_t_max_ms");
  h.context.t_max_ms = 10.0;
  h.context.options["governor_scales"] = "0.5,1";
  EXPECT_THROW(createMode("governed", h.context), Error);
  h.context.options["governor_scales"] = "1,0.1";
  EXPECT_THROW(createMode("governed", h.context), Error);
  h.context.options["governor_scales"] = "1,0.5";
  h.context.options["governed"] = "governed";
  EXPECT_THROW(createMode("governed", h.context), Error);
  h.context.options["governed"] = "no-such-mode";
  EXPECT_THROW(createMode("governed", h.context), Error);
  h.context.options.erase("governed");
  h.context.options["governor_impostor_px"] = "4,2";  // must increase
  EXPECT_THROW(createMode("governed", h.context), Error);
  h.context.options["governor_impostor_px"] = "0";  // a bound of no pixels
  EXPECT_THROW(createMode("governed", h.context), Error);
}

}  // namespace
}  // namespace farfield::eval
