// Pipeline store layer views: a view's mesh, texture and ids round trip through their files, and files that
// disagree with the index (counts, size, checks, missing files) are refused naming the file.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <random>
#include <string>

#include "farfield/core/error.h"
#include "farfield/image/png_io.h"
#include "farfield/store/impostor_store.h"
#include "store/pipeline_store_fixture.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::store {
namespace {

using pipeline_store_test::expectSameCamera;
using pipeline_store_test::oddCamera;

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
