// Pipeline stores (index version 3, per-cell "pipeline" records of Decoret et al. 1999's extractor pipeline): the index
// round trip keeps every field; every kind of damage to a record gives a farfield::Error naming the element; layer
// views whose files disagree with the index are refused.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <tuple>

#include "farfield/core/error.h"
#include "farfield/image/png_io.h"
#include "farfield/store/impostor_store.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::store {
namespace {

constexpr size_t kSceneObjects = 20;

// A camera with no round numbers in it, so a lossy float or double conversion anywhere shows.
Camera oddCamera(float seed) {
  Camera c;
  c.eye = Vec3(10.125f + seed, -3.3333333f * seed, 1.7000001f);
  c.at = Vec3(97.77777f + seed, 40.1f, 1.6999999f);
  c.up = Vec3(0.0f, 0.0f, 1.0f);
  c.fov_y = 1.0471975f + 0.001f * seed;
  c.width = 96 + int(seed);
  c.height = 64 + int(seed);
  c.near_plane = 0.5123f;
  c.far_plane = 19876.5f;
  return c;
}

StoredView oddView(uint32_t half_edge, size_t layer, size_t view, double seed, bool with_data = true) {
  StoredView v;
  v.camera = oddCamera(float(seed));
  const std::string stem = layerFileStem(half_edge, "mmi", layer, view);
  v.texture = with_data ? stem + ".png" : "";
  v.mesh = stem + ".ffmesh";
  v.triangles = with_data ? 1234 + size_t(seed) : 0;
  v.vertices = with_data ? 777 + size_t(seed) : 0;
  v.data_pixels = with_data ? 4321 + size_t(seed) : 0;
  v.render_ms = 1.0 / 3.0 + seed;
  v.build_ms = 2.0 / 7.0 + seed;
  // File checks with every byte of the CRC in use (no file behind them: the index round trip only).
  const auto check = [&](uint32_t salt) {
    FileCheck c;
    c.crc32 = 0xfedcba98u - salt - uint32_t(seed * 1000.0);
    c.bytes = 123456789012ull + salt;
    c.known = true;
    return c;
  };
  v.mesh_check = check(1);
  if (with_data) {
    v.texture_check = check(2);
    v.ids = stem + ".ids.png";
    v.ids_check = check(3);
  }
  return v;
}

// A validity region with no round numbers in it.
impostor::ValidityRegion oddRegion(float seed) {
  impostor::ValidityRegion r;
  r.origin = Vec3(10.125f + seed, -3.3333333f, 1.7000001f);
  r.end = Vec3(60.1f, -3.3f * seed, 1.6999999f);
  r.half_width = 5.4000001f;
  r.below = 0.6f;
  r.above = 0.3f;
  r.back = 2.0f;
  r.step = 1.0f + 0.1f * seed;
  r.laterals = 3;
  r.envelope = {0.0f, 0.00012345f, 0.0012345f * seed, 0.0123456f * seed, 0.0f, 3.1415926f};
  return r;
}

// A fully baked cell: PVS, split, two layers (the second with six views, one of them empty) and the single mesh.
CellEntry fullCell(uint32_t half_edge) {
  CellEntry e;
  e.half_edge = half_edge;
  e.camera = oddCamera(0.5f);
  e.local_objects = {1, 2, 3};
  e.distant_objects = 17;
  e.data_pixels = 0;
  e.render_ms = 12.3456789012345;
  CellPipeline p;
  p.has_pvs = true;
  p.pvs = {1, 2, 5, 7, 9, 11, 20};
  p.pvs_samples = 13;
  p.pvs_ms = 45.678901234567;
  p.has_split = true;
  p.near = {1, 2};
  p.far = {5, 7, 9, 11, 20};
  p.has_mmi = true;
  p.threshold_rad = 0.040906154343617;
  p.event_edges = 6;
  p.max_weight_rad = 0.71234567891234;
  p.weights_ms = 0.123456789;
  StoredLayer near_layer;
  near_layer.objects = {5, 9};
  near_layer.views = {oddView(half_edge, 0, 0, 1.0)};
  StoredLayer far_layer;
  far_layer.objects = {7, 11, 20};
  for (size_t v = 0; v < 6; ++v) far_layer.views.push_back(oddView(half_edge, 1, v, 2.0 + double(v), v != 3));
  near_layer.validity = {oddRegion(1.0f)};
  // The far layer from two stations, three views each.
  for (size_t v = 3; v < 6; ++v) far_layer.views[v].station = 1;
  far_layer.validity = {oddRegion(2.0f), oddRegion(2.5f)};
  p.layers = {near_layer, far_layer};
  p.has_single = true;
  p.single.validity = {oddRegion(3.0f)};
  p.single.objects = p.far;
  p.single.views = {oddView(half_edge, 0, 0, 9.0)};
  p.single.views[0].mesh = layerFileStem(half_edge, "smi", 0, 0) + ".ffmesh";
  p.single.views[0].texture = layerFileStem(half_edge, "smi", 0, 0) + ".png";
  p.single.views[0].ids = "";  // a view without per-texel ids
  p.single.views[0].ids_check = {};
  e.pipeline = p;
  return e;
}

// A cell whose single and mmi stages were left to the runtime.
CellEntry onlineCell(uint32_t half_edge) {
  CellEntry e = fullCell(half_edge);
  CellPipeline& p = *e.pipeline;
  p.has_mmi = false;
  p.threshold_rad = 0.0;
  p.event_edges = 0;
  p.max_weight_rad = 0.0;
  p.weights_ms = 0.0;
  p.layers.clear();
  p.has_single = false;
  p.single = {};
  return e;
}

StoreIndex pipelineIndex() {
  StoreIndex index;
  index.generation = 4000000007ull;  // more digits than the names' six
  index.streets = streetsFileName(index.generation);
  index.streets_check.crc32 = 0x89abcdefu;
  index.streets_check.bytes = 31337;
  index.streets_check.known = true;
  index.techniques = {};  // a pipeline store has no Sillion techniques
  index.scene = "city.glb";
  index.scene_objects = kSceneObjects;
  index.local_model = "junction";
  index.cell_lookup = "nearest";
  index.options = {{"pipeline", {{"resolution", 128}, {"error_px", 10.5}}}, {"block_margin", 5.25}};
  index.pipeline = {"pvs", "near-far", "single", "mmi"};
  index.online = {};
  index.storage = {{"written_bytes", 123456789}, {"mean_layers", 2.3333333333333335}};
  index.cells = {fullCell(4), fullCell(9)};
  // A cell with the PVS only (the record of a pipeline that stops after pvs is a valid record too).
  CellEntry pvs_only = onlineCell(30);
  pvs_only.pipeline->has_split = false;
  pvs_only.pipeline->near.clear();
  pvs_only.pipeline->far.clear();
  index.cells.push_back(pvs_only);
  return index;
}

void expectSameCheck(const FileCheck& a, const FileCheck& b, const std::string& where) {
  EXPECT_EQ(a.known, b.known) << where;
  EXPECT_EQ(a.crc32, b.crc32) << where;
  EXPECT_EQ(a.bytes, b.bytes) << where;
}

void expectSameCamera(const Camera& a, const Camera& b, const std::string& where) {
  EXPECT_EQ(a.eye, b.eye) << where;
  EXPECT_EQ(a.at, b.at) << where;
  EXPECT_EQ(a.up, b.up) << where;
  EXPECT_EQ(a.fov_y, b.fov_y) << where;
  EXPECT_EQ(a.width, b.width) << where;
  EXPECT_EQ(a.height, b.height) << where;
  EXPECT_EQ(a.near_plane, b.near_plane) << where;
  EXPECT_EQ(a.far_plane, b.far_plane) << where;
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

// Expects indexFromJson(j) to throw a farfield::Error whose message contains each of `parts`.
void expectIndexError(const nlohmann::json& j, const std::vector<std::string>& parts) {
  try {
    indexFromJson(j, "damaged/index.json");
    ADD_FAILURE() << "expected farfield::Error mentioning " << parts.front();
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("damaged/index.json"), std::string::npos) << msg;
    for (const std::string& part : parts)
      EXPECT_NE(msg.find(part), std::string::npos) << "'" << part << "' in: " << msg;
  }
}

// The index of pipelineIndex() as a version 2 or 3 bake wrote it: the mmi stage built the single mesh
// (options.pipeline.single_mesh) and held it inside its record; "single" is no stage.
StoreIndex legacyIndex(int version) {
  StoreIndex index = pipelineIndex();
  index.version = version;
  index.options["pipeline"]["single_mesh"] = true;
  return index;
}
nlohmann::json legacyJson(int version) { return indexToJson(legacyIndex(version)); }

TEST(PipelineStoreTest, Version2And3SingleMeshInsideMmiIsReadAsTheSingleStage) {
  for (const int version : {2, 3}) {
    SCOPED_TRACE("version " + std::to_string(version));
    const StoreIndex legacy = legacyIndex(version);
    const nlohmann::json j = legacyJson(version);
    // Written with that version's layout.
    EXPECT_EQ(j["pipeline"], nlohmann::json({"pvs", "near-far", "mmi"}));
    ASSERT_TRUE(j["cells"][0]["pipeline"]["mmi"].contains("single"));
    EXPECT_FALSE(j["cells"][0]["pipeline"].contains("single"));
    // Read as version 4 holds it: the stage list has single, each mmi record's single mesh is the single stage's.
    const StoreIndex read = indexFromJson(j, "old");
    EXPECT_EQ(read.version, version);
    EXPECT_EQ(read.pipeline, (std::vector<std::string>{"pvs", "near-far", "single", "mmi"}));
    for (size_t k = 0; k < 2; ++k) {
      const CellPipeline& p = *read.cells[k].pipeline;
      EXPECT_TRUE(p.has_single);
      ASSERT_EQ(p.single.views.size(), 1u);
      EXPECT_EQ(p.single.objects, legacy.cells[k].pipeline->single.objects);
      EXPECT_EQ(p.single.views[0].mesh, legacy.cells[k].pipeline->single.views[0].mesh);
    }
    EXPECT_FALSE(read.cells[2].pipeline->has_single);  // the cell without mmi record has none
    // mmi online: the single mesh was built online by it, so single is online too.
    StoreIndex online = legacyIndex(version);
    online.online = {"mmi"};
    online.cells = {onlineCell(3)};
    const StoreIndex online_read = indexFromJson(indexToJson(online), "old online");
    EXPECT_EQ(online_read.pipeline, (std::vector<std::string>{"pvs", "near-far", "single", "mmi"}));
    EXPECT_EQ(online_read.online, (std::vector<std::string>{"single", "mmi"}));
    // single_mesh false: the mmi stage built no single mesh; no single stage.
    nlohmann::json no_single = j;
    no_single["options"]["pipeline"]["single_mesh"] = false;
    const StoreIndex without = indexFromJson(no_single, "old");
    EXPECT_EQ(without.pipeline, (std::vector<std::string>{"pvs", "near-far", "mmi"}));
    EXPECT_FALSE(without.cells[0].pipeline->has_single);
    EXPECT_TRUE(without.cells[0].pipeline->single.views.empty());
    // single_mesh is required there, a boolean: not silently taken as either.
    nlohmann::json bad = j;
    bad["options"]["pipeline"].erase("single_mesh");
    expectIndexError(bad, {"options", "pipeline", "single_mesh"});
    bad["options"]["pipeline"]["single_mesh"] = 1;
    expectIndexError(bad, {"options", "pipeline", "single_mesh"});
    bad.erase("options");
    expectIndexError(bad, {"options", "pipeline", "single_mesh"});
    // Versions 2 and 3 had no single stage.
    bad = j;
    bad["pipeline"] = {"pvs", "near-far", "single", "mmi"};
    expectIndexError(bad, {"\"pipeline\"", "single", "version " + std::to_string(version)});
    bad = j;
    bad["cells"][0]["pipeline"]["single"] = bad["cells"][0]["pipeline"]["mmi"]["single"];
    expectIndexError(bad, {"cells[0]", "single", "no single stage"});
    // The mmi record must still hold the single mesh.
    bad = j;
    bad["cells"][0]["pipeline"]["mmi"].erase("single");
    expectIndexError(bad, {"pipeline.mmi", "single"});
  }
}

TEST(PipelineStoreTest, CorruptedPipelineRecordsNameTheElement) {
  const nlohmann::json good = indexToJson(pipelineIndex());
  ASSERT_NO_THROW(indexFromJson(good, "good"));
  const auto cell0 = [](nlohmann::json& j) -> nlohmann::json& { return j["cells"][0]["pipeline"]; };
  const std::string over = std::to_string(kSceneObjects + 1);

  // Object ids 0 and > scene_objects, in each id list of a record.
  struct IdList {
    std::vector<std::string> path;  // inside the cell's "pipeline"
    std::string element;            // what the message must name
  };
  const std::vector<IdList> lists{
      {{"pvs", "ids"}, "pipeline.pvs"},
      {{"split", "near"}, "pipeline.split"},
      {{"split", "far"}, "pipeline.split"},
      {{"mmi", "layers", "1", "objects"}, "layers[1]"},
      {{"single", "objects"}, "pipeline.single"},
  };
  for (const IdList& list : lists) {
    for (const uint64_t bad : {uint64_t(0), uint64_t(kSceneObjects + 1), uint64_t(1) << 40}) {
      nlohmann::json j = good;
      nlohmann::json* node = &cell0(j);
      for (const std::string& key : list.path)
        node = key == "1" ? &(*node)[size_t(1)] : &(*node)[key];
      ASSERT_TRUE(node->is_array()) << list.element;
      (*node)[0] = bad;
      SCOPED_TRACE(list.element + " id " + std::to_string(bad));
      expectIndexError(j, {"cells[0]", list.element, "outside 1.." + std::to_string(kSceneObjects)});
    }
    // Not ascending, and a repeat.
    for (const bool repeat : {false, true}) {
      nlohmann::json j = good;
      nlohmann::json* node = &cell0(j);
      for (const std::string& key : list.path)
        node = key == "1" ? &(*node)[size_t(1)] : &(*node)[key];
      ASSERT_GE(node->size(), 2u) << list.element;
      if (repeat)
        (*node)[1] = (*node)[0];
      else
        std::swap((*node)[0], (*node)[1]);
      SCOPED_TRACE(list.element + (repeat ? " repeated" : " descending"));
      expectIndexError(j, {"cells[0]", list.element, "ascending"});
    }
  }
  // A negative id and a non-number.
  {
    nlohmann::json j = good;
    cell0(j)["pvs"]["ids"][0] = -3;
    expectIndexError(j, {"pipeline.pvs", "outside"});
    j = good;
    cell0(j)["split"]["far"][0] = "5";
    expectIndexError(j, {"pipeline.split", "outside"});
  }

  // A view with triangles but no texture.
  {
    nlohmann::json j = good;
    cell0(j)["mmi"]["layers"][0]["views"][0]["texture"] = "";
    expectIndexError(j, {"cells[0]", "layers[0]", "views[0]", "no texture"});
    j = good;
    cell0(j)["single"]["views"][0]["texture"] = "";
    expectIndexError(j, {"cells[0]", "pipeline.single", "views[0]", "no texture"});
    // The empty view of the far layer (no triangles, no texture) is fine.
    j = good;
    ASSERT_EQ(cell0(j)["mmi"]["layers"][1]["views"][3]["texture"], "");
    EXPECT_NO_THROW(indexFromJson(j, "good"));
  }
  // File names escaping the store.
  for (const char* key : {"texture", "mesh"}) {
    nlohmann::json j = good;
    cell0(j)["mmi"]["layers"][1]["views"][2][key] = "cells/../../outside.bin";
    expectIndexError(j, {"layers[1]", "views[2]", key, ".."});
    j = good;
    cell0(j)["mmi"]["layers"][1]["views"][2][key] = "/etc/passwd";
    expectIndexError(j, {"layers[1]", "views[2]", key, "relative"});
  }
  // A view without a mesh file, a missing count, a bad camera.
  {
    nlohmann::json j = good;
    cell0(j)["mmi"]["layers"][0]["views"][0]["mesh"] = "";
    expectIndexError(j, {"layers[0]", "views[0]", "mesh"});
    j = good;
    cell0(j)["mmi"]["layers"][0]["views"][0].erase("triangles");
    expectIndexError(j, {"layers[0]", "views[0]", "triangles"});
    j = good;
    cell0(j)["mmi"]["layers"][0]["views"][0]["camera"]["fov_y"] = 0.0;
    expectIndexError(j, {"layers[0]", "views[0]", "camera"});
    j = good;
    cell0(j)["mmi"]["single"] = cell0(j)["single"];  // the layout of versions 2 and 3
    expectIndexError(j, {"pipeline.mmi", "single", "version 4"});
    j = good;
    cell0(j)["mmi"]["layers"] = 3;
    expectIndexError(j, {"pipeline.mmi", "layers"});
  }
  // Stage lists.
  {
    nlohmann::json j = good;
    j["online"] = {"smi"};
    expectIndexError(j, {"\"online\"", "smi", "not in the pipeline"});
    j = good;
    j["online"] = {"mmi"};
    j["pipeline"] = {"pvs", "near-far"};
    expectIndexError(j, {"\"online\"", "mmi"});
    j = good;
    j["pipeline"] = {"pvs", 3};
    expectIndexError(j, {"\"pipeline\""});
  }
  // Versions.
  {
    nlohmann::json j = good;
    j["version"] = kIndexVersion + 1;
    expectIndexError(j, {"version", std::to_string(kIndexVersion + 1)});
    j["version"] = 0;
    expectIndexError(j, {"version", "0"});
    j = legacyJson(3);
    j["version"] = 1;  // still read (with the layout of its time)
    EXPECT_NO_THROW(indexFromJson(j, "v1"));
    // Version 2 had no validity regions: read without them; version 3 requires them where a layer has views.
    j = legacyJson(3);
    cell0(j)["mmi"]["layers"][0].erase("validity");
    j["version"] = 2;
    EXPECT_NO_THROW(indexFromJson(j, "v2"));
    j["version"] = 3;
    expectIndexError(j, {"layers[0]", "validity"});
  }
  // File checks and the generation: version 3 (written with the layout of version 3: the single mesh inside mmi)
  // requires them, naming what is missing; version 2 reads without them.
  {
    const nlohmann::json good = legacyJson(3);
    using Node = std::function<nlohmann::json&(nlohmann::json&)>;
    const std::vector<std::tuple<Node, std::string, std::vector<std::string>>> needed{
        {[](nlohmann::json& j) -> nlohmann::json& { return j; }, "streets_crc32", {"top level"}},
        {[](nlohmann::json& j) -> nlohmann::json& { return j; }, "streets_bytes", {"top level"}},
        {[](nlohmann::json& j) -> nlohmann::json& { return j; }, "generation", {"top level"}},
        {[&](nlohmann::json& j) -> nlohmann::json& { return cell0(j)["mmi"]["layers"][0]["views"][0]; },
         "mesh_crc32", {"cells[0]", "layers[0]", "views[0]"}},
        {[&](nlohmann::json& j) -> nlohmann::json& { return cell0(j)["mmi"]["layers"][1]["views"][2]; },
         "texture_bytes", {"cells[0]", "layers[1]", "views[2]"}},
        {[&](nlohmann::json& j) -> nlohmann::json& { return cell0(j)["mmi"]["layers"][1]["views"][5]; },
         "ids_crc32", {"cells[0]", "layers[1]", "views[5]"}},
        {[&](nlohmann::json& j) -> nlohmann::json& { return cell0(j)["mmi"]["single"]["views"][0]; },
         "texture_crc32", {"cells[0]", "single", "views[0]"}},
    };
    for (const auto& [node, key, element] : needed) {
      SCOPED_TRACE(key);
      nlohmann::json j = good;
      ASSERT_TRUE(node(j).contains(key));
      node(j).erase(key);
      std::vector<std::string> parts = element;
      parts.push_back("missing \"" + key + "\"");
      expectIndexError(j, parts);
      // Version 2 needs no checks (but a check it has must be whole).
      j["version"] = 2;
      const std::string file_key = key.substr(0, key.rfind('_'));
      if (key != "generation") {
        ASSERT_TRUE(node(j).contains(file_key + "_crc32") || node(j).contains(file_key + "_bytes"));
        expectIndexError(j, {"missing \"" + key + "\""});
        node(j).erase(file_key + "_crc32");
        node(j).erase(file_key + "_bytes");
      }
      EXPECT_NO_THROW(indexFromJson(j, "v2"));
    }
    // A check that is not a CRC-32 or a size.
    nlohmann::json j = good;
    cell0(j)["mmi"]["layers"][0]["views"][0]["mesh_crc32"] = uint64_t(1) << 32;
    expectIndexError(j, {"views[0]", "mesh_crc32", "CRC-32"});
    cell0(j)["mmi"]["layers"][0]["views"][0]["mesh_crc32"] = -1;
    expectIndexError(j, {"views[0]", "mesh_crc32"});
    j = good;
    cell0(j)["mmi"]["layers"][0]["views"][0]["mesh_bytes"] = "12";
    expectIndexError(j, {"views[0]", "mesh_bytes"});
    // An empty view names no file and needs no check.
    j = good;
    ASSERT_FALSE(cell0(j)["mmi"]["layers"][1]["views"][3].contains("texture_crc32"));
    EXPECT_NO_THROW(indexFromJson(j, "good"));
  }
  // Version 4's own single record needs its checks too.
  {
    nlohmann::json j = good;
    cell0(j)["single"]["views"][0].erase("mesh_crc32");
    expectIndexError(j, {"cells[0]", "pipeline.single", "views[0]", "missing \"mesh_crc32\""});
  }
  // Validity regions.
  {
    nlohmann::json j = good;
    cell0(j)["mmi"]["layers"][1]["validity"][0]["envelope"] = {0.1, 0.2, 0.0, 0.1, 0.2, 0.15};
    expectIndexError(j, {"layers[1]", "validity", "decrease"});
    cell0(j)["mmi"]["layers"][1]["validity"][0]["envelope"] = {0.1, 0.2, 0.0, 0.1, 0.2};
    expectIndexError(j, {"layers[1]", "validity", "rows"});
    cell0(j)["mmi"]["layers"][1]["validity"][0]["laterals"] = 2;
    expectIndexError(j, {"layers[1]", "validity", "laterals"});
    j = good;
    cell0(j)["single"]["validity"][0]["step"] = 0.0;
    expectIndexError(j, {"pipeline.single", "validity", "step"});
    j = good;
    cell0(j)["mmi"]["layers"][0]["validity"][0]["envelope"] = {-0.1};
    expectIndexError(j, {"layers[0]", "validity", "envelope"});
    j = good;
    cell0(j)["mmi"]["layers"][0]["validity"][0].erase("origin");
    expectIndexError(j, {"layers[0]", "validity", "origin"});
    j = good;
    cell0(j)["mmi"]["layers"][1]["validity"].erase(1);  // two stations, one region
    expectIndexError(j, {"layers[1]", "validity", "station"});
    j = good;
    cell0(j)["mmi"]["layers"][1]["views"][4].erase("station");
    expectIndexError(j, {"layers[1]", "views[4]", "station"});
  }
}

// Layer view files: a mesh whose counts disagree with the index, a texture of the wrong size.
impostor::DepthMeshImpostor smallView(int size) {
  impostor::DepthMeshImpostor imp;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-50.0f, 50.0f), t(0.0f, 1.0f);
  for (int k = 0; k < 9; ++k) {
    imp.mesh.positions.emplace_back(u(rng), u(rng), u(rng));
    imp.mesh.uvs.emplace_back(t(rng), t(rng));
  }
  imp.mesh.indices = {0, 1, 2, 3, 4, 5, 6, 7, 8, 0, 4, 8};
  imp.triangle_ids = {5, 5, 9, 11};
  auto texture = std::make_shared<image::ColorImage>(size, size, image::Rgba8(10, 20, 30, 255));
  texture->at(1, 2) = image::Rgba8(200, 0, 0, 0);
  imp.texture = texture;
  // Per-texel ids with every byte of the 32 bits in use (the PNG packing must keep all four).
  auto ids = std::make_shared<image::IdImage>(size, size, 0u);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) ids->at(x, y) = (x + y) % 3 == 0 ? 0u : 0x01020304u * uint32_t(x + 1) + uint32_t(y);
  imp.ids = ids;
  imp.camera = oddCamera(0.0f);
  imp.camera.width = imp.camera.height = size;
  return imp;
}

TEST(PipelineStoreTest, LayerViewsRoundTripAndDamageIsDetected) {
  const std::string dir = test::scratchDir("pipeline_store_views").string();
  const impostor::DepthMeshImpostor view = smallView(24);
  const std::string stem = layerFileStem(7, "mmi", 2, 5);
  EXPECT_EQ(stem, "cells/e000007.mmi.02.5");
  const StoredView stored = writeLayerView(dir, stem, view);
  EXPECT_EQ(stored.texture, stem + ".png");
  EXPECT_EQ(stored.mesh, stem + ".ffmesh");
  EXPECT_EQ(stored.triangles, 4u);
  EXPECT_EQ(stored.vertices, 9u);
  EXPECT_TRUE(fs::is_regular_file(fs::path(dir) / stored.texture));
  EXPECT_TRUE(fs::is_regular_file(fs::path(dir) / stored.mesh));

  const impostor::DepthMeshImpostor back = loadLayerView(dir, stored);
  EXPECT_EQ(back.mesh.positions, view.mesh.positions);
  EXPECT_EQ(back.mesh.uvs, view.mesh.uvs);
  EXPECT_EQ(back.mesh.indices, view.mesh.indices);
  EXPECT_EQ(back.triangle_ids, view.triangle_ids);
  ASSERT_TRUE(back.texture);
  EXPECT_EQ(back.texture->pixels(), view.texture->pixels());
  EXPECT_EQ(stored.ids, stem + ".ids.png");
  ASSERT_TRUE(back.ids);
  EXPECT_EQ(back.ids->pixels(), view.ids->pixels());
  expectSameCamera(back.camera, view.camera, "loaded view");

  // An empty view: a mesh file with zero counts and no texture.
  impostor::DepthMeshImpostor empty;
  empty.camera = view.camera;
  const StoredView empty_stored = writeLayerView(dir, layerFileStem(7, "mmi", 3, 0), empty);
  EXPECT_EQ(empty_stored.texture, "");
  EXPECT_EQ(empty_stored.triangles, 0u);
  EXPECT_TRUE(fs::is_regular_file(fs::path(dir) / empty_stored.mesh));
  EXPECT_TRUE(loadLayerView(dir, empty_stored).empty());

  const std::string mesh_file = (fs::path(dir) / stored.mesh).string();
  const std::string texture_file = (fs::path(dir) / stored.texture).string();
  const auto expect_error = [](const auto& fn, const std::string& file, const std::string& what) {
    try {
      fn();
      ADD_FAILURE() << "expected farfield::Error naming " << file;
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(file), std::string::npos) << msg;
      EXPECT_NE(msg.find(what), std::string::npos) << msg;
    }
  };
  // The files carry their checks, and loading names the record.
  EXPECT_TRUE(stored.mesh_check.known && stored.texture_check.known && stored.ids_check.known);
  EXPECT_EQ(stored.mesh_check.bytes, fs::file_size(fs::path(dir) / stored.mesh));
  // Counts in the index that disagree with the file.
  StoredView wrong = stored;
  wrong.triangles = 5;
  expect_error([&] { loadLayerView(dir, wrong); }, mesh_file, "the index says 5");
  wrong = stored;
  wrong.vertices = 8;
  expect_error([&] { loadLayerView(dir, wrong); }, mesh_file, "the index says");
  // An empty view in the index whose mesh has data.
  wrong = empty_stored;
  wrong.mesh = stored.mesh;
  wrong.mesh_check = stored.mesh_check;
  expect_error([&] { loadLayerView(dir, wrong); }, mesh_file, "the index says 0");
  // The mesh of another view with different counts put in its place: its size differs from the index's; with an
  // index whose checks match it (written for it), the counts still disagree.
  {
    impostor::DepthMeshImpostor other = view;
    other.mesh.indices.resize(6);
    other.triangle_ids.resize(2);
    wrong = stored;
    wrong.record = "cell 7: mmi layer 2 view 5";
    wrong.mesh_check = writeMesh(mesh_file, other);
    expect_error([&] { loadLayerView(dir, stored); }, mesh_file, "truncated: ");
    expect_error([&] { loadLayerView(dir, wrong); }, mesh_file, "cell 7: mmi layer 2 view 5 mesh: holds 2 triangles");
    writeMesh(mesh_file, view);
    EXPECT_NO_THROW(loadLayerView(dir, stored));
  }
  // A texture of the wrong size (a readable PNG) and a missing one.
  image::writePng(texture_file, image::ColorImage(24, 23));
  expect_error([&] { loadLayerView(dir, stored); }, texture_file, "layer view texture: ");
  wrong = stored;
  wrong.texture_check = {};  // as in a version 2 index
  expect_error([&] { loadLayerView(dir, wrong); }, texture_file, "24x23");
  fs::remove(texture_file);
  expect_error([&] { loadLayerView(dir, stored); }, texture_file, "");
  // A missing mesh.
  fs::remove(mesh_file);
  expect_error([&] { loadLayerView(dir, stored); }, mesh_file, "");
}

}  // namespace
}  // namespace farfield::store
