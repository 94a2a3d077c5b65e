#include "farfield/gpu/renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
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

// A small "city": blocks of boxes as single meshes (two parts each: walls and a flat ground slab), under object
// transforms that turn, scale and mirror them, plus a double-sided sheet; small clusters so culling has units to drop.
class CulledItemsTest : public GpuTest {
 protected:
  void SetUp() override {
    GpuTest::SetUp();
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    scene::Material plain;
    plain.base_color = Vec4(0.8f, 0.7f, 0.6f, 1.0f);
    const uint32_t walls = scene_.addMaterial(plain);
    plain.base_color = Vec4(0.3f, 0.6f, 0.3f, 1.0f);
    const uint32_t slab = scene_.addMaterial(plain);
    plain.base_color = Vec4(0.2f, 0.3f, 0.9f, 1.0f);
    plain.double_sided = true;
    const uint32_t sheet = scene_.addMaterial(plain);
    for (int b = 0; b < 6; ++b) {
      scene::Mesh block;
      for (int i = 0; i < 40; ++i) {
        const Vec3 lo(u(rng) * 16.0f, u(rng) * 16.0f, 0.0f);
        const Vec3 size(0.5f + u(rng) * 3.0f, 0.5f + u(rng) * 3.0f, 1.0f + u(rng) * 8.0f);
        block.append(scene::makeBox(Vec3(0.0f), size),
                     glm::rotate(glm::translate(Mat4(1.0f), lo), 0.4f * float(i % 3), Vec3(0, 0, 1)));
      }
      block.computeBounds();
      scene::Object object;
      object.name = "block " + std::to_string(b);
      object.parts.push_back({scene_.addMesh(std::move(block)), walls});
      object.parts.push_back({scene_.addMesh(scene::makeBox(Vec3(-1, -1, -0.2f), Vec3(17, 17, 0))), slab});
      Mat4 m = glm::translate(Mat4(1.0f), Vec3(float(b % 3) * 22.0f - 30.0f, float(b / 3) * 22.0f - 20.0f, 0.0f));
      if (b == 1) m = glm::rotate(m, 0.7f, Vec3(0, 0, 1));
      if (b == 2) m = glm::scale(m, Vec3(1.3f, 0.8f, 1.1f));
      if (b == 4) m = glm::scale(glm::translate(m, Vec3(16.0f, 0.0f, 0.0f)), Vec3(-1.0f, 1.0f, 1.0f));  // mirrored
      object.transform = m;
      scene_.addObject(std::move(object));
    }
    scene::Object object;
    object.name = "sheet";
    scene::Mesh sheet_mesh;
    for (int i = 0; i < 8; ++i)
      sheet_mesh.append(scene::makeGroundQuad(Vec2(float(i) * 3.0f, 0.0f), Vec2(float(i) * 3.0f + 3.0f, 2.0f)));
    object.parts.push_back({scene_.addMesh(std::move(sheet_mesh)), sheet});
    object.transform = glm::rotate(glm::translate(Mat4(1.0f), Vec3(-20.0f, 30.0f, 6.0f)), 1.2f, Vec3(1, 0, 0));
    scene_.addObject(std::move(object));
    GpuSceneOptions options;
    options.cluster_triangles = 24;
    options.min_facing_triangles = 2;
    options.bridge_triangles = 0;
    gpu_scene_ = std::make_unique<GpuScene>(scene_, options);
    options.bridge_triangles = 30;
    bridged_scene_ = std::make_unique<GpuScene>(scene_, options);
  }

  Camera randomCamera(std::mt19937& rng) const {
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    Camera camera;
    camera.width = 96;
    camera.height = 64;
    camera.near_plane = 0.2f;
    camera.far_plane = 300.0f;
    camera.fov_y = float(degToRad(35.0 + 30.0 * (u(rng) + 1.0)));
    // Inside the blocks at street height, above them, and outside looking in.
    const float r = 50.0f * (u(rng) + 1.0f);
    camera.eye = Vec3(r * u(rng), r * u(rng), 1.5f + 15.0f * (u(rng) + 1.0f));
    camera.at = camera.eye + Vec3(u(rng), u(rng), 0.6f * u(rng) - 0.2f);
    return camera;
  }

  uint64_t triangleCount(const std::vector<DrawItem>& items) const {
    uint64_t n = 0;
    for (const DrawItem& item : items) n += item.triangleCount();
    return n;
  }

  scene::Scene scene_;
  std::unique_ptr<GpuScene> gpu_scene_;
  std::unique_ptr<GpuScene> bridged_scene_;  // the same, drawing small culled clusters between drawn ones
};

TEST_F(CulledItemsTest, CulledFramesAreIdenticalToAllItemsFromRandomCameras) {
  Renderer renderer;
  RenderTarget target(96, 64);
  const std::vector<DrawItem> all = gpu_scene_->drawItems();
  const uint64_t all_triangles = triangleCount(all);
  std::mt19937 rng(5);
  uint64_t frustum_triangles = 0, camera_triangles = 0;
  int frames_with_pixels = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const Camera camera = randomCamera(rng);
    // The bridged scene's items draw from its own meshes: compared against its own full frame.
    std::vector<DrawItem> by_frustum, by_camera, bridged;
    gpu_scene_->appendDrawItems({}, by_frustum, Frustum::fromMatrix(camera.viewProjection()));
    gpu_scene_->appendDrawItems({}, by_camera, camera);
    bridged_scene_->appendDrawItems({}, bridged, camera);
    frustum_triangles += triangleCount(by_frustum);
    camera_triangles += triangleCount(by_camera);
    const std::vector<DrawItem> bridged_all = bridged_scene_->drawItems();
    for (RenderMode mode : {RenderMode::Shaded, RenderMode::ItemBuffer}) {
      for (const auto* items : {&by_frustum, &by_camera, &bridged}) {
        renderer.render(camera, items == &bridged ? bridged_all : all, target, mode);
        const image::ColorImage want_color = target.readColor();
        const image::IdImage want_ids = target.readIds();
        if (items == &by_frustum)
          frames_with_pixels += std::count_if(want_ids.pixels().begin(), want_ids.pixels().end(),
                                              [](uint32_t id) { return id != 0; }) > 0;
        const char* what = items == &by_frustum ? ", frustum" : items == &by_camera ? ", camera" : ", bridged";
        const FrameStats stats = renderer.render(camera, *items, target, mode);
        EXPECT_EQ(stats.triangles, triangleCount(*items));
        ASSERT_TRUE(target.readIds().pixels() == want_ids.pixels()) << "trial " << trial << what;
        ASSERT_TRUE(target.readColor().pixels() == want_color.pixels()) << "trial " << trial << what;
      }
    }
  }
  // Not vacuous: most frames show something, and each overload drops a good share of what is out of its reach.
  EXPECT_GT(frames_with_pixels, 60);
  EXPECT_LT(frustum_triangles, 60 * all_triangles * 3 / 4);
  EXPECT_LT(camera_triangles, frustum_triangles * 3 / 4);
}

TEST_F(CulledItemsTest, DropsClustersOutOfView) {
  // Looking down at a corner of the first block (at x, y from -31 to -12) with a narrow view: a corner of it in view.
  Camera camera;
  camera.width = 96;
  camera.height = 64;
  camera.fov_y = float(degToRad(12.0));
  camera.eye = Vec3(-28.0f, -18.0f, 40.0f);
  camera.at = Vec3(-28.0f, -18.0f, 0.0f);
  camera.up = Vec3(0.0f, 1.0f, 0.0f);
  const uint32_t first[] = {1};
  std::vector<DrawItem> all, culled;
  gpu_scene_->appendDrawItems(first, all);
  gpu_scene_->appendDrawItems(first, culled, Frustum::fromMatrix(camera.viewProjection()));
  EXPECT_GT(triangleCount(culled), 0u);
  EXPECT_LT(triangleCount(culled), triangleCount(all) / 3);
  // Drawn as ranges of the same meshes.
  for (const DrawItem& item : culled) {
    EXPECT_GT(item.index_count, 0u);
    EXPECT_LE(item.first_index + item.index_count, item.mesh->indexCount());
  }
}

TEST_F(CulledItemsTest, ClustersHoldEveryTriangleOnceAndItemsKeepObjectIds) {
  for (uint32_t m = 0; m < scene_.meshes.size(); ++m) {
    uint64_t sum = 0;
    uint32_t next = 0;
    for (const MeshCluster& cluster : gpu_scene_->clusters(m)) {
      EXPECT_EQ(cluster.first_index, next);
      next += cluster.index_count;
      sum += cluster.index_count / 3;
    }
    EXPECT_EQ(sum, scene_.meshes[m].triangleCount()) << "mesh " << m;
    EXPECT_EQ(next, gpu_scene_->meshes()[m].indexCount());
  }
  EXPECT_GT(gpu_scene_->clusters(0).size(), 10u);

  // A frustum around everything keeps every triangle, as whole parts (the runs of clusters merge).
  Camera far_camera;
  far_camera.eye = Vec3(0.0f, -400.0f, 300.0f);
  far_camera.at = Vec3(0.0f, 0.0f, 0.0f);
  far_camera.far_plane = 2000.0f;
  std::vector<DrawItem> all = gpu_scene_->drawItems(), culled;
  gpu_scene_->appendDrawItems({}, culled, Frustum::fromMatrix(far_camera.viewProjection()));
  EXPECT_EQ(triangleCount(culled), triangleCount(all));
  EXPECT_EQ(culled.size(), all.size());

  // Items of chosen objects, from many cameras: each names its object, with its transform, and one of its parts.
  std::mt19937 rng(9);
  const uint32_t ids[] = {2, 5, 7};
  for (int trial = 0; trial < 30; ++trial) {
    const Camera camera = randomCamera(rng);
    std::vector<DrawItem> items;
    gpu_scene_->appendDrawItems(ids, items, camera);
    for (const DrawItem& item : items) {
      ASSERT_TRUE(item.object_id == 2 || item.object_id == 5 || item.object_id == 7) << item.object_id;
      const scene::Object& object = scene_.object(item.object_id);
      EXPECT_EQ(item.transform, object.transform);
      const bool of_object = std::any_of(object.parts.begin(), object.parts.end(), [&](const scene::Part& part) {
        return &gpu_scene_->meshes()[part.mesh] == item.mesh;
      });
      EXPECT_TRUE(of_object);
    }
  }
  const uint32_t bad[] = {uint32_t(scene_.objects.size() + 1)};
  std::vector<DrawItem> items;
  EXPECT_THROW(gpu_scene_->appendDrawItems(bad, items, far_camera), Error);
}

TEST_F(GpuTest, DrawItemIndexRangeDrawsOnlyThoseTriangles) {
  // The unit cube face by face (two triangles, six indices each): the faces seen cover what the whole cube covers,
  // with the same ids, and the faces turned away cover nothing.
  const GpuMesh cube(scene::makeUnitCube());
  GpuMaterial material;
  Camera camera = test::testCamera(Vec3(2.0f, -3.0f, 2.5f), Vec3(0.0f));
  RenderTarget target(camera.width, camera.height);
  Renderer renderer;
  const DrawItem whole{&cube, &material, Mat4(1.0f), 1};
  EXPECT_EQ(renderer.render(camera, {&whole, 1}, target).triangles, 12u);
  const auto covered = [](const image::IdImage& ids) {
    return std::count_if(ids.pixels().begin(), ids.pixels().end(), [](uint32_t id) { return id != 0; });
  };
  const long whole_covered = covered(target.readIds());
  long sum = 0;
  int faces_seen = 0;
  for (uint32_t face = 0; face < 6; ++face) {
    const DrawItem part{&cube, &material, Mat4(1.0f), 1, 6 * face, 6};
    EXPECT_EQ(renderer.render(camera, {&part, 1}, target).triangles, 2u);
    const long c = covered(target.readIds());
    sum += c;
    faces_seen += c > 0;
  }
  EXPECT_EQ(faces_seen, 3);
  EXPECT_EQ(sum, whole_covered);
}

}  // namespace
}  // namespace farfield::gpu
