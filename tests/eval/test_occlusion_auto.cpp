// gpu_occlusion=auto (eval/gpu_culled_mode.h, runtime/faster_variant.h) through the harness: the frames equal the
// frames with occlusion culling always on, the chooser took the harness's measured times (it probed), and a bad value
// is an error naming the mode.
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <string>

#include "farfield/core/error.h"
#include "farfield/eval/frame_runner.h"
#include "farfield/eval/mode.h"
#include "farfield/gpu/context.h"
#include "farfield/scene/builtin.h"
#include "eval/eval_test_scenes.h"

namespace farfield::eval {
namespace {

TEST(OcclusionAuto, FramesEqualTheFramesWithOcclusionAlwaysOnAndTheChooserProbes) {
  const scene::Scene scene = scene::builtinScene("cubes");
  gpu::sharedHeadlessContext().makeCurrent();
  ModeRunResources with_auto(scene, 96, 64, {{"gpu_occlusion", "auto"}});
  ModeRunResources with_on(scene, 96, 64, {{"gpu_occlusion", "on"}});
  std::unique_ptr<Mode> a = createMode("culled", with_auto.context), o = createMode("culled", with_on.context);
  a->prepare(with_auto.context);
  o->prepare(with_on.context);
  FrameRunner run_a(with_auto.renderer, with_auto.target), run_o(with_on.renderer, with_on.target);
  const gen::CameraPath path = test::sideWalkPath(40);
  for (size_t k = 0; k < path.frames.size(); ++k) {
    const Camera camera = pathCamera(path, k, 96, 64);
    run_a.run(*a, camera, k);
    run_o.run(*o, camera, k);
    ASSERT_EQ(with_auto.target.readIds().pixels(), with_on.target.readIds().pixels()) << "frame " << k;
    ASSERT_EQ(with_auto.target.readColor().pixels(), with_on.target.readColor().pixels()) << "frame " << k;
  }
  const std::map<std::string, double> info = a->info();
  ASSERT_TRUE(info.count("gpu_occlusion_auto"));
  EXPECT_EQ(info.at("gpu_occlusion_kinds"), 1.0);
  // 40 measured frames: the first probe (after 4 measured frames with it on) drew frames without it.
  EXPECT_GE(info.at("gpu_occlusion_probes"), 1.0);
  EXPECT_LT(info.at("gpu_occlusion_frames"), 1.0);
  EXPECT_GT(info.at("gpu_occlusion_frames"), 0.0);
  EXPECT_FALSE(o->info().count("gpu_occlusion_auto"));
  EXPECT_GT(o->info().at("gpu_occlusion_culled"), 0.0);  // not vacuous: the front boxes hide parts of others
}

TEST(OcclusionAuto, ABadValueIsAnErrorNamingTheMode) {
  const scene::Scene scene = scene::builtinScene("cubes");
  gpu::sharedHeadlessContext().makeCurrent();
  ModeRunResources run(scene, 32, 32, {{"gpu_occlusion", "sometimes"}});
  try {
    createMode("culled", run.context);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("culled"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("gpu_occlusion must be on, off or auto"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace farfield::eval
