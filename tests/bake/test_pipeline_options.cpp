// The pipeline options: saved in the index and read back strictly (older index versions included), and bad
// options, cells and stage orders are errors.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "farfield/bake/pipeline.h"
#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/renderer.h"
#include "support/expect_error.h"
#include "support/test_support.h"
#include "bake/pipeline_fixture.h"

namespace farfield::bake {
using namespace farfield::extract;
namespace {

using pipeline_test::BakedCity;
using pipeline_test::bakedCity;
using pipeline_test::PipelineBakeTest;
using pipeline_test::smallOptions;
using test::expectErrorMentions;

TEST_F(PipelineBakeTest, OptionsSurviveTheIndexAndBadOptionsAreErrors) {
  const BakedCity& b = bakedCity();
  PipelineOptions o = smallOptions();
  o.error_px = 7.5;
  o.frame_width = 300;
  o.near_radius = 25.0f;
  o.mesh = LayerMesh::DepthMesh;
  o.views = LayerViews::Six;
  o.layer_order = urban::LayerOrder::Given;
  o.layer_choice = urban::LayerChoice::SmallestArea;
  o.events.points = urban::RepresentativePoints::HullVertices;
  o.events.landmark_boost = 3.0;
  const PipelineOptions back = pipelineOptionsFromJson(nlohmann::json::parse(pipelineOptionsToJson(o).dump()), "x");
  EXPECT_EQ(back.base.resolution, o.base.resolution);
  EXPECT_EQ(back.error_px, o.error_px);
  EXPECT_EQ(back.frame_width, o.frame_width);
  EXPECT_EQ(back.near_radius, o.near_radius);
  EXPECT_EQ(back.mesh, o.mesh);
  EXPECT_EQ(back.views, o.views);
  EXPECT_EQ(back.layer_order, o.layer_order);
  EXPECT_EQ(back.layer_choice, o.layer_choice);
  EXPECT_EQ(back.events.points, o.events.points);
  EXPECT_EQ(back.events.landmark_boost, o.events.landmark_boost);
  EXPECT_EQ(back.pvs.spacing, o.pvs.spacing);
  EXPECT_EQ(back.pvs.face_size, o.pvs.face_size);
  EXPECT_EQ(back.grid_cells, o.grid_cells);
  EXPECT_EQ(back.frame_height, o.frame_height);
  EXPECT_EQ(back.frame_fov_deg, o.frame_fov_deg);
  EXPECT_EQ(back.validity.step, o.validity.step);
  EXPECT_EQ(back.validity.laterals, o.validity.laterals);
  EXPECT_EQ(back.validity.below, o.validity.below);
  EXPECT_EQ(back.base.capture.detect_seen_from_below, o.base.capture.detect_seen_from_below);
  EXPECT_THROW(pipelineOptionsFromJson({{"error_px", "ten"}}, "x"), Error);
  EXPECT_THROW(pipelineOptionsFromJson({{"layer_mesh", "voxels"}}, "x"), Error);
  EXPECT_THROW(pipelineOptionsFromJson(nlohmann::json::array(), "x"), Error);
  // Saved whole, read back strictly: every key missing, changed to a wrong type or joined by an unknown one is an
  // error naming it; no silent default.
  const nlohmann::json whole = pipelineOptionsToJson(o);
  for (const auto& [key, value] : whole.items()) {
    nlohmann::json j = whole;
    j.erase(key);
    expectErrorMentions([&] { pipelineOptionsFromJson(j, "idx"); }, {"idx", key});
    j = whole;
    j[key] = nlohmann::json::array({"?"});
    expectErrorMentions([&] { pipelineOptionsFromJson(j, "idx"); }, {"idx", key});
  }
  {
    nlohmann::json j = whole;
    j["error_pixels"] = 3;
    expectErrorMentions([&] { pipelineOptionsFromJson(j, "idx"); }, {"idx", "unknown", "error_pixels"});
    j = whole;
    j["validity"]["stride"] = 3;
    expectErrorMentions([&] { pipelineOptionsFromJson(j, "idx"); }, {"idx", "unknown", "stride"});
    j = whole;
    j["grid_cells"] = 2.5;
    expectErrorMentions([&] { pipelineOptionsFromJson(j, "idx"); }, {"idx", "grid_cells", "integer"});
    j = whole;
    j["layer_order"] = "random";
    expectErrorMentions([&] { pipelineOptionsFromJson(j, "idx"); }, {"idx", "layer_order", "random"});
  }
  {
    // A version 2 store had no frame height, frame field of view or validity sampling: square frames at fov_deg.
    nlohmann::json v2 = whole;
    v2.erase("frame_height");
    v2.erase("frame_fov_deg");
    v2.erase("validity");
    v2.erase("station_spacing");
    EXPECT_THROW(pipelineOptionsFromJson(v2, "idx"), Error);
    // Versions 2 and 3 also said whether the mmi stage built the single mesh (now the single stage: the store's
    // reader maps it); required there, a boolean, and unknown in version 4.
    expectErrorMentions([&] { pipelineOptionsFromJson(v2, "idx", 2); }, {"idx", "single_mesh", "missing"});
    v2["single_mesh"] = "yes";
    expectErrorMentions([&] { pipelineOptionsFromJson(v2, "idx", 2); }, {"idx", "single_mesh", "true or false"});
    v2["single_mesh"] = false;
    const PipelineOptions old = pipelineOptionsFromJson(v2, "idx", 2);
    EXPECT_EQ(old.frame_height, old.frame_width);
    EXPECT_EQ(old.frame_fov_deg, o.base.fov_deg);
    nlohmann::json v3 = whole;
    expectErrorMentions([&] { pipelineOptionsFromJson(v3, "idx", 3); }, {"idx", "single_mesh", "missing"});
    v3["single_mesh"] = true;
    EXPECT_EQ(pipelineOptionsFromJson(v3, "idx", 3).mesh, o.mesh);
    expectErrorMentions([&] { pipelineOptionsFromJson(v3, "idx", 4); }, {"idx", "unknown", "single_mesh"});
  }

  const std::string dir = test::scratchDir("pipeline_bad").string();
  const auto bake = [&](const PipelineOptions& options, std::vector<uint32_t> cells) {
    bakePipeline(gpu::sharedHeadlessContext(), b.city.scene, *b.cells, std::move(cells),
                 parsePipeline("pvs,near-far,single,mmi"), options, dir);
  };
  PipelineOptions bad = smallOptions();
  bad.error_px = 0.0;
  EXPECT_THROW(bake(bad, {b.visited.front()}), Error);
  bad = smallOptions();
  bad.grid_cells = 129;  // more grid cells than pixels
  EXPECT_THROW(bake(bad, {b.visited.front()}), Error);
  bad = smallOptions();
  bad.near_radius = -1.0f;
  EXPECT_THROW(bake(bad, {b.visited.front()}), Error);
  EXPECT_THROW(bake(smallOptions(), {uint32_t(b.cells->cellCount())}), Error);  // no such cell
  // mmi before near-far, on the runner directly.
  const gpu::GpuScene gpu_scene(b.city.scene);
  PipelineRunner runner(b.city.scene, gpu_scene, *b.cells, smallOptions());
  CellWork work = runner.start(b.visited.front());
  expectErrorMentions([&] { runner.runStage(kStageMmi, work); }, {"mmi needs the near-far stage"});
  expectErrorMentions([&] { runner.runStage(kStageSingle, work); }, {"single needs the near-far stage"});
  EXPECT_THROW(runner.runStage("smi", work), Error);
  EXPECT_THROW(runner.start(uint32_t(b.cells->cellCount())), Error);
}

}  // namespace
}  // namespace farfield::bake
