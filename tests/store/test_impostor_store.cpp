// Impostor store: round trips are exact, and every kind of damage gives a farfield::Error naming the file.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <set>

#include "farfield/core/error.h"
#include "farfield/image/png_io.h"
#include "farfield/store/impostor_store.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::store {
namespace {

impostor::DepthMeshImpostor randomImpostor(uint32_t seed, int size = 32, size_t vertices = 40, size_t triangles = 60) {
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

CellEntry entryFor(uint32_t half_edge, const Camera& camera) {
  CellEntry e;
  e.half_edge = half_edge;
  e.camera = camera;
  e.local_objects = {1, 4, 5};
  e.distant_objects = 7;
  e.data_pixels = 99;
  e.render_ms = 1.5;
  return e;
}

StoreIndex indexWith(std::vector<CellEntry> cells) {
  StoreIndex index;
  index.techniques = {"depth-mesh", "grid-mesh"};
  index.scene = "test.glb";
  index.scene_objects = 12;
  index.cells = std::move(cells);
  return index;
}

// A store with two cells (12 and 40; cell 40's impostors are empty).
struct TestStore {
  std::string dir;
  impostor::DepthMeshImpostor depth, grid;
  StoreIndex index;
};

TestStore makeStore(const std::string& name) {
  TestStore s;
  s.dir = test::scratchDir(name).string();
  s.depth = randomImpostor(1);
  s.grid = randomImpostor(2, 32, 25, 30);
  s.grid.texture = s.depth.texture;  // one capture per cell
  s.index = indexWith({});
  s.index.generation = nextGeneration(s.dir);
  writeStreets(s.dir, s.index, "{\"junctions\": [], \"streets\": []}\n");
  CellEntry a = entryFor(12, s.depth.camera);
  writeCell(s.dir, a, {{"depth-mesh", &s.depth}, {"grid-mesh", &s.grid}}, s.index.generation);
  impostor::DepthMeshImpostor empty;
  empty.camera = s.depth.camera;
  CellEntry b = entryFor(40, s.depth.camera);
  writeCell(s.dir, b, {{"depth-mesh", &empty}, {"grid-mesh", &empty}}, s.index.generation);
  s.index.cells = {a, b};
  writeIndex(s.dir, s.index);
  return s;
}

void expectSame(const impostor::DepthMeshImpostor& got, const impostor::DepthMeshImpostor& want) {
  EXPECT_EQ(got.mesh.positions, want.mesh.positions);
  EXPECT_EQ(got.mesh.uvs, want.mesh.uvs);
  EXPECT_EQ(got.mesh.indices, want.mesh.indices);
  EXPECT_EQ(got.triangle_ids, want.triangle_ids);
  ASSERT_TRUE(got.texture);
  EXPECT_EQ(got.texture->width(), want.texture->width());
  EXPECT_EQ(got.texture->pixels(), want.texture->pixels());
  EXPECT_EQ(got.camera.eye, want.camera.eye);
  EXPECT_EQ(got.camera.at, want.camera.at);
  EXPECT_EQ(got.camera.fov_y, want.camera.fov_y);
  EXPECT_EQ(got.camera.width, want.camera.width);
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

std::string readBytes(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
void writeBytes(const std::string& file, const std::string& bytes) {
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
}

TEST(ImpostorStoreTest, RoundTripIsExact) {
  const TestStore s = makeStore("store_round_trip");
  const StoreIndex index = readIndex(s.dir);
  ASSERT_EQ(index.cells.size(), 2u);
  EXPECT_EQ(index.techniques, s.index.techniques);
  EXPECT_EQ(index.scene_objects, 12u);
  const CellEntry* a = index.find(12);
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(index.find(13), nullptr);
  EXPECT_EQ(a->local_objects, (std::vector<uint32_t>{1, 4, 5}));
  EXPECT_EQ(a->impostors.at("depth-mesh").triangles, 60u);
  EXPECT_EQ(a->impostors.at("grid-mesh").triangles, 30u);
  // One texture file for both techniques, named with the store's generation (1: a new store).
  EXPECT_EQ(index.generation, 1u);
  EXPECT_EQ(a->texture, textureFileName(12, 1));
  EXPECT_EQ(a->texture, "cells/g000001.e000012.png");
  EXPECT_EQ(index.streets, "g000001.streets.json");
  size_t pngs = 0;
  for (const auto& f : fs::directory_iterator(fs::path(s.dir) / "cells")) pngs += f.path().extension() == ".png";
  EXPECT_EQ(pngs, 1u);
  expectSame(loadImpostor(s.dir, *a, "depth-mesh"), s.depth);
  expectSame(loadImpostor(s.dir, *a, "grid-mesh"), s.grid);
  // The empty cell loads as an empty impostor.
  const impostor::DepthMeshImpostor empty = loadImpostor(s.dir, *index.find(40), "depth-mesh");
  EXPECT_TRUE(empty.empty());
  EXPECT_FALSE(empty.texture);
  EXPECT_TRUE(index.find(40)->texture.empty());
}

TEST(ImpostorStoreTest, DamagedMeshFilesGiveErrorsNamingTheFile) {
  const TestStore s = makeStore("store_damaged_mesh");
  const std::string file = (fs::path(s.dir) / meshFileName(12, "depth-mesh", 1)).string();
  const std::string good = readBytes(file);
  ASSERT_EQ(good.size(), 24u + 20u * 40u + 4u * 180u + 4u * 60u);  // the documented layout

  writeBytes(file, good.substr(0, good.size() - 7));
  expectError([&] { readMesh(file); }, file, "truncated");
  writeBytes(file, good.substr(0, 10));
  expectError([&] { readMesh(file); }, file, "truncated");
  writeBytes(file, good + "xx");
  expectError([&] { readMesh(file); }, file, "trailing");
  std::string bad = good;
  bad[0] = 'X';
  writeBytes(file, bad);
  expectError([&] { readMesh(file); }, file, "bad magic");
  bad = good;
  bad[8] = 2;  // version 2
  writeBytes(file, bad);
  expectError([&] { readMesh(file); }, file, "version 2");
  bad = good;
  const uint32_t huge = 1000000;  // index 0 out of range
  std::memcpy(bad.data() + 24 + 20 * 40, &huge, 4);
  writeBytes(file, bad);
  expectError([&] { readMesh(file); }, file, "out of range");
  bad = good;
  const float nan = std::nanf("");
  std::memcpy(bad.data() + 24, &nan, 4);
  writeBytes(file, bad);
  expectError([&] { readMesh(file); }, file, "non-finite");
  fs::remove(file);
  expectError([&] { readMesh(file); }, file, "cannot open");

  // A valid mesh file whose counts disagree with the index: its size does first; with a version 2 index (no checks)
  // the counts do.
  const std::string other = (fs::path(s.dir) / meshFileName(12, "grid-mesh", 1)).string();
  writeBytes(file, readBytes(other));
  const StoreIndex index = readIndex(s.dir);
  expectError([&] { loadImpostor(s.dir, *index.find(12), "depth-mesh"); }, file,
              "cell 12 depth-mesh mesh: truncated: ");
  CellEntry unchecked = *index.find(12);
  unchecked.impostors.at("depth-mesh").mesh_check = {};
  expectError([&] { loadImpostor(s.dir, unchecked, "depth-mesh"); }, file,
              "cell 12 depth-mesh mesh: holds 30 triangles and 25 vertices, the index says 60 and 40");
}

TEST(ImpostorStoreTest, DamagedTextureGivesAnErrorNamingTheFile) {
  const TestStore s = makeStore("store_damaged_texture");
  const StoreIndex index = readIndex(s.dir);
  const std::string file = (fs::path(s.dir) / textureFileName(12, 1)).string();
  const std::string good = readBytes(file);
  writeBytes(file, good.substr(0, good.size() / 2));
  expectError([&] { loadImpostor(s.dir, *index.find(12), "depth-mesh"); }, file,
              "cell 12 depth-mesh texture: truncated: " + std::to_string(good.size() / 2) + " of " +
                  std::to_string(good.size()) + " bytes");
  // A readable texture of the wrong size: another file than the index's; without the check, the wrong size.
  image::writePng(file, image::ColorImage(8, 8));
  expectError([&] { loadImpostor(s.dir, *index.find(12), "depth-mesh"); }, file, "cell 12 depth-mesh texture: ");
  CellEntry unchecked = *index.find(12);
  unchecked.texture_check = {};
  expectError([&] { loadImpostor(s.dir, unchecked, "depth-mesh"); }, file, "8x8");
}

TEST(ImpostorStoreTest, DamagedIndexGivesErrorsNamingTheFile) {
  const TestStore s = makeStore("store_damaged_index");
  const std::string file = (fs::path(s.dir) / kIndexFile).string();
  const nlohmann::json good = nlohmann::json::parse(readBytes(file));
  // Damage with a valid checksum (as a writer with a bug would leave it): the shape checks find it.
  auto expect_index_error = [&](const nlohmann::json& j, const std::string& what) {
    writeBytes(file, indexFileText(j));
    expectError([&] { readIndex(s.dir); }, file, what);
  };
  nlohmann::json j = good;
  j["version"] = 7;
  expect_index_error(j, "unsupported version 7");
  j = good;
  j["format"] = "something else";
  expect_index_error(j, "format");
  j = good;
  j["cells"][0].erase("camera");
  expect_index_error(j, "cells[0]: missing \"camera\"");
  j = good;
  j["cells"][1]["half_edge"] = 3;  // not sorted
  expect_index_error(j, "sorted");
  j = good;
  j["cells"][0]["impostors"].erase("grid-mesh");
  expect_index_error(j, "grid-mesh");
  j = good;
  j["cells"][0]["texture"] = "../outside.png";
  expect_index_error(j, "..");
  j = good;
  j["cells"][0]["local_objects"] = {1, 99};
  expect_index_error(j, "outside 1..12");
  j = good;
  j["cells"][0]["camera"]["at"] = j["cells"][0]["camera"]["eye"];
  expect_index_error(j, "coincide");
  // Values beyond the types they are stored in: an int conversion made 2^32 + width the same width, and an object
  // count beyond 32 bits let ids wrap.
  j = good;
  j["cells"][0]["camera"]["width"] = (uint64_t(1) << 32) + j["cells"][0]["camera"]["width"].get<uint64_t>();
  expect_index_error(j, "cells[0]: camera: \"width\": 4294967");
  j = good;
  j["cells"][0]["camera"]["height"] = uint64_t(1) << 63;
  expect_index_error(j, "is out of range");
  j = good;
  j["scene_objects"] = (uint64_t(1) << 32) + 12;
  expect_index_error(j, "\"scene_objects\": must be at most 4294967295");
  writeBytes(file, good.dump().substr(0, 100));
  expectError([&] { readIndex(s.dir); }, file, "not valid JSON");
  // The same content with another layout, and a changed value without a new checksum.
  writeBytes(file, good.dump());
  expectError([&] { readIndex(s.dir); }, file, "not the text the store writer wrote");
  j = good;
  j["scene_objects"] = 13;
  writeBytes(file, j.dump(1) + "\n");
  expectError([&] { readIndex(s.dir); }, file, "checksum mismatch");
  j.erase("checksum");
  writeBytes(file, j.dump(1) + "\n");
  expectError([&] { readIndex(s.dir); }, file, "missing \"checksum\"");
  writeBytes(file, indexFileText(good));
  EXPECT_NO_THROW(readIndex(s.dir));
  fs::remove(file);
  expectError([&] { readIndex(s.dir); }, file, "cannot open");
  expectError([&] { readIndex(s.dir + "/missing"); }, "missing", "not found");
}

TEST(ImpostorStoreTest, CellWithDifferentTexturesPerTechniqueIsRefused) {
  const std::string dir = test::scratchDir("store_two_textures").string();
  const impostor::DepthMeshImpostor a = randomImpostor(3), b = randomImpostor(4);
  CellEntry e = entryFor(5, a.camera);
  EXPECT_THROW(writeCell(dir, e, {{"depth-mesh", &a}, {"grid-mesh", &b}}), Error);
}


// ---- Store v3: checksums per file, atomic rewrites --------------------------------------------------------------

// What a small store holds, in memory: the street graph text, two cells with both Sillion techniques (the second
// cell's impostors empty) and, on the first, a pipeline record: one layer of two views (the second empty) and the
// single mesh, both with per-texel ids. Every kind of file a store holds is in it.
struct StoreContent {
  std::string streets;
  uint32_t cell_a = 0, cell_b = 0;
  impostor::DepthMeshImpostor depth, grid, layer_view, single_view, empty;
};

std::shared_ptr<image::IdImage> randomIds(uint32_t seed, int size) {
  std::mt19937 rng(seed);
  auto ids = std::make_shared<image::IdImage>(size, size, 0u);
  for (uint32_t& id : ids->pixels()) id = rng() % 3 == 0 ? 0u : uint32_t(rng());
  return ids;
}

StoreContent makeContent(uint32_t seed) {
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

impostor::ValidityRegion simpleRegion() {
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
StoreIndex writeStore(const std::string& dir, const StoreContent& c, int version = kIndexVersion) {
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
void appendImpostor(std::string& d, const impostor::DepthMeshImpostor& imp) {
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
std::string expectedContent(const StoreContent& c) {
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
std::string storedContent(const std::string& dir) {
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
std::set<std::string> filesIn(const std::string& dir) {
  std::set<std::string> out;
  for (const auto& f : fs::recursive_directory_iterator(dir))
    if (f.is_regular_file()) out.insert(fs::relative(f.path(), dir).generic_string());
  return out;
}

// The files an index names, and the index.
std::set<std::string> namedFiles(const StoreIndex& index) {
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

TEST(StoreIntegrityTest, ChecksAreZlibCrc32AndSizeOfTheBytesOnDisk) {
  // The CRC-32 check value of the standard ("123456789" -> cbf43926).
  const FileCheck check = fileCheck("123456789");
  EXPECT_EQ(check.crc32, 0xcbf43926u);
  EXPECT_EQ(check.bytes, 9u);
  EXPECT_TRUE(check.known);
  const std::string dir = test::scratchDir("store_checks").string();
  const StoreContent c = makeContent(1);
  const StoreIndex written = writeStore(dir, c);
  EXPECT_EQ(storedContent(dir), expectedContent(c));
  // Every check in the index is the size and the CRC-32 (computed here with zlib directly) of its file.
  const StoreIndex index = readIndex(dir);
  size_t checked = 0;
  const auto expect_check = [&](const std::string& name, const FileCheck& check) {
    if (name.empty()) return;
    const std::string bytes = readBytes((fs::path(dir) / name).string());
    EXPECT_TRUE(check.known) << name;
    EXPECT_EQ(check.bytes, bytes.size()) << name;
    EXPECT_EQ(check.crc32, uint32_t(::crc32(0, reinterpret_cast<const Bytef*>(bytes.data()), uInt(bytes.size()))))
        << name;
    ++checked;
  };
  expect_check(index.streets, index.streets_check);
  for (const CellEntry& e : index.cells) {
    expect_check(e.texture, e.texture_check);
    for (const auto& [technique, imp] : e.impostors) expect_check(imp.mesh, imp.mesh_check);
    if (!e.pipeline) continue;
    for (const StoredView* v : {&e.pipeline->layers[0].views[0], &e.pipeline->layers[0].views[1],
                                &e.pipeline->single.views[0]}) {
      expect_check(v->texture, v->texture_check);
      expect_check(v->mesh, v->mesh_check);
      expect_check(v->ids, v->ids_check);
    }
  }
  // Every file of the store but the index is checked: streets, 1 texture and 4 meshes of the Sillion cells, 3 + 1 + 3
  // files of the views.
  EXPECT_EQ(checked, 13u);
  EXPECT_EQ(filesIn(dir).size(), checked + 1);
  EXPECT_EQ(filesIn(dir), namedFiles(index));
  // The index's own checksum covers its content.
  const nlohmann::json j = nlohmann::json::parse(readBytes((fs::path(dir) / kIndexFile).string()));
  EXPECT_EQ(j.at("checksum").get<uint32_t>(), indexChecksum(j));
  EXPECT_EQ(j.at("generation").get<uint64_t>(), 1u);
  EXPECT_EQ(written.generation, 1u);
}

TEST(StoreIntegrityTest, EveryTruncationAndByteFlipOfEveryFileIsAnErrorNamingFileAndRecord) {
  const std::string dir = test::scratchDir("store_damage").string();
  const StoreContent c = makeContent(1);
  writeStore(dir, c);
  const StoreIndex index = readIndex(dir);
  const CellEntry& a = *index.find(c.cell_a);
  const StoredView& view = a.pipeline->layers[0].views[0];
  const StoredView& single = a.pipeline->single.views[0];
  struct Target {
    std::string name;    // relative to dir
    std::string record;  // what the message must name besides the file
    std::string kind;    // to make sure each kind is covered
    std::function<void()> load;
  };
  const std::vector<Target> targets{
      {kIndexFile, "", "index", [&] { readIndex(dir); }},
      {index.streets, "streets", "streets", [&] { readIndex(dir); }},
      {a.texture, "cell 12 depth-mesh texture", "texture", [&] { loadImpostor(dir, a, "depth-mesh"); }},
      {a.impostors.at("depth-mesh").mesh, "cell 12 depth-mesh mesh", "mesh", [&] { loadImpostor(dir, a, "depth-mesh"); }},
      {a.impostors.at("grid-mesh").mesh, "cell 12 grid-mesh mesh", "mesh", [&] { loadImpostor(dir, a, "grid-mesh"); }},
      {view.mesh, "cell 12: mmi layer 0 view 0 mesh", "mesh", [&] { loadLayerView(dir, view); }},
      {view.texture, "cell 12: mmi layer 0 view 0 texture", "texture", [&] { loadLayerView(dir, view); }},
      {view.ids, "cell 12: mmi layer 0 view 0 ids", "ids", [&] { loadLayerView(dir, view); }},
      {a.pipeline->layers[0].views[1].mesh, "cell 12: mmi layer 0 view 1 mesh", "mesh",
       [&] { loadLayerView(dir, a.pipeline->layers[0].views[1]); }},
      {single.mesh, "cell 12: single mesh view 0 mesh", "mesh", [&] { loadLayerView(dir, single); }},
      {single.texture, "cell 12: single mesh view 0 texture", "texture", [&] { loadLayerView(dir, single); }},
      {single.ids, "cell 12: single mesh view 0 ids", "ids", [&] { loadLayerView(dir, single); }},
      {index.find(c.cell_b)->impostors.at("depth-mesh").mesh, "cell " + std::to_string(c.cell_b) + " depth-mesh mesh",
       "mesh", [&] { loadImpostor(dir, *index.find(c.cell_b), "depth-mesh"); }},
  };
  // Every kind of file, and every file the index names but the grid mesh of the empty cell (the same as depth's).
  std::set<std::string> kinds, covered;
  for (const Target& t : targets) kinds.insert(t.kind), covered.insert(t.name);
  EXPECT_EQ(kinds, (std::set<std::string>{"index", "streets", "texture", "mesh", "ids"}));
  EXPECT_EQ(covered.size() + 1, namedFiles(index).size());

  size_t cases = 0;
  for (const Target& t : targets) {
    const std::string file = (fs::path(dir) / t.name).string();
    const std::string good = readBytes(file);
    ASSERT_GT(good.size(), 2u) << t.name;
    const auto expect_damage_found = [&](const std::string& bytes, const std::string& what, const std::string& how) {
      writeBytes(file, bytes);
      try {
        t.load();
        ADD_FAILURE() << t.name << ": " << how << " not detected";
      } catch (const Error& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find(file), std::string::npos) << how << ": " << msg;
        EXPECT_NE(msg.find(t.record), std::string::npos) << how << ": " << msg;
        EXPECT_NE(msg.find(what), std::string::npos) << how << ": " << msg;
      }
      ++cases;
    };
    const bool index_file = t.kind == "index";
    const size_t n = good.size();
    for (const size_t keep : {size_t(0), size_t(1), size_t(8), n / 3, n / 2, n - 2, n - 1}) {
      const std::string what = index_file ? "" : "truncated: " + std::to_string(keep) + " of " + std::to_string(n) +
                                                     " bytes";
      expect_damage_found(good.substr(0, keep), what, "truncation to " + std::to_string(keep) + " bytes");
    }
    std::mt19937 rng{uint32_t(n)};
    std::vector<size_t> offsets{0, 1, 7, n / 2, n - 2, n - 1};
    for (int k = 0; k < 6; ++k) offsets.push_back(rng() % n);
    for (const size_t at : offsets)
      for (const uint8_t mask : {uint8_t(0x01), uint8_t(0x20), uint8_t(0x80), uint8_t(0xff)}) {
        std::string bad = good;
        bad[at] = char(uint8_t(bad[at]) ^ mask);
        expect_damage_found(bad, index_file ? "" : "checksum mismatch",
                            "flip of byte " + std::to_string(at) + " with " + std::to_string(mask));
      }
    // Trailing bytes.
    expect_damage_found(good + "x", index_file ? "" : "too long", "one byte appended");
    writeBytes(file, good);
    EXPECT_NO_THROW(t.load()) << t.name;
  }
  EXPECT_EQ(cases, targets.size() * (7 + 12 * 4 + 1));
  EXPECT_EQ(storedContent(dir), expectedContent(c));
}

TEST(StoreIntegrityTest, DigitFlipsInTheIndexAreCaughtByItsChecksum) {
  // A flip that leaves valid JSON of the same layout (a digit for another): only the checksum can see it.
  const std::string dir = test::scratchDir("store_index_digits").string();
  writeStore(dir, makeContent(1));
  const std::string file = (fs::path(dir) / kIndexFile).string();
  const std::string good = readBytes(file);
  size_t digits = 0;
  for (size_t at = 0; at < good.size(); ++at) {
    if (good[at] < '0' || good[at] > '8') continue;
    std::string bad = good;
    ++bad[at];
    writeBytes(file, bad);
    try {
      readIndex(dir);
      ADD_FAILURE() << "digit at " << at << " changed without an error";
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(file), std::string::npos) << msg;
      // A digit of a number that does not change the text's form: the checksum says so (a digit in a name or a
      // leading zero may be refused by the shape or form checks first, which is fine too).
      EXPECT_TRUE(msg.find("checksum mismatch") != std::string::npos || msg.find("text the store writer") != std::string::npos ||
                  msg.find("not valid JSON") != std::string::npos)
          << msg;
    }
    ++digits;
  }
  EXPECT_GT(digits, 100u);
  writeBytes(file, good);
  EXPECT_NO_THROW(readIndex(dir));
}

TEST(StoreIntegrityTest, ARewriteKilledAtAnyFileOperationLeavesTheOldOrTheNewStore) {
  const StoreContent old_content = makeContent(1), new_content = makeContent(2);
  const std::string old_expected = expectedContent(old_content), new_expected = expectedContent(new_content);
  ASSERT_NE(old_expected, new_expected);
  const std::string dir = test::scratchDir("store_killed_rewrite").string();
  const std::string old_store = test::scratchDir("store_killed_rewrite_old").string();
  writeStore(old_store, old_content);

  // The file operations of a complete rewrite, in order.
  std::vector<std::pair<std::string, std::string>> operations;
  fs::copy(old_store, dir, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  EXPECT_EQ(storedContent(dir), old_expected);
  setFileOperationHook([&](const char* op, const std::string& path) {
    operations.emplace_back(op, fs::relative(path, dir).generic_string());
  });
  const StoreIndex rewritten = writeStore(dir, new_content);
  setFileOperationHook({});
  EXPECT_EQ(storedContent(dir), new_expected);
  EXPECT_EQ(rewritten.generation, 2u);
  EXPECT_EQ(filesIn(dir), namedFiles(rewritten)) << "files of generation 1 left behind";
  std::set<std::string> kinds;
  for (const auto& [op, path] : operations) kinds.insert(op);
  EXPECT_EQ(kinds, (std::set<std::string>{"create", "write", "fsync", "rename", "sync-dir", "remove"}));
  ASSERT_GT(operations.size(), 50u);

  // Kill a child process doing the same rewrite (_exit: no unwinding, no cleanup) before each operation in turn.
  size_t saw_old = 0, saw_new = 0;
  for (size_t kill_at = 1; kill_at <= operations.size(); ++kill_at) {
    const std::string where = "killed before operation " + std::to_string(kill_at) + " (" +
                              operations[kill_at - 1].first + " " + operations[kill_at - 1].second + ")";
    fs::remove_all(dir);
    fs::copy(old_store, dir, fs::copy_options::recursive);  // the old store, as written (no fsyncs: faster)
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      size_t count = 0;
      setFileOperationHook([&](const char*, const std::string&) {
        if (++count == kill_at) _exit(0);
      });
      try {
        writeStore(dir, new_content);
      } catch (...) {
        _exit(3);
      }
      _exit(1);
    }
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status)) << where;
    ASSERT_EQ(WEXITSTATUS(status), 0) << where << ": the rewrite was not killed there";
    std::string read;
    try {
      read = storedContent(dir);
    } catch (const Error& e) {
      ADD_FAILURE() << where << ": the store is not readable: " << e.what();
      continue;
    }
    const bool is_old = read == old_expected, is_new = read == new_expected;
    EXPECT_TRUE(is_old || is_new) << where << ": the store holds neither the old nor the new content";
    saw_old += is_old;
    saw_new += is_new;
    // The index is replaced by one rename: before it the old store, after it the new one.
    const auto rename_index = std::find(operations.begin(), operations.end(),
                                        std::pair<std::string, std::string>("rename", kIndexFile));
    ASSERT_NE(rename_index, operations.end());
    EXPECT_EQ(is_new, kill_at > size_t(rename_index - operations.begin()) + 1) << where;
    // A later bake over the debris completes and leaves the new store alone in the directory.
    const StoreIndex again = writeStore(dir, new_content);
    EXPECT_EQ(storedContent(dir), new_expected) << where;
    EXPECT_EQ(filesIn(dir), namedFiles(again)) << where;
  }
  EXPECT_GT(saw_old, 0u);
  EXPECT_GT(saw_new, 0u);
  std::printf("killed rewrites: %zu file operations, %zu left the old store, %zu the new one\n", operations.size(),
              saw_old, saw_new);
}

TEST(StoreIntegrityTest, WriterErrorsLeaveTheOldStoreReadable) {
  // The same points as an I/O error (an exception) instead of a kill: the writer unwinds, the old store stays.
  const StoreContent old_content = makeContent(1), new_content = makeContent(2);
  const std::string dir = test::scratchDir("store_failed_rewrite").string();
  writeStore(dir, old_content);
  size_t total = 0;
  setFileOperationHook([&](const char*, const std::string&) { ++total; });
  writeStore(dir, new_content);
  setFileOperationHook({});
  for (size_t fail_at = 1; fail_at <= total; fail_at += 3) {
    fs::remove_all(dir);
    writeStore(dir, old_content);
    size_t count = 0;
    setFileOperationHook([&](const char* op, const std::string& path) {
      if (++count == fail_at) throw Error(path, std::string("injected failure before ") + op);
    });
    EXPECT_THROW(writeStore(dir, new_content), Error) << fail_at;
    setFileOperationHook({});
    const std::string read = storedContent(dir);
    EXPECT_TRUE(read == expectedContent(old_content) || read == expectedContent(new_content)) << fail_at;
  }
}

TEST(StoreIntegrityTest, Version2StoresAreReadWithoutChecksumsAndRewrittenAsTheCurrentVersion) {
  const std::string dir = test::scratchDir("store_v2").string();
  const StoreContent old_content = makeContent(1);
  const StoreIndex v2 = writeStore(dir, old_content, 2);
  // The files and index of the version 2 format: old names, no checks, no generation, no checksum.
  const std::string text = readBytes((fs::path(dir) / kIndexFile).string());
  for (const char* absent : {"checksum", "_crc32", "_bytes", "generation", "g000"})
    EXPECT_EQ(text.find(absent), std::string::npos) << absent;
  EXPECT_TRUE(fs::is_regular_file(fs::path(dir) / "streets.json"));
  EXPECT_TRUE(fs::is_regular_file(fs::path(dir) / "cells/e000012.png"));
  EXPECT_TRUE(fs::is_regular_file(fs::path(dir) / "cells/e000012.mmi.00.0.ids.png"));
  const StoreIndex index = readIndex(dir);
  EXPECT_EQ(index.version, 2);
  EXPECT_FALSE(index.streets_check.known);
  EXPECT_FALSE(index.find(12)->texture_check.known);
  EXPECT_FALSE(index.find(12)->pipeline->layers[0].views[0].mesh_check.known);
  EXPECT_EQ(storedContent(dir), expectedContent(old_content));
  // The version 2 layout (no single stage; the single mesh inside mmi, built by it: options.pipeline.single_mesh) is
  // read as the single stage's record.
  const nlohmann::json v2_json = nlohmann::json::parse(text);
  EXPECT_EQ(v2_json.at("pipeline"), nlohmann::json({"pvs", "near-far", "mmi"}));
  EXPECT_TRUE(v2_json.at("cells")[0].at("pipeline").at("mmi").contains("single"));
  EXPECT_FALSE(v2_json.at("cells")[0].at("pipeline").contains("single"));
  EXPECT_EQ(index.pipeline, (std::vector<std::string>{"pvs", "near-far", "single", "mmi"}));
  EXPECT_TRUE(index.find(12)->pipeline->has_single);
  EXPECT_EQ(index.find(12)->pipeline->single.views.size(), 1u);
  // A version 1 index is read too (the Sillion part).
  nlohmann::json j = nlohmann::json::parse(text);
  j["version"] = 1;
  for (nlohmann::json& cell : j["cells"]) cell.erase("pipeline");
  j.erase("pipeline");
  writeBytes((fs::path(dir) / kIndexFile).string(), j.dump(1) + "\n");
  EXPECT_EQ(readIndex(dir).version, 1);
  writeBytes((fs::path(dir) / kIndexFile).string(), text);

  // A bake over it writes generation 1 of a store of the current version and removes the version 2 files; unrelated
  // files stay.
  writeBytes((fs::path(dir) / "notes.txt").string(), "mine");
  writeBytes((fs::path(dir) / "cells" / "README").string(), "mine too");
  const StoreContent new_content = makeContent(2);
  const StoreIndex v3 = writeStore(dir, new_content);
  EXPECT_EQ(v3.generation, 1u);
  EXPECT_EQ(storedContent(dir), expectedContent(new_content));
  std::set<std::string> expected = namedFiles(v3);
  expected.insert("notes.txt");
  expected.insert("cells/README");
  EXPECT_EQ(filesIn(dir), expected);
  (void)v2;
}

TEST(StoreIntegrityTest, Version3IndexWithoutChecksumsIsAnErrorNamingWhatIsMissing) {
  const std::string dir = test::scratchDir("store_v3_missing").string();
  writeStore(dir, makeContent(1), 3);  // the layout of version 3 (the single mesh inside mmi), relabelled 2 below
  const std::string file = (fs::path(dir) / kIndexFile).string();
  const nlohmann::json good = nlohmann::json::parse(readBytes(file));
  const auto expect_missing = [&](nlohmann::json j, const std::vector<std::string>& parts) {
    writeBytes(file, indexFileText(j));
    try {
      readIndex(dir);
      ADD_FAILURE() << "expected an error naming " << parts.back();
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(file), std::string::npos) << msg;
      for (const std::string& part : parts) EXPECT_NE(msg.find(part), std::string::npos) << part << " in " << msg;
    }
  };
  nlohmann::json j = good;
  j.erase("streets_crc32");
  expect_missing(j, {"top level", "missing \"streets_crc32\""});
  j = good;
  j["cells"][0].erase("texture_bytes");
  expect_missing(j, {"cells[0]", "missing \"texture_bytes\""});
  j = good;
  j["cells"][1]["impostors"]["grid-mesh"].erase("mesh_crc32");
  expect_missing(j, {"cells[1]: impostors.grid-mesh", "missing \"mesh_crc32\""});
  j = good;
  j["cells"][0]["pipeline"]["mmi"]["layers"][0]["views"][0].erase("ids_crc32");
  expect_missing(j, {"cells[0]: pipeline.mmi.layers[0]: views[0]", "missing \"ids_crc32\""});
  j = good;
  j["cells"][0]["pipeline"]["mmi"]["single"]["views"][0].erase("mesh_bytes");
  expect_missing(j, {"cells[0]: pipeline.mmi.single: views[0]", "missing \"mesh_bytes\""});
  // A whole check gone (as in a version 2 index relabelled 3), and the generation.
  j = good;
  j["cells"][0]["pipeline"]["mmi"]["layers"][0]["views"][0].erase("texture_crc32");
  j["cells"][0]["pipeline"]["mmi"]["layers"][0]["views"][0].erase("texture_bytes");
  expect_missing(j, {"cells[0]: pipeline.mmi.layers[0]: views[0]", "missing \"texture_crc32\""});
  j = good;
  j.erase("streets_crc32");
  j.erase("streets_bytes");
  expect_missing(j, {"top level", "missing \"streets_crc32\""});
  j = good;
  j["cells"][0]["impostors"]["depth-mesh"].erase("mesh_crc32");
  j["cells"][0]["impostors"]["depth-mesh"].erase("mesh_bytes");
  expect_missing(j, {"cells[0]: impostors.depth-mesh", "missing \"mesh_crc32\""});
  j = good;
  j.erase("generation");
  expect_missing(j, {"top level", "missing \"generation\""});
  // The same index labelled version 2 (which has no index checksum either) is read without them.
  j["version"] = 2;
  j.erase("checksum");
  j["cells"][0]["impostors"]["depth-mesh"].erase("mesh_crc32");
  j["cells"][0]["impostors"]["depth-mesh"].erase("mesh_bytes");
  writeBytes(file, indexFileText(j));
  EXPECT_NO_THROW(readIndex(dir));
  // The index's own checksum.
  writeBytes(file, good.dump(1) + "\n");
  EXPECT_NO_THROW(readIndex(dir));
  j = good;
  j.erase("checksum");
  writeBytes(file, j.dump(1) + "\n");
  expectError([&] { readIndex(dir); }, file, "top level: missing \"checksum\"");
  writeBytes(file, good.dump(1) + "\n");

  // The writer refuses a version 3 index with a file it has no check for, naming the record.
  StoreIndex index = readIndex(dir);
  index.cells[0].pipeline->layers[0].views[0].texture_check = {};
  expectError([&] { writeIndex(dir, index); }, file, "cell 12: mmi layer 0 view 0 texture: no size and CRC-32");
  index = readIndex(dir);
  index.streets_check = {};
  expectError([&] { writeIndex(dir, index); }, file, "streets: no size and CRC-32");
  EXPECT_NO_THROW(readIndex(dir));  // the refused writes changed nothing
}

}  // namespace
}  // namespace farfield::store
