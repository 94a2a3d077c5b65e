#include "farfield/eval/cull_check.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "farfield/core/error.h"
#include "gpu/street_scene.h"
#include "support/test_support.h"

namespace farfield::eval {
namespace {

// A walk down the street canyon (gpu/street_scene.h), with a turn and a jump above the walls.
gen::CameraPath canyonWalk() {
  gen::CameraPath path;
  for (int k = 0; k < 24; ++k) {
    gen::PathFrame f;
    f.eye = Vec3(0.5f * std::sin(0.3f * float(k)), -50.0f + 4.0f * float(k), k == 16 ? 30.0f : 1.7f);
    f.at = f.eye + Vec3(0.3f * std::cos(0.2f * float(k)), 5.0f, k == 16 ? -3.0f : 0.0f);
    path.frames.push_back(f);
  }
  return path;
}

// The check passes on the GPU-culled frames, and fails, naming the frames, when the occlusion test is broken (boxes
// in front of the depth called hidden): the comparison sees a visible cluster dropped.
TEST(CullCheck, PassesAndCatchesABrokenOcclusionTest) {
  const scene::Scene scene = gpu::test::streetCanyonScene(true);
  const gen::CameraPath path = canyonWalk();
  CullCheckOptions options;
  options.width = 96;
  options.height = 64;
  const CullCheckResult good = runCullCheck(gpu::sharedHeadlessContext(), scene, path, options);
  ASSERT_EQ(good.frames.size(), path.frames.size());
  EXPECT_TRUE(good.passed);
  EXPECT_EQ(good.frames_differing, 0u);
  EXPECT_GE(good.psnr_db_min, 60.0);
  uint64_t triangles = 0;
  for (const CullCheckFrame& f : good.frames) triangles += f.reference_triangles;
  EXPECT_GT(triangles, 0u);

  options.cull.occlusion_margin = -0.5f;
  const CullCheckResult broken = runCullCheck(gpu::sharedHeadlessContext(), scene, path, options);
  EXPECT_FALSE(broken.passed);
  EXPECT_GT(broken.frames_differing, 0u);

  const std::string dir = test::scratchDir("cull_check").string();
  writeCullCheck(broken, "canyon", "walk", dir);
  std::ifstream in(std::filesystem::path(dir) / "cullcheck.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("passed"), false);
  EXPECT_EQ(j.at("per_frame").size(), path.frames.size());
  EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(dir) / "cullcheck.md"));

  EXPECT_THROW(runCullCheck(gpu::sharedHeadlessContext(), scene, gen::CameraPath{}, options), Error);
}

}  // namespace
}  // namespace farfield::eval
