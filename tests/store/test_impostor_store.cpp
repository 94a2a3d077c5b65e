// Impostor store: round trips are exact, and every kind of damage gives a farfield::Error naming the file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

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
  CellEntry a = entryFor(12, s.depth.camera);
  writeCell(s.dir, a, {{"depth-mesh", &s.depth}, {"grid-mesh", &s.grid}});
  impostor::DepthMeshImpostor empty;
  empty.camera = s.depth.camera;
  CellEntry b = entryFor(40, s.depth.camera);
  writeCell(s.dir, b, {{"depth-mesh", &empty}, {"grid-mesh", &empty}});
  s.index = indexWith({a, b});
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
  // One texture file for both techniques.
  EXPECT_EQ(a->texture, textureFileName(12));
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
  const std::string file = (fs::path(s.dir) / meshFileName(12, "depth-mesh")).string();
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

  // A valid mesh file whose counts disagree with the index.
  const std::string other = (fs::path(s.dir) / meshFileName(12, "grid-mesh")).string();
  writeBytes(file, readBytes(other));
  const StoreIndex index = readIndex(s.dir);
  expectError([&] { loadImpostor(s.dir, *index.find(12), "depth-mesh"); }, file, "the index says");
}

TEST(ImpostorStoreTest, DamagedTextureGivesAnErrorNamingTheFile) {
  const TestStore s = makeStore("store_damaged_texture");
  const StoreIndex index = readIndex(s.dir);
  const std::string file = (fs::path(s.dir) / textureFileName(12)).string();
  const std::string good = readBytes(file);
  writeBytes(file, good.substr(0, good.size() / 2));
  expectError([&] { loadImpostor(s.dir, *index.find(12), "depth-mesh"); }, file, "");
  // A readable texture of the wrong size.
  image::writePng(file, image::ColorImage(8, 8));
  expectError([&] { loadImpostor(s.dir, *index.find(12), "depth-mesh"); }, file, "8x8");
}

TEST(ImpostorStoreTest, DamagedIndexGivesErrorsNamingTheFile) {
  const TestStore s = makeStore("store_damaged_index");
  const std::string file = (fs::path(s.dir) / kIndexFile).string();
  const nlohmann::json good = nlohmann::json::parse(readBytes(file));
  auto expect_index_error = [&](const nlohmann::json& j, const std::string& what) {
    writeBytes(file, j.dump());
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
  writeBytes(file, good.dump().substr(0, 100));
  expectError([&] { readIndex(s.dir); }, file, "not valid JSON");
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
