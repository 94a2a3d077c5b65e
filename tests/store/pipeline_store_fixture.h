// Shared by the pipeline store tests (test_pipeline_store_*.cpp): cells and indexes with no round numbers in them,
// the same index as a version 2 or 3 bake wrote it, a camera comparison and an index error check naming each part.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/store/impostor_store.h"

namespace farfield::store::pipeline_store_test {

inline constexpr size_t kSceneObjects = 20;

// A camera with no round numbers in it, so a lossy float or double conversion anywhere shows.
inline Camera oddCamera(float seed) {
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

inline StoredView oddView(uint32_t half_edge, size_t layer, size_t view, double seed, bool with_data = true) {
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
inline impostor::ValidityRegion oddRegion(float seed) {
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
inline CellEntry fullCell(uint32_t half_edge) {
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
inline CellEntry onlineCell(uint32_t half_edge) {
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

inline StoreIndex pipelineIndex() {
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

inline void expectSameCamera(const Camera& a, const Camera& b, const std::string& where) {
  EXPECT_EQ(a.eye, b.eye) << where;
  EXPECT_EQ(a.at, b.at) << where;
  EXPECT_EQ(a.up, b.up) << where;
  EXPECT_EQ(a.fov_y, b.fov_y) << where;
  EXPECT_EQ(a.width, b.width) << where;
  EXPECT_EQ(a.height, b.height) << where;
  EXPECT_EQ(a.near_plane, b.near_plane) << where;
  EXPECT_EQ(a.far_plane, b.far_plane) << where;
}

// Expects indexFromJson(j) to throw a farfield::Error whose message contains each of `parts`.
inline void expectIndexError(const nlohmann::json& j, const std::vector<std::string>& parts) {
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
inline StoreIndex legacyIndex(int version) {
  StoreIndex index = pipelineIndex();
  index.version = version;
  index.options["pipeline"]["single_mesh"] = true;
  return index;
}
inline nlohmann::json legacyJson(int version) { return indexToJson(legacyIndex(version)); }

}  // namespace farfield::store::pipeline_store_test
