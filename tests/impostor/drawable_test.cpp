#include "farfield/impostor/drawable.h"

#include <gtest/gtest.h>

#include <random>

#include "farfield/impostor/impostor_mesh.h"
#include "farfield/impostor/capture.h"
#include "farfield/impostor/grid_mesh.h"
#include "impostor_fixture.h"

namespace farfield::impostor {
namespace {

TEST(DrawableTest, TextureProjectionGivesTheImagePositionOverTheSize) {
  Camera camera;
  camera.eye = Vec3(3.0f, -20.0f, 5.0f);
  camera.at = Vec3(10.0f, 50.0f, 12.0f);
  camera.width = 320;
  camera.height = 200;
  const Mat4 t = textureProjection(camera);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-40.0f, 40.0f);
  for (int i = 0; i < 50; ++i) {
    const Vec3 p = camera.at + Vec3(u(rng), u(rng), u(rng));
    float w = 0.0f;
    const Vec3 image = camera.project(p, &w);
    if (w <= 0.0f) continue;
    const Vec4 q = t * Vec4(p, 1.0f);
    EXPECT_NEAR(q.x / q.w, image.x / camera.width, 1e-5f);
    EXPECT_NEAR(q.y / q.w, image.y / camera.height, 1e-5f);
  }
  // The image's top-left corner ray maps to uv (0, 0), the bottom-right to (1, 1).
  const Vec4 tl = t * Vec4(camera.unproject(0.0f, 0.0f, 0.3f), 1.0f);
  const Vec4 br = t * Vec4(camera.unproject(320.0f, 200.0f, 0.3f), 1.0f);
  EXPECT_NEAR(tl.x / tl.w, 0.0f, 1e-4f);
  EXPECT_NEAR(tl.y / tl.w, 0.0f, 1e-4f);
  EXPECT_NEAR(br.x / br.w, 1.0f, 1e-4f);
  EXPECT_NEAR(br.y / br.w, 1.0f, 1e-4f);
}

TEST(DrawableTest, SplitByObjectIdKeepsEveryTriangle) {
  scene::Mesh mesh;
  for (int i = 0; i < 6; ++i) {
    mesh.positions.push_back(Vec3(float(i), float(i * i), 1.0f));
    mesh.uvs.push_back(Vec2(0.1f * float(i), 0.2f));
  }
  mesh.indices = {0, 1, 2, 1, 2, 3, 2, 3, 4, 3, 4, 5};
  const std::vector<uint32_t> ids = {7, 3, 7, 0};
  const std::vector<IdMesh> parts = splitByObjectId(mesh, ids);
  ASSERT_EQ(parts.size(), 3u);
  size_t triangles = 0;
  for (const IdMesh& part : parts) {
    triangles += part.mesh.triangleCount();
    EXPECT_EQ(part.mesh.uvs.size(), part.mesh.positions.size());
    // Each triangle of the part is one of the input triangles with that id, in order.
    size_t k = 0;
    for (size_t t = 0; t < ids.size(); ++t) {
      if (ids[t] != part.id) continue;
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(part.mesh.positions[part.mesh.indices[3 * k + size_t(c)]], mesh.positions[mesh.indices[3 * t + size_t(c)]]);
        EXPECT_EQ(part.mesh.uvs[part.mesh.indices[3 * k + size_t(c)]], mesh.uvs[mesh.indices[3 * t + size_t(c)]]);
      }
      ++k;
    }
    EXPECT_EQ(k, part.mesh.triangleCount());
  }
  EXPECT_EQ(triangles, mesh.triangleCount());
}

TEST(DrawableTest, SceneImpostorIsUnlitDoubleSidedAndTextured) {
  DepthMeshImpostor impostor;
  impostor.mesh.positions = {Vec3(0.0f), Vec3(1.0f, 0.0f, 0.0f), Vec3(0.0f, 0.0f, 1.0f)};
  impostor.mesh.uvs = {Vec2(0.0f), Vec2(1.0f, 0.0f), Vec2(0.0f, 1.0f)};
  impostor.mesh.indices = {0, 1, 2};
  impostor.texture = std::make_shared<image::ColorImage>(4, 4, image::Rgba8(1, 2, 3, 255));
  const SceneImpostor s = toSceneImpostor(impostor, "cell 12");
  EXPECT_TRUE(s.material.unlit);
  EXPECT_TRUE(s.material.double_sided);
  EXPECT_EQ(s.material.texture, impostor.texture);
  EXPECT_EQ(s.material.name, "cell 12");
  EXPECT_EQ(s.mesh.indices, impostor.mesh.indices);
}

}  // namespace
}  // namespace farfield::impostor

// Per-texel ids (GpuImpostorOptions::id_texture): drawn from its creation camera, an impostor's item buffer must
// equal the capture's ids on every data pixel, including pixels of grid triangles that straddle two objects (whose
// majority id, split_by_object_id's, is wrong for part of their pixels). Reference: the capture itself.
namespace farfield::impostor {
namespace {

class DrawableIdTextureTest : public test::ImpostorGpuTest {};

TEST_F(DrawableIdTextureTest, ItemBufferShowsTheCapturedObjectOfEveryPixel) {
  test::BoxScene boxes;
  const uint32_t a = boxes.addBox({-6.0f, 20.0f, 0.0f}, {-1.0f, 24.0f, 6.0f}, {0.8f, 0.2f, 0.2f});
  const uint32_t b = boxes.addBox({-1.5f, 34.0f, 0.0f}, {5.0f, 38.0f, 9.0f}, {0.2f, 0.8f, 0.2f});
  const uint32_t c = boxes.addBox({3.0f, 60.0f, 0.0f}, {9.0f, 64.0f, 14.0f}, {0.2f, 0.2f, 0.8f});
  gpu::GpuScene gpu_scene(boxes.scene);
  const Camera camera = test::makeCamera({0.0f, 0.0f, 2.0f}, {0.0f, 40.0f, 3.0f}, 128);
  const std::vector<uint32_t> objects{a, b, c};
  const ImpostorCapture capture = captureView(*renderer_, gpu_scene, objects, camera);
  GridMeshOptions grid;
  grid.grid_spacing_px = 16.0;  // coarse: many triangles cover two objects
  const DepthMeshImpostor impostor = buildGridMesh(capture, grid);
  ASSERT_TRUE(impostor.ids);

  const auto idsOf = [&](const GpuImpostorOptions& options) {
    GpuImpostor gpu(impostor, options);
    std::vector<gpu::DrawItem> items;
    gpu.appendDrawItems(items, 999);
    return test::renderItems(*renderer_, camera, items).ids;
  };
  GpuImpostorOptions with_texture;
  with_texture.id_texture = true;
  GpuImpostorOptions split;
  split.split_by_object_id = true;
  const image::IdImage texel_ids = idsOf(with_texture), triangle_ids = idsOf(split);
  size_t data = 0, texel_wrong = 0, triangle_wrong = 0;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const uint32_t want = capture.ids.at(x, y);
      if (want == 0) continue;
      ++data;
      texel_wrong += texel_ids.at(x, y) != want ? 1 : 0;
      triangle_wrong += triangle_ids.at(x, y) != want ? 1 : 0;
    }
  ASSERT_GT(data, 1000u);
  EXPECT_EQ(texel_wrong, 0u);
  // The per-triangle majority gets the straddling triangles' minority pixels wrong: the case the texture fixes.
  EXPECT_GT(triangle_wrong, 0u);
}

}  // namespace
}  // namespace farfield::impostor
