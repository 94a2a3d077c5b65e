#include "farfield/impostor/drawable.h"

#include <gtest/gtest.h>

#include <random>

#include "farfield/impostor/impostor_mesh.h"

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
