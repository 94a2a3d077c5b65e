// The storage report of a pipeline bake: the bytes of the files it wrote, and the paper's estimate next to them.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <set>
#include <string>

#include "farfield/bake/pipeline.h"
#include "farfield/store/impostor_store.h"
#include "bake/pipeline_fixture.h"

namespace fs = std::filesystem;

namespace farfield::bake {
using namespace farfield::extract;
namespace {

using pipeline_test::BakedCity;
using pipeline_test::bakedCity;
using pipeline_test::PipelineBakeTest;

uint64_t fileBytes(const std::string& dir, const std::string& name) {
  if (name.empty()) return 0;
  const fs::path p = fs::path(dir) / name;
  EXPECT_TRUE(fs::is_regular_file(p)) << p;
  return fs::is_regular_file(p) ? uint64_t(fs::file_size(p)) : 0;
}

TEST_F(PipelineBakeTest, StorageReportCountsTheBytesWritten) {
  const BakedCity& b = bakedCity();
  const store::StoreIndex index = store::readIndex(b.full_dir);
  uint64_t textures = 0, meshes = 0, ids = 0;
  size_t layers = 0, views = 0;
  std::set<std::string> referenced;
  for (const store::CellEntry& e : index.cells) {
    ASSERT_TRUE(e.pipeline && e.pipeline->has_mmi);
    layers += e.pipeline->layers.size();
    auto add = [&](const store::StoredView& v) {
      textures += fileBytes(b.full_dir, v.texture);
      meshes += fileBytes(b.full_dir, v.mesh);
      ids += fileBytes(b.full_dir, v.ids);
      if (!v.texture.empty()) referenced.insert(v.texture);
      if (!v.ids.empty()) referenced.insert(v.ids);
      // A view with data carries its per-texel object ids.
      EXPECT_EQ(v.ids.empty(), v.texture.empty()) << v.mesh;
      referenced.insert(v.mesh);
    };
    for (const store::StoredLayer& l : e.pipeline->layers)
      for (const store::StoredView& v : l.views) {
        add(v);
        ++views;
      }
    for (const store::StoredView& v : e.pipeline->single.views) add(v);
  }
  // Every file under cells/ is referenced (nothing written that the index does not know of).
  uint64_t on_disk = 0;
  for (const auto& f : fs::directory_iterator(fs::path(b.full_dir) / "cells")) {
    const std::string name = "cells/" + f.path().filename().string();
    EXPECT_TRUE(referenced.count(name)) << name << " is not referenced by the index";
    on_disk += uint64_t(f.file_size());
  }
  const nlohmann::json& s = index.storage;
  ASSERT_TRUE(s.is_object());
  EXPECT_EQ(s.at("written_texture_bytes").get<uint64_t>(), textures);
  EXPECT_EQ(s.at("written_mesh_bytes").get<uint64_t>(), meshes);
  EXPECT_EQ(s.at("written_bytes").get<uint64_t>(), textures + meshes);
  EXPECT_EQ(s.at("written_id_bytes").get<uint64_t>(), ids);
  EXPECT_EQ(on_disk, textures + meshes + ids);
  EXPECT_GT(textures, 0u);
  EXPECT_EQ(b.full_report.storage, s);
  EXPECT_EQ(s.at("cells").get<size_t>(), index.cells.size());
  EXPECT_EQ(s.at("layers").get<size_t>(), layers);
  // The paper's estimate (section 5.1): RGB images of resolution^2 and a 30 x 30 grid of float xyz (10.8 kB).
  const double image = 128.0 * 128.0 * 3.0, mesh = 30.0 * 30.0 * 12.0;
  EXPECT_DOUBLE_EQ(s.at("mesh_bytes_each").get<double>(), 10800.0);
  EXPECT_DOUBLE_EQ(s.at("estimate_bytes_measured_layers").get<double>(), double(views) * (image + mesh));
  EXPECT_DOUBLE_EQ(s.at("estimate_bytes_3_layers").get<double>(), double(index.cells.size()) * 3.0 * (image + mesh));
  std::printf("storage: %zu views, %llu texture + %llu mesh bytes written; estimate %.0f bytes (3 layers: %.0f)\n",
              views, (unsigned long long)textures, (unsigned long long)meshes,
              s.at("estimate_bytes_measured_layers").get<double>(), s.at("estimate_bytes_3_layers").get<double>());
}

}  // namespace
}  // namespace farfield::bake
