// Impostor store files: a round trip is exact, damaged mesh, texture and index files give a farfield::Error naming
// the file, and a cell with different textures per technique is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/image/png_io.h"
#include "farfield/store/impostor_store.h"
#include "store/impostor_store_fixture.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::store {
namespace {

using impostor_store_test::entryFor;
using impostor_store_test::expectError;
using impostor_store_test::indexWith;
using impostor_store_test::randomImpostor;
using impostor_store_test::readBytes;
using impostor_store_test::writeBytes;

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

}  // namespace
}  // namespace farfield::store
