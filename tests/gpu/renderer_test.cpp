#include "farfield/gpu/renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/scene/builtin.h"
#include "gpu/gpu_fixture.h"

namespace farfield::gpu {
namespace {

using test::GpuTest;

Mat4 translate(const Vec3& t, float scale = 1.0f) {
  return glm::scale(glm::translate(Mat4(1.0f), t), Vec3(scale));
}

// A unit cube seen from above a corner: the +x, -y and +z faces are visible.
class CubeTest : public GpuTest {
 protected:
  void SetUp() override {
    GpuTest::SetUp();
    renderer_ = std::make_unique<Renderer>();
    cube_ = std::make_unique<GpuMesh>(scene::makeUnitCube());
    material_.base_color = Vec4(0.8f, 0.6f, 0.4f, 1.0f);
  }
  std::unique_ptr<Renderer> renderer_;
  std::unique_ptr<GpuMesh> cube_;
  GpuMaterial material_;
  Camera camera_ = test::testCamera(Vec3(2.0f, -3.0f, 2.5f), Vec3(0.0f));
};

TEST_F(CubeTest, FacesHaveTheLitColourAndTheCornerIsSky) {
  RenderTarget target(camera_.width, camera_.height);
  const DrawItem item{cube_.get(), &material_, Mat4(1.0f), 1};
  renderer_->render(camera_, {&item, 1}, target);
  const image::ColorImage color = target.readColor();
  const Vec3 albedo(material_.base_color);
  const LightSettings& light = renderer_->light();
  struct Face {
    Vec3 center, normal;
  };
  for (const Face& face : {Face{{0.5f, 0, 0}, {1, 0, 0}}, Face{{0, -0.5f, 0}, {0, -1, 0}},
                           Face{{0, 0, 0.5f}, {0, 0, 1}}}) {
    const IVec2 px = test::pixelOf(camera_, face.center);
    EXPECT_TRUE(test::colorNear(color.at(px.x, px.y), test::expectedLit(albedo, face.normal, light)))
        << "face with normal (" << face.normal.x << ", " << face.normal.y << ", " << face.normal.z << ")";
  }
  EXPECT_TRUE(test::colorNear(color.at(0, 0), test::skyColor(light), 1));
  EXPECT_TRUE(test::colorNear(color.at(camera_.width - 1, camera_.height - 1), test::skyColor(light), 1));
}

TEST_F(CubeTest, DepthReprojectsOntoTheCubeFaces) {
  RenderTarget target(camera_.width, camera_.height);
  const DrawItem item{cube_.get(), &material_, Mat4(1.0f), 7};
  renderer_->render(camera_, {&item, 1}, target);
  const image::DepthImage depth = target.readDepth();
  const image::IdImage ids = target.readIds();
  int covered = 0;
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x) {
      const float d = depth.at(x, y);
      if (d <= 0.0f) {
        ASSERT_EQ(ids.at(x, y), 0u) << x << ", " << y;
        continue;
      }
      ++covered;
      ASSERT_EQ(ids.at(x, y), 7u) << x << ", " << y;
      const Vec3 p = camera_.unproject(float(x) + 0.5f, float(y) + 0.5f, d);
      const float m = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
      ASSERT_NEAR(m, 0.5f, 1e-3f) << "pixel " << x << ", " << y << " -> (" << p.x << ", " << p.y << ", " << p.z << ")";
    }
  // The cube covers a good part of the 128 x 128 view (its silhouette spans about 40 pixels).
  EXPECT_GT(covered, 1000);
}

TEST_F(CubeTest, MissingNormalsFallBackToFaceNormals) {
  scene::Mesh mesh = scene::makeUnitCube();
  mesh.normals.clear();
  const GpuMesh no_normals(mesh);
  RenderTarget target(camera_.width, camera_.height);
  const DrawItem item{&no_normals, &material_, Mat4(1.0f), 1};
  renderer_->render(camera_, {&item, 1}, target);
  const image::ColorImage color = target.readColor();
  for (const Vec3& n : {Vec3(1, 0, 0), Vec3(0, -1, 0), Vec3(0, 0, 1)}) {
    const IVec2 px = test::pixelOf(camera_, n * 0.5f);
    EXPECT_TRUE(test::colorNear(color.at(px.x, px.y),
                                test::expectedLit(Vec3(material_.base_color), n, renderer_->light())));
  }
}

TEST_F(CubeTest, MirroringTransformStillShowsTheOuterFaces) {
  // A negative scale flips the triangles' winding; culling must follow, or the far inner faces would show.
  RenderTarget target(camera_.width, camera_.height);
  const DrawItem mirrored{cube_.get(), &material_, glm::scale(Mat4(1.0f), Vec3(-1.0f, 1.0f, 1.0f)), 1};
  renderer_->render(camera_, {&mirrored, 1}, target);
  const image::DepthImage depth = target.readDepth();
  int covered = 0;
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x) {
      if (depth.at(x, y) <= 0.0f) continue;
      ++covered;
      const Vec3 p = camera_.unproject(float(x) + 0.5f, float(y) + 0.5f, depth.at(x, y));
      // Visible outer faces: x = +0.5, y = -0.5, z = +0.5.
      const bool on_near_face = std::abs(p.x - 0.5f) < 1e-3f || std::abs(p.y + 0.5f) < 1e-3f ||
                                std::abs(p.z - 0.5f) < 1e-3f;
      ASSERT_TRUE(on_near_face) << x << ", " << y;
    }
  EXPECT_GT(covered, 1000);
}

TEST_F(CubeTest, BackFacesAreCulledUnlessDoubleSided) {
  // A quad in the plane y = 0 wound to face +y (away from the camera at y = -5), stored normal +y.
  scene::Mesh quad;
  quad.positions = {{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}};
  quad.normals.assign(4, Vec3(0, 1, 0));
  quad.indices = {0, 2, 1, 0, 3, 2};
  const GpuMesh mesh(quad);
  const Camera camera = test::testCamera(Vec3(0, -5, 0), Vec3(0.0f), 64);
  RenderTarget target(64, 64);
  const IVec2 center(32, 32);

  GpuMaterial single = material_;
  const DrawItem a{&mesh, &single, Mat4(1.0f), 3};
  renderer_->render(camera, {&a, 1}, target);
  EXPECT_EQ(target.readIds().at(center.x, center.y), 0u);

  GpuMaterial twin = material_;
  twin.double_sided = true;
  const DrawItem b{&mesh, &twin, Mat4(1.0f), 3};
  renderer_->render(camera, {&b, 1}, target);
  EXPECT_EQ(target.readIds().at(center.x, center.y), 3u);
  // Seen from behind, the surface is lit as if its normal pointed at the camera (-y).
  EXPECT_TRUE(test::colorNear(target.readColor().at(center.x, center.y),
                              test::expectedLit(Vec3(material_.base_color), Vec3(0, -1, 0), renderer_->light())));
}

TEST_F(CubeTest, UnlitMaterialIsTheBaseColour) {
  material_.unlit = true;
  RenderTarget target(camera_.width, camera_.height);
  const DrawItem item{cube_.get(), &material_, Mat4(1.0f), 1};
  renderer_->render(camera_, {&item, 1}, target);
  const image::ColorImage color = target.readColor();
  for (const Vec3& n : {Vec3(1, 0, 0), Vec3(0, -1, 0), Vec3(0, 0, 1)}) {
    const IVec2 px = test::pixelOf(camera_, n * 0.5f);
    EXPECT_TRUE(test::colorNear(color.at(px.x, px.y), Vec3(material_.base_color)));
  }
}

// Three cubes seen head-on: A (id 1) at the origin, B (id 2, half size) right behind A and fully hidden by it,
// C (id 3) to the right.
class ItemBufferTest : public CubeTest {
 protected:
  std::vector<DrawItem> items() const {
    return {{cube_.get(), &material_, translate(Vec3(0.0f)), 1},
            {cube_.get(), &material_, translate(Vec3(0.0f, 2.0f, 0.0f), 0.5f), 2},
            {cube_.get(), &material_, translate(Vec3(2.0f, 0.0f, 0.0f)), 3}};
  }
  Camera camera_ = test::testCamera(Vec3(0.0f, -5.0f, 0.0f), Vec3(0.0f));
};

TEST_F(ItemBufferTest, IdsAtKnownPixelsAndHiddenObjectAbsent) {
  RenderTarget target(camera_.width, camera_.height);
  const std::vector<DrawItem> list = items();
  const FrameStats stats = renderer_->render(camera_, list, target, RenderMode::ItemBuffer);
  EXPECT_EQ(stats.objects, 3u);  // drawn, even if hidden
  EXPECT_EQ(stats.draw_calls, 3u);
  const image::IdImage ids = target.readIds();
  const IVec2 a = test::pixelOf(camera_, Vec3(0.0f, -0.5f, 0.0f));
  const IVec2 c = test::pixelOf(camera_, Vec3(2.0f, -0.5f, 0.0f));
  EXPECT_EQ(ids.at(a.x, a.y), 1u);
  EXPECT_EQ(ids.at(c.x, c.y), 3u);
  EXPECT_EQ(ids.at(0, 0), 0u);
  std::set<uint32_t> seen(ids.pixels().begin(), ids.pixels().end());
  EXPECT_EQ(seen, (std::set<uint32_t>{0u, 1u, 3u}));

  // Depth testing, not submission order, decides: the reversed list gives the same image.
  std::vector<DrawItem> reversed(list.rbegin(), list.rend());
  renderer_->render(camera_, reversed, target, RenderMode::ItemBuffer);
  EXPECT_EQ(target.readIds().pixels(), ids.pixels());
  // Shaded mode writes the same ids.
  renderer_->render(camera_, list, target, RenderMode::Shaded);
  EXPECT_EQ(target.readIds().pixels(), ids.pixels());
}

TEST_F(ItemBufferTest, ItemBufferColourIsFlatPerObject) {
  const Camera camera = test::testCamera(Vec3(2.0f, -3.0f, 2.5f), Vec3(0.0f));
  RenderTarget target(camera.width, camera.height);
  const DrawItem item{cube_.get(), &material_, Mat4(1.0f), 5};
  auto coloursOfObject = [&] {
    const image::ColorImage color = target.readColor();
    const image::IdImage ids = target.readIds();
    std::set<uint32_t> colours;
    for (size_t i = 0; i < ids.pixelCount(); ++i)
      if (ids.pixels()[i] == 5u) {
        const image::Rgba8 c = color.pixels()[i];
        colours.insert(uint32_t(c.r) << 16 | uint32_t(c.g) << 8 | c.b);
      }
    return colours;
  };
  renderer_->render(camera, {&item, 1}, target, RenderMode::ItemBuffer);
  EXPECT_EQ(coloursOfObject().size(), 1u);  // no lighting: three faces, one colour
  renderer_->render(camera, {&item, 1}, target, RenderMode::Shaded);
  EXPECT_GE(coloursOfObject().size(), 3u);  // lit faces differ
}

TEST_F(CubeTest, ReadbackRowZeroIsTheTop) {
  const Camera camera = test::testCamera(Vec3(0.0f, -6.0f, 0.0f), Vec3(0.0f));
  const std::vector<DrawItem> items = {{cube_.get(), &material_, translate(Vec3(0.0f, 0.0f, 1.5f)), 1},
                                       {cube_.get(), &material_, translate(Vec3(1.6f, 0.0f, -0.2f)), 2}};
  RenderTarget target(camera.width, camera.height);
  renderer_->render(camera, items, target);
  const image::IdImage ids = target.readIds();
  int above = 0, right = 0;
  for (int y = 0; y < ids.height(); ++y)
    for (int x = 0; x < ids.width(); ++x) {
      if (ids.at(x, y) == 1u) {
        ++above;
        ASSERT_LT(y, ids.height() / 2) << "object above the view axis seen in row " << y;
      }
      if (ids.at(x, y) == 2u) {
        ++right;
        ASSERT_GT(x, ids.width() / 2) << "object right of the view axis seen in column " << x;
      }
    }
  EXPECT_GT(above, 50);
  EXPECT_GT(right, 50);
  // And the depth and colour images have the same orientation as the ids.
  const IVec2 top = test::pixelOf(camera, Vec3(0.0f, -0.5f, 1.5f));
  EXPECT_GT(target.readDepth().at(top.x, top.y), 0.0f);
  EXPECT_FALSE(test::colorNear(target.readColor().at(top.x, top.y), test::skyColor(renderer_->light()), 4));
  EXPECT_EQ(target.readDepth().at(top.x, ids.height() - 1 - top.y), 0.0f);
}

TEST_F(GpuTest, FrameStatsAreSumsOverTheDrawList) {
  const scene::Scene scene = scene::builtinScene("cubes");
  const GpuScene gpu_scene(scene);
  const std::vector<DrawItem> items = gpu_scene.drawItems();
  uint64_t triangles = 0;
  size_t parts = 0;
  for (const auto& object : scene.objects)
    for (const auto& part : object.parts) {
      triangles += scene.meshes[part.mesh].indices.size() / 3;
      ++parts;
    }
  ASSERT_EQ(items.size(), parts);
  Camera camera = test::testCamera(Vec3(0.0f, -18.0f, 30.0f), Vec3(0.0f), 96);
  RenderTarget target(96, 96);
  Renderer renderer;
  const FrameStats stats = renderer.render(camera, items, target);
  EXPECT_EQ(stats.triangles, triangles);
  EXPECT_EQ(stats.draw_calls, parts);
  EXPECT_EQ(stats.objects, scene.objects.size());
  EXPECT_GT(stats.wall_ms, 0.0);
  EXPECT_GE(stats.gpu_ms, 0.0);
  EXPECT_LE(stats.gpu_ms, stats.wall_ms);  // the GPU cannot work longer than the frame took

  // The whole scene is in view: every object shows up in the id image.
  const image::IdImage ids = target.readIds();
  std::set<uint32_t> seen(ids.pixels().begin(), ids.pixels().end());
  seen.erase(0u);
  EXPECT_EQ(seen.size(), scene.objects.size());
}

TEST_F(GpuTest, GpuSceneDrawItemsForChosenObjects) {
  const scene::Scene scene = scene::builtinScene("cubes");
  const GpuScene gpu_scene(scene);
  std::vector<DrawItem> items;
  const uint32_t ids[] = {3, 5};
  gpu_scene.appendDrawItems(ids, items);
  ASSERT_EQ(items.size(), scene.object(3).parts.size() + scene.object(5).parts.size());
  EXPECT_EQ(items.front().object_id, 3u);
  EXPECT_EQ(items.back().object_id, 5u);
  EXPECT_EQ(items.front().transform, scene.object(3).transform);
  EXPECT_EQ(items.front().mesh->triangleCount(), scene.meshes[scene.object(3).parts[0].mesh].indices.size() / 3);
  const uint32_t bad[] = {0};
  EXPECT_THROW(gpu_scene.appendDrawItems(bad, items), Error);
  const uint32_t too_big[] = {uint32_t(scene.objects.size() + 1)};
  EXPECT_THROW(gpu_scene.appendDrawItems(too_big, items), Error);

  // Meshes at 32 bytes per vertex and 4 per index, plus the one checker texture with its mipmaps.
  size_t mesh_bytes = 0;
  size_t texture_bytes = 0;
  std::set<const image::ColorImage*> images;
  for (const auto& m : scene.meshes) mesh_bytes += m.positions.size() * 32 + m.indices.size() * 4;
  for (const auto& m : scene.materials)
    if (m.texture && images.insert(m.texture.get()).second) texture_bytes += m.texture->pixelCount() * 4;
  EXPECT_GE(gpu_scene.gpuBytes(), mesh_bytes + texture_bytes);
  EXPECT_LE(gpu_scene.gpuBytes(), mesh_bytes + texture_bytes * 4 / 3 + 16);
}

}  // namespace
}  // namespace farfield::gpu
