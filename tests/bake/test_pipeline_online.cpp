// A store whose single and mmi stages are left online: it holds the PVS and the split, and the runtime finishing
// it gives the same layers and single mesh as the bake of every stage.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "farfield/bake/pipeline.h"
#include "farfield/gpu/renderer.h"
#include "farfield/store/impostor_store.h"
#include "bake/pipeline_fixture.h"

namespace fs = std::filesystem;

namespace farfield::bake {
using namespace farfield::extract;
namespace {

using pipeline_test::BakedCity;
using pipeline_test::bakedCity;
using pipeline_test::PipelineBakeTest;

TEST_F(PipelineBakeTest, OnlineSingleAndMmiStoreHoldsPvsAndSplitAndTheRuntimeFinishesItIdentically) {
  const BakedCity& b = bakedCity();
  const store::StoreIndex full = store::readIndex(b.full_dir);
  const store::StoreIndex online = store::readIndex(b.online_dir);
  EXPECT_EQ(online.pipeline, (std::vector<std::string>{"pvs", "near-far", "single", "mmi"}));
  EXPECT_EQ(online.online, (std::vector<std::string>{"single", "mmi"}));
  ASSERT_EQ(online.cells.size(), full.cells.size());
  for (const store::CellEntry& e : online.cells) {
    ASSERT_TRUE(e.pipeline);
    EXPECT_TRUE(e.pipeline->has_pvs);
    EXPECT_TRUE(e.pipeline->has_split);
    EXPECT_FALSE(e.pipeline->has_mmi) << "cell " << e.half_edge;
    EXPECT_FALSE(e.pipeline->has_single) << "cell " << e.half_edge;
    EXPECT_TRUE(e.pipeline->layers.empty());
    EXPECT_TRUE(e.pipeline->single.views.empty());
  }
  // No image or mesh written, and the storage report says so.
  size_t files = 0;
  if (fs::is_directory(fs::path(b.online_dir) / "cells"))
    for ([[maybe_unused]] const auto& f : fs::directory_iterator(fs::path(b.online_dir) / "cells")) ++files;
  EXPECT_EQ(files, 0u);
  EXPECT_EQ(online.storage.at("written_bytes").get<uint64_t>(), 0u);
  EXPECT_EQ(b.online_report.cells.size(), b.full_report.cells.size());

  // The runtime's path: the runner resumed from the stored record, the online stages run; the same layers as the
  // bake's, for every cell.
  const gpu::GpuScene gpu_scene(b.city.scene);
  const PipelineOptions options = pipelineOptionsFromJson(online.options.at("pipeline"), "online index");
  PipelineRunner runner(b.city.scene, gpu_scene, *b.cells, options);
  EXPECT_DOUBLE_EQ(runner.threshold(), b.full_report.threshold_rad);
  for (const store::CellEntry& e : online.cells) {
    SCOPED_TRACE("cell " + std::to_string(e.half_edge));
    const store::CellEntry* baked = full.find(e.half_edge);
    ASSERT_NE(baked, nullptr);
    // The stages both bakes ran agree.
    EXPECT_EQ(e.pipeline->pvs, baked->pipeline->pvs);
    EXPECT_EQ(e.pipeline->near, baked->pipeline->near);
    EXPECT_EQ(e.pipeline->far, baked->pipeline->far);
    CellWork work = runner.resume(e.half_edge, *e.pipeline);
    EXPECT_EQ(work.candidates, e.pipeline->far);
    runner.runStages(online.online, work);
    const store::CellPipeline& r = work.result;
    ASSERT_TRUE(r.has_mmi);
    ASSERT_EQ(r.layers.size(), baked->pipeline->layers.size());
    for (size_t l = 0; l < r.layers.size(); ++l) {
      EXPECT_EQ(r.layers[l].objects, baked->pipeline->layers[l].objects) << "layer " << l;
      ASSERT_EQ(r.layers[l].views.size(), baked->pipeline->layers[l].views.size());
      for (size_t v = 0; v < r.layers[l].views.size(); ++v)
        EXPECT_EQ(r.layers[l].views[v].triangles, baked->pipeline->layers[l].views[v].triangles) << "layer " << l;
    }
    ASSERT_TRUE(r.has_single);
    EXPECT_EQ(r.single.objects, baked->pipeline->single.objects);
    ASSERT_EQ(r.single.views.size(), baked->pipeline->single.views.size());
    for (size_t v = 0; v < r.single.views.size(); ++v) {
      EXPECT_EQ(r.single.views[v].triangles, baked->pipeline->single.views[v].triangles) << "single view " << v;
      EXPECT_EQ(r.single.views[v].station, baked->pipeline->single.views[v].station) << "single view " << v;
    }
    EXPECT_EQ(r.single.validity.size(), baked->pipeline->single.validity.size());
    EXPECT_EQ(work.layer_views.size(), r.layers.size());
    EXPECT_EQ(work.single_views.size(), r.single.views.size());
    EXPECT_TRUE(work.layer_captures.empty());  // buildMeshes ran and freed them
    EXPECT_TRUE(work.single_captures.empty());
  }
}

}  // namespace
}  // namespace farfield::bake
