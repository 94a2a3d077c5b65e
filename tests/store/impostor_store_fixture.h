// Shared by the impostor store tests (test_impostor_store_*.cpp): random impostors, cell entries and indexes, file
// helpers, an error check naming the file, and a small store holding every kind of file (writeStore) with what a
// reader must get back from it.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/store/impostor_store.h"

namespace farfield::store::impostor_store_test {

namespace fs = std::filesystem;

inline impostor::DepthMeshImpostor randomImpostor(uint32_t seed, int size = 32, size_t vertices = 40,
                                                 size_t triangles = 60) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-100.0f, 100.0f), t(0.0f, 1.0f);
  impostor::DepthMeshImpostor imp;
  for (size_t v = 0; v < vertices; ++v) {
    imp.mesh.positions.emplace_back(u(rng), u(rng), u(rng));
    imp.mesh.uvs.emplace_back(t(rng), t(rng));
  }
  for (size_t k = 0; k < 3 * triangles; ++k) imp.mesh.indices.push_back(uint32_t(rng() % vertices));
  for (size_t k = 0; k < triangles; ++k) imp.triangle_ids.push_back(uint32_t(rng() % 9));
  auto texture = std::make_shared<image::ColorImage>(size, size);
  for (auto& p : texture->pixels()) p = image::Rgba8(rng() % 256, rng() % 256, rng() % 256, (rng() % 2) * 255);
  imp.texture = texture;
  imp.camera.eye = Vec3(1.0f, 2.0f, 1.7f);
  imp.camera.at = Vec3(1.0f, 80.0f, 1.7f);
  imp.camera.width = imp.camera.height = size;
  imp.camera.fov_y = 1.234567f;
  return imp;
}

inline CellEntry entryFor(uint32_t half_edge, const Camera& camera) {
  CellEntry e;
  e.half_edge = half_edge;
  e.camera = camera;
  e.local_objects = {1, 4, 5};
  e.distant_objects = 7;
  e.data_pixels = 99;
  e.render_ms = 1.5;
  return e;
}

inline StoreIndex indexWith(std::vector<CellEntry> cells) {
  StoreIndex index;
  index.techniques = {"depth-mesh", "grid-mesh"};
  index.scene = "test.glb";
  index.scene_objects = 12;
  index.cells = std::move(cells);
  return index;
}

// Runs fn and expects a farfield::Error whose message names `file` and contains `what`.
template <class Fn>
void expectError(Fn&& fn, const std::string& file, const std::string& what) {
  try {
    fn();
    ADD_FAILURE() << "expected farfield::Error for " << file;
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(fs::path(file).filename().string()), std::string::npos) << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << msg;
  }
}

inline std::string readBytes(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
inline void writeBytes(const std::string& file, const std::string& bytes) {
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
}

// What a small store holds, in memory: the street graph text, two cells with both Sillion techniques (the second
// cell's impostors empty) and, on the first, a pipeline record: one layer of two views (the second empty) and the
// single mesh, both with per-texel ids. Every kind of file a store holds is in it.
struct StoreContent {
  std::string streets;
  uint32_t cell_a = 0, cell_b = 0;
  impostor::DepthMeshImpostor depth, grid, layer_view, single_view, empty;
};

inline std::shared_ptr<image::IdImage> randomIds(uint32_t seed, int size) {
  std::mt19937 rng(seed);
  auto ids = std::make_shared<image::IdImage>(size, size, 0u);
  for (uint32_t& id : ids->pixels()) id = rng() % 3 == 0 ? 0u : uint32_t(rng());
  return ids;
}

inline StoreContent makeContent(uint32_t seed) {
  StoreContent c;
  c.streets = "{\"format\": \"farfield-streets\", \"junctions\": [[0, 0], [" + std::to_string(seed) +
              ", 1]], \"streets\": []}\n";
  c.cell_a = 12;
  c.cell_b = 40 + seed;
  c.depth = randomImpostor(10 * seed + 1);
  c.grid = randomImpostor(10 * seed + 2, 32, 25, 30);
  c.grid.texture = c.depth.texture;
  c.layer_view = randomImpostor(10 * seed + 3, 16, 12, 9);
  c.layer_view.ids = randomIds(10 * seed + 4, 16);
  c.single_view = randomImpostor(10 * seed + 5, 16, 7, 4);
  c.single_view.ids = randomIds(10 * seed + 6, 16);
  c.empty.camera = c.depth.camera;
  return c;
}

inline impostor::ValidityRegion simpleRegion() {
  impostor::ValidityRegion r;
  r.origin = Vec3(1.0f, 2.0f, 1.7f);
  r.end = Vec3(1.0f, 30.0f, 1.7f);
  r.half_width = 5.0f;
  r.step = 1.0f;
  r.laterals = 1;
  r.envelope = {0.0f, 0.001f};
  return r;
}

// Writes `c` into dir the way the bakes did and do (bake/pipeline.cpp; the Sillion records with store::writeCell as
// the Sillion bake of stores up to version 3 did): a new generation of files, the streets first, then the cells, the
// index last. Version 2 writes the files with the names and index of that format (the single mesh inside mmi, the
// options saying the mmi stage built it).
inline StoreIndex writeStore(const std::string& dir, const StoreContent& c, int version = kIndexVersion) {
  StoreIndex index = indexWith({});
  index.version = version;
  index.generation = version >= 3 ? nextGeneration(dir) : 0;
  const uint64_t g = index.generation;
  index.pipeline = {"pvs", "near-far", "single", "mmi"};
  if (version <= 3) index.options = {{"pipeline", {{"single_mesh", true}}}};
  writeStreets(dir, index, c.streets);
  CellEntry a = entryFor(c.cell_a, c.depth.camera);
  writeCell(dir, a, {{"depth-mesh", &c.depth}, {"grid-mesh", &c.grid}}, g);
  CellPipeline p;
  p.has_mmi = true;
  p.threshold_rad = 0.01;
  StoredLayer layer;
  layer.objects = {2, 3};
  layer.views = {writeLayerView(dir, layerFileStem(c.cell_a, "mmi", 0, 0, g), c.layer_view),
                 writeLayerView(dir, layerFileStem(c.cell_a, "mmi", 0, 1, g), c.empty)};
  layer.validity = {simpleRegion()};
  p.layers = {layer};
  p.has_single = true;
  p.single.objects = {2, 3};
  p.single.views = {writeLayerView(dir, layerFileStem(c.cell_a, "smi", 0, 0, g), c.single_view)};
  p.single.validity = {simpleRegion()};
  a.pipeline = p;
  CellEntry b = entryFor(c.cell_b, c.depth.camera);
  writeCell(dir, b, {{"depth-mesh", &c.empty}, {"grid-mesh", &c.empty}}, g);
  index.cells = {a, b};
  writeIndex(dir, index);
  return index;
}

template <class T>
void appendBytes(std::string& d, const std::vector<T>& v) {
  d += std::to_string(v.size()) + ":";
  d.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

// Everything a reader gets from an impostor, as bytes.
inline void appendImpostor(std::string& d, const impostor::DepthMeshImpostor& imp) {
  appendBytes(d, imp.mesh.positions);
  appendBytes(d, imp.mesh.uvs);
  appendBytes(d, imp.mesh.indices);
  appendBytes(d, imp.triangle_ids);
  if (imp.texture) appendBytes(d, imp.texture->pixels());
  d += "|";
  if (imp.ids) appendBytes(d, imp.ids->pixels());
  d += "|" + std::to_string(imp.camera.width) + "x" + std::to_string(imp.camera.height);
  appendBytes(d, std::vector<Vec3>{imp.camera.eye, imp.camera.at});
}

// What writeStore(c) must read back as, built from memory.
inline std::string expectedContent(const StoreContent& c) {
  std::string d = c.streets;
  d += "cell " + std::to_string(c.cell_a);
  for (const impostor::DepthMeshImpostor* imp : {&c.depth, &c.grid, &c.layer_view, &c.empty, &c.single_view})
    appendImpostor(d, *imp);
  d += "cell " + std::to_string(c.cell_b);
  appendImpostor(d, c.empty);
  appendImpostor(d, c.empty);
  return d;
}

// What a reader gets from the store in dir: the index, the streets file and every impostor and view.
inline std::string storedContent(const std::string& dir) {
  const StoreIndex index = readIndex(dir);
  std::string d = readCheckedFile((fs::path(dir) / index.streets).string(), index.streets_check, "streets");
  for (const CellEntry& e : index.cells) {
    d += "cell " + std::to_string(e.half_edge);
    for (const std::string& technique : index.techniques) appendImpostor(d, loadImpostor(dir, e, technique));
    if (!e.pipeline) continue;
    for (const StoredLayer& l : e.pipeline->layers)
      for (const StoredView& v : l.views) appendImpostor(d, loadLayerView(dir, v));
    for (const StoredView& v : e.pipeline->single.views) appendImpostor(d, loadLayerView(dir, v));
  }
  return d;
}

// Every file under dir, relative to it.
inline std::set<std::string> filesIn(const std::string& dir) {
  std::set<std::string> out;
  for (const auto& f : fs::recursive_directory_iterator(dir))
    if (f.is_regular_file()) out.insert(fs::relative(f.path(), dir).generic_string());
  return out;
}

// The files an index names, and the index.
inline std::set<std::string> namedFiles(const StoreIndex& index) {
  std::set<std::string> out{kIndexFile, index.streets};
  const auto add = [&](const StoredView& v) {
    for (const std::string* name : {&v.texture, &v.mesh, &v.ids})
      if (!name->empty()) out.insert(*name);
  };
  for (const CellEntry& e : index.cells) {
    if (!e.texture.empty()) out.insert(e.texture);
    for (const auto& [technique, imp] : e.impostors) out.insert(imp.mesh);
    if (!e.pipeline) continue;
    for (const StoredLayer& l : e.pipeline->layers)
      for (const StoredView& v : l.views) add(v);
    for (const StoredView& v : e.pipeline->single.views) add(v);
  }
  return out;
}

}  // namespace farfield::store::impostor_store_test
