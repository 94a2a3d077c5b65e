// Pipeline store index round trip (per-cell "pipeline" records of Decoret et al. 1999's extractor pipeline): every
// field survives memory, printed text and the files; online stages and Sillion cells keep their shape.
#include <gtest/gtest.h>

#include <string>

#include "farfield/store/impostor_store.h"
#include "store/pipeline_store_fixture.h"
#include "support/test_support.h"

namespace farfield::store {
namespace {

using pipeline_store_test::expectSameCamera;
using pipeline_store_test::onlineCell;
using pipeline_store_test::pipelineIndex;

void expectSameCheck(const FileCheck& a, const FileCheck& b, const std::string& where) {
  EXPECT_EQ(a.known, b.known) << where;
  EXPECT_EQ(a.crc32, b.crc32) << where;
  EXPECT_EQ(a.bytes, b.bytes) << where;
}

void expectSameLayer(const StoredLayer& a, const StoredLayer& b, const std::string& where) {
  EXPECT_EQ(a.objects, b.objects) << where;
  ASSERT_EQ(a.views.size(), b.views.size()) << where;
  for (size_t v = 0; v < a.views.size(); ++v) {
    const std::string at = where + " view " + std::to_string(v);
    const StoredView &x = a.views[v], &y = b.views[v];
    expectSameCamera(x.camera, y.camera, at);
    EXPECT_EQ(x.texture, y.texture) << at;
    EXPECT_EQ(x.mesh, y.mesh) << at;
    EXPECT_EQ(x.ids, y.ids) << at;
    expectSameCheck(x.texture_check, y.texture_check, at + " texture");
    expectSameCheck(x.mesh_check, y.mesh_check, at + " mesh");
    expectSameCheck(x.ids_check, y.ids_check, at + " ids");
    EXPECT_EQ(x.triangles, y.triangles) << at;
    EXPECT_EQ(x.vertices, y.vertices) << at;
    EXPECT_EQ(x.data_pixels, y.data_pixels) << at;
    EXPECT_EQ(x.render_ms, y.render_ms) << at;
    EXPECT_EQ(x.build_ms, y.build_ms) << at;
  }
  for (size_t v = 0; v < a.views.size(); ++v) EXPECT_EQ(a.views[v].station, b.views[v].station) << where;
  ASSERT_EQ(a.validity.size(), b.validity.size()) << where;
  for (size_t k = 0; k < a.validity.size(); ++k) {
    const impostor::ValidityRegion &x = a.validity[k], &y = b.validity[k];
    EXPECT_EQ(x.origin, y.origin) << where;
    EXPECT_EQ(x.end, y.end) << where;
    EXPECT_EQ(x.half_width, y.half_width) << where;
    EXPECT_EQ(x.below, y.below) << where;
    EXPECT_EQ(x.above, y.above) << where;
    EXPECT_EQ(x.back, y.back) << where;
    EXPECT_EQ(x.step, y.step) << where;
    EXPECT_EQ(x.laterals, y.laterals) << where;
    EXPECT_EQ(x.envelope, y.envelope) << where;
  }
}

void expectSameIndex(const StoreIndex& a, const StoreIndex& b) {
  EXPECT_EQ(a.version, b.version);
  EXPECT_EQ(a.generation, b.generation);
  EXPECT_EQ(a.techniques, b.techniques);
  EXPECT_EQ(a.streets, b.streets);
  expectSameCheck(a.streets_check, b.streets_check, "streets");
  EXPECT_EQ(a.scene, b.scene);
  EXPECT_EQ(a.scene_objects, b.scene_objects);
  EXPECT_EQ(a.local_model, b.local_model);
  EXPECT_EQ(a.cell_lookup, b.cell_lookup);
  EXPECT_EQ(a.options, b.options);
  EXPECT_EQ(a.pipeline, b.pipeline);
  EXPECT_EQ(a.online, b.online);
  EXPECT_EQ(a.storage, b.storage);
  ASSERT_EQ(a.cells.size(), b.cells.size());
  for (size_t k = 0; k < a.cells.size(); ++k) {
    const CellEntry &x = a.cells[k], &y = b.cells[k];
    const std::string at = "cell " + std::to_string(x.half_edge);
    EXPECT_EQ(x.half_edge, y.half_edge);
    expectSameCamera(x.camera, y.camera, at);
    EXPECT_EQ(x.local_objects, y.local_objects) << at;
    EXPECT_EQ(x.distant_objects, y.distant_objects) << at;
    EXPECT_EQ(x.data_pixels, y.data_pixels) << at;
    EXPECT_EQ(x.render_ms, y.render_ms) << at;
    EXPECT_EQ(x.texture, y.texture) << at;
    EXPECT_EQ(x.impostors.size(), y.impostors.size()) << at;
    ASSERT_EQ(x.pipeline.has_value(), y.pipeline.has_value()) << at;
    if (!x.pipeline) continue;
    const CellPipeline &p = *x.pipeline, &q = *y.pipeline;
    EXPECT_EQ(p.has_pvs, q.has_pvs) << at;
    EXPECT_EQ(p.pvs, q.pvs) << at;
    EXPECT_EQ(p.pvs_samples, q.pvs_samples) << at;
    EXPECT_EQ(p.pvs_ms, q.pvs_ms) << at;
    EXPECT_EQ(p.has_split, q.has_split) << at;
    EXPECT_EQ(p.near, q.near) << at;
    EXPECT_EQ(p.far, q.far) << at;
    EXPECT_EQ(p.has_single, q.has_single) << at;
    EXPECT_EQ(p.has_mmi, q.has_mmi) << at;
    EXPECT_EQ(p.threshold_rad, q.threshold_rad) << at;
    EXPECT_EQ(p.event_edges, q.event_edges) << at;
    EXPECT_EQ(p.max_weight_rad, q.max_weight_rad) << at;
    EXPECT_EQ(p.weights_ms, q.weights_ms) << at;
    ASSERT_EQ(p.layers.size(), q.layers.size()) << at;
    for (size_t l = 0; l < p.layers.size(); ++l)
      expectSameLayer(p.layers[l], q.layers[l], at + " layer " + std::to_string(l));
    expectSameLayer(p.single, q.single, at + " single");
  }
}

TEST(PipelineStoreTest, IndexRoundTripKeepsEveryField) {
  const StoreIndex index = pipelineIndex();
  // In memory, and through the text the bake writes (numbers must survive printing).
  expectSameIndex(indexFromJson(indexToJson(index), "memory"), index);
  const std::string text = indexToJson(index).dump(1);
  expectSameIndex(indexFromJson(nlohmann::json::parse(text), "text"), index);
  // And through the files (readIndex checks the streets file: it must be there).
  const std::string dir = test::scratchDir("pipeline_store_round_trip").string();
  StoreIndex with_streets = index;
  writeStreets(dir, with_streets, "{\"junctions\": [], \"streets\": []}\n");
  EXPECT_EQ(with_streets.streets, "g4000000007.streets.json");
  writeIndex(dir, with_streets);
  const StoreIndex read = readIndex(dir);
  expectSameIndex(read, with_streets);
  // The record names (not stored) are set from where each view is.
  EXPECT_EQ(read.cells[0].pipeline->layers[1].views[2].record, "cell 4: mmi layer 1 view 2");
  EXPECT_EQ(read.cells[1].pipeline->single.views[0].record, "cell 9: single mesh view 0");
  EXPECT_EQ(read.version, kIndexVersion);
  EXPECT_EQ(kIndexVersion, 4);
  // Version 4: the single mesh is the single stage's record, beside mmi, which no longer holds it.
  const nlohmann::json written = indexToJson(index);
  EXPECT_TRUE(written["cells"][0]["pipeline"].contains("single"));
  EXPECT_FALSE(written["cells"][0]["pipeline"]["mmi"].contains("single"));
  EXPECT_EQ(written["pipeline"], nlohmann::json({"pvs", "near-far", "single", "mmi"}));

  // A store with the single and mmi stages left online: cells have pvs and split, no single mesh, no mmi.
  StoreIndex online = pipelineIndex();
  online.online = {"single", "mmi"};
  online.cells = {onlineCell(3), onlineCell(5)};
  const StoreIndex online_read = indexFromJson(nlohmann::json::parse(indexToJson(online).dump()), "online");
  expectSameIndex(online_read, online);
  ASSERT_TRUE(online_read.cells[0].pipeline);
  EXPECT_FALSE(online_read.cells[0].pipeline->has_mmi);
  EXPECT_FALSE(online_read.cells[0].pipeline->has_single);
  EXPECT_TRUE(online_read.cells[0].pipeline->layers.empty());

  // A Sillion cell (no pipeline record) stays without one.
  StoreIndex mixed = pipelineIndex();
  mixed.cells[1].pipeline.reset();
  const StoreIndex mixed_read = indexFromJson(indexToJson(mixed), "mixed");
  EXPECT_FALSE(mixed_read.cells[1].pipeline.has_value());
  EXPECT_TRUE(mixed_read.cells[0].pipeline.has_value());
}

}  // namespace
}  // namespace farfield::store
