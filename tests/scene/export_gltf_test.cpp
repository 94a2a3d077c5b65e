#include "farfield/scene/export_gltf.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "farfield/core/error.h"
#include "farfield/scene/builtin.h"
#include "farfield/scene/import.h"
#include "support/test_support.h"

namespace farfield::scene {
namespace {

void expectBoxNear(const Box3& a, const Box3& b, const std::string& what) {
  const float scale = std::max(1.0f, glm::length(b.extent()));
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(a.lo[i], b.lo[i], 1e-4f * scale) << what;
    EXPECT_NEAR(a.hi[i], b.hi[i], 1e-4f * scale) << what;
  }
}

// Builtin "cubes" plus an object with a rotated, translated, scaled transform that shares a mesh, a parent and an
// unlit, double-sided, translucent material.
Scene testScene() {
  Scene s = builtinScene("cubes");
  Material m;
  m.name = "glass";
  m.base_color = {0.2f, 0.4f, 0.6f, 0.5f};
  m.unlit = true;
  m.double_sided = true;
  m.texture = s.materials[0].texture;  // shared with the ground: written once
  Object o;
  o.name = "turned";
  o.parts = {{s.objects[3].parts[0].mesh, s.addMaterial(m)}};
  o.transform = glm::translate(Mat4(1.0f), Vec3(30, -5, 2)) *
                glm::rotate(Mat4(1.0f), 0.7f, glm::normalize(Vec3(1, 2, 3))) * glm::scale(Mat4(1.0f), Vec3(1, 2, 0.5f));
  o.parent = 2;
  o.footprint = {{29, -6}, {31, -6}, {30, -4}};
  s.addObject(o);
  return s;
}

TEST(ExportGlb, RoundTripKeepsGeometryTexturesAndExtras) {
  const Scene src = testScene();
  const auto dir = test::scratchDir("export_glb");
  const std::string path = (dir / "cubes.glb").string();
  exportGlb(src, path);
  const Scene back = importScene(path);
  EXPECT_NO_THROW(back.validate(path));

  EXPECT_EQ(back.triangleCount(), src.triangleCount());
  expectBoxNear(back.bounds(), src.bounds(), "scene bounds");
  ASSERT_EQ(back.objects.size(), src.objects.size());
  for (size_t i = 0; i < src.objects.size(); ++i) {
    const Object& a = src.objects[i];
    const Object& b = back.objects[i];
    EXPECT_EQ(b.name, a.name);
    EXPECT_EQ(b.parent, a.parent) << a.name;
    expectBoxNear(b.world_bounds, a.world_bounds, a.name);
    ASSERT_EQ(b.footprint.size(), a.footprint.size()) << a.name;
    for (size_t k = 0; k < a.footprint.size(); ++k) EXPECT_NEAR(glm::distance(b.footprint[k], a.footprint[k]), 0.0f, 1e-5f);
    ASSERT_EQ(b.parts.size(), a.parts.size());
    const Material& ma = src.materials[a.parts[0].material];
    const Material& mb = back.materials[b.parts[0].material];
    EXPECT_NEAR(glm::distance(ma.base_color, mb.base_color), 0.0f, 1e-6f) << a.name;
    EXPECT_EQ(ma.unlit, mb.unlit);
    EXPECT_EQ(ma.double_sided, mb.double_sided);
    EXPECT_EQ(bool(ma.texture), bool(mb.texture));
    // Every world-space vertex comes back where it was (transforms converted to Y up and back).
    const Mesh& mesh_a = src.meshes[a.parts[0].mesh];
    const Mesh& mesh_b = back.meshes[b.parts[0].mesh];
    ASSERT_EQ(mesh_a.positions.size(), mesh_b.positions.size());
    for (size_t v = 0; v < mesh_a.positions.size(); ++v) {
      const Vec3 pa(a.transform * Vec4(mesh_a.positions[v], 1.0f)), pb(b.transform * Vec4(mesh_b.positions[v], 1.0f));
      EXPECT_NEAR(glm::distance(pa, pb), 0.0f, 1e-4f) << a.name << " vertex " << v;
      if (!mesh_a.uvs.empty()) {
        EXPECT_EQ(mesh_a.uvs[v], mesh_b.uvs[v]);
      }
    }
  }
  // The texture keeps its size and (PNG is lossless) its pixels, and is stored once.
  const auto& ta = *src.materials[0].texture;
  const Material& ground = back.materials[back.objects[0].parts[0].material];
  ASSERT_TRUE(ground.texture);
  EXPECT_EQ(ground.texture->width(), ta.width());
  EXPECT_EQ(ground.texture->height(), ta.height());
  EXPECT_EQ(ground.texture->pixels(), ta.pixels());
  EXPECT_EQ(back.stats().textures, 1u);
}

TEST(ExportGlb, TruncatedFileGivesError) {
  const auto dir = test::scratchDir("export_glb_truncated");
  const std::string good = (dir / "cube.glb").string();
  exportGlb(builtinScene("cubes"), good);
  std::ifstream in(good, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 1000u);
  for (size_t cut : {bytes.size() / 2, size_t(10), size_t(30), bytes.size() - 1}) {
    const std::string path = (dir / ("cut_" + std::to_string(cut) + ".glb")).string();
    std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(cut));
    try {
      importScene(path);
      ADD_FAILURE() << "cut at " << cut << ": expected farfield::Error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
}

TEST(ExportGlb, UnwritablePathGivesError) {
  const std::string path = (test::scratchDir("export_glb_bad") / "no_dir" / "x.glb").string();
  try {
    exportGlb(builtinScene("cube"), path);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("x.glb"), std::string::npos);
  }
}

}  // namespace
}  // namespace farfield::scene
