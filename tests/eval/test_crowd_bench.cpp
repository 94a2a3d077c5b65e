// The crowd bench end to end on a tiny city and crowd: crowd-geometry draws what the reference draws (identical
// frames), the impostor modes differ from it and draw impostors, speedups are relative to crowd-geometry, and the
// report files are written; bad options are errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/eval/crowd_bench.h"
#include "farfield/gpu/context.h"
#include "support/test_support.h"

using namespace farfield;

namespace {

// The bench runs on the real models beside the repository: every test is skipped without them.
class CrowdBench : public ::testing::Test {
 protected:
  void SetUp() override {
    FF_SHARED_FILE_OR_SKIP(man_glb, "models/CesiumMan.glb");
    FF_SHARED_FILE_OR_SKIP(fox_glb, "models/Fox.glb");
    models_ = {man_glb.string(), fox_glb.string()};
  }

  eval::CrowdBenchOptions tinyOptions() const {
    eval::CrowdBenchOptions o;
    o.blocks = 10;
    o.detail = 0;
    o.agent_counts = {60};
    o.paths = {"pedestrian"};
    o.frames = 3;
    o.frame_step = 10;
    o.width = o.height = 64;
    o.models = models_;
    o.runtime.grid.azimuths = 8;
    o.runtime.grid.elevations = 2;
    o.runtime.frames = 2;
    o.runtime.palette_poses = 4;
    o.samples = 0;
    return o;
  }

  std::vector<std::string> models_;
};

}  // namespace

TEST_F(CrowdBench, GeometryModeEqualsTheReferenceAndImpostorModesAreMeasuredAgainstIt) {
  eval::CrowdBenchOptions o = tinyOptions();
  o.out_dir = test::scratchDir("crowd_bench").string();
  const eval::CrowdBenchResult r = eval::runCrowdBench(gpu::sharedHeadlessContext(), o);
  ASSERT_EQ(r.runs.size(), 1u);
  const eval::CrowdRun& run = r.runs[0];
  ASSERT_EQ(run.modes.size(), 3u);
  EXPECT_EQ(run.modes[0].name, "crowd-geometry");
  EXPECT_DOUBLE_EQ(run.modes[0].speedup, 1.0);
  EXPECT_GT(run.modes[0].in_view, 0.0) << "the walk must see agents for the comparison to mean anything";
  // The same policy as the reference: the same pixels.
  EXPECT_GE(run.modes[0].psnr_min, 99.0);
  EXPECT_EQ(run.modes[0].bad_share_mean, 0.0);
  EXPECT_EQ(run.modes[0].impostor_agents, 0.0);
  // crowd-impostor draws every agent in view as an impostor, and its pixels are not the reference's.
  EXPECT_EQ(run.modes[1].name, "crowd-impostor");
  EXPECT_DOUBLE_EQ(run.modes[1].impostor_agents, run.modes[1].in_view);
  EXPECT_LT(run.modes[1].psnr_mean, 99.0);
  EXPECT_GT(run.modes[1].speedup, 0.0);
  for (const char* file : {"crowd.json", "crowd.md"})
    EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(o.out_dir) / file)) << file;
  EXPECT_NE(r.markdown.find("crowd-mixed"), std::string::npos);
}

// With the agents hidden behind the city left out, every mode's agents are those in view less the hidden ones, and
// crowd-geometry still draws exactly what the (unculled) reference draws.
TEST_F(CrowdBench, AgentsCulledBehindTheCityLeaveTheGeometryFrameExact) {
  eval::CrowdBenchOptions o = tinyOptions();
  o.agent_occlusion = true;
  o.out_dir = test::scratchDir("crowd_bench_occlusion").string();
  const eval::CrowdBenchResult r = eval::runCrowdBench(gpu::sharedHeadlessContext(), o);
  ASSERT_EQ(r.runs.size(), 1u);
  for (const eval::CrowdModeResult& m : r.runs[0].modes) {
    EXPECT_NEAR(m.geometry_agents + m.impostor_agents + m.occluded, m.in_view, 1e-9) << m.name;
    EXPECT_EQ(m.occluded, r.runs[0].modes[0].occluded) << m.name << ": the same agents hide in every mode";
  }
  EXPECT_GE(r.runs[0].modes[0].psnr_min, 99.0);
  EXPECT_EQ(r.runs[0].modes[0].bad_share_mean, 0.0);
  EXPECT_NE(r.markdown.find("hidden behind the city"), std::string::npos);
}

// --compare-skinning adds the palette-skinned policies; they draw the baked reference's frames to rounding (the
// geometry mode's crowd pixels well above the impostors' PSNR) and the same agents as their baked counterparts.
TEST_F(CrowdBench, PaletteSkinningDrawsTheBakedPosesFrames) {
  eval::CrowdBenchOptions o = tinyOptions();
  o.compare_skinning = true;
  o.timing_passes = 2;
  const eval::CrowdBenchResult r = eval::runCrowdBench(gpu::sharedHeadlessContext(), o);
  ASSERT_EQ(r.runs.size(), 1u);
  const eval::CrowdRun& run = r.runs[0];
  ASSERT_EQ(run.modes.size(), 5u);
  EXPECT_EQ(run.modes[3].name, "crowd-geometry-palette");
  EXPECT_EQ(run.modes[4].name, "crowd-mixed-palette");
  EXPECT_GT(run.modes[0].in_view, 0.0);
  EXPECT_EQ(run.modes[3].geometry_agents, run.modes[0].geometry_agents);
  EXPECT_EQ(run.modes[4].geometry_agents, run.modes[2].geometry_agents);
  EXPECT_GT(run.modes[3].psnr_min, 45.0);
  EXPECT_LT(run.modes[3].bad_share_mean, 0.01);
  EXPECT_NEAR(run.modes[4].psnr_mean, run.modes[2].psnr_mean, 1.0);
  EXPECT_NE(r.markdown.find("skinning: baked poses"), std::string::npos);
  EXPECT_NE(r.markdown.find("fastest of 2 passes"), std::string::npos);
  for (const eval::CrowdModeResult& m : run.modes) EXPECT_GT(m.wall.median, 0.0) << m.name;
}

TEST_F(CrowdBench, BadOptionsAreErrors) {
  eval::CrowdBenchOptions o = tinyOptions();
  o.frames = 1;
  EXPECT_THROW(eval::runCrowdBench(gpu::sharedHeadlessContext(), o), Error);
  o = tinyOptions();
  o.models.clear();
  EXPECT_THROW(eval::runCrowdBench(gpu::sharedHeadlessContext(), o), Error);
  o = tinyOptions();
  o.paths = {"sideways"};
  EXPECT_THROW(eval::runCrowdBench(gpu::sharedHeadlessContext(), o), Error);
  o = tinyOptions();
  o.timing_passes = 0;
  EXPECT_THROW(eval::runCrowdBench(gpu::sharedHeadlessContext(), o), Error);
}
