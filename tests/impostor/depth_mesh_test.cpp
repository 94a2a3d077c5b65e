#include "farfield/impostor/depth_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "farfield/core/error.h"
#include "farfield/image/metrics.h"
#include "farfield/image/png_io.h"
#include "support/test_support.h"
#include "farfield/impostor/capture.h"
#include "farfield/impostor/drawable.h"
#include "farfield/impostor/grid_mesh.h"
#include "impostor/impostor_fixture.h"

namespace farfield::impostor {
namespace {

using test::BoxScene;
using test::ImpostorGpuTest;

// Boxes at several distances on a ground quad, seen from street level at an angle (no face exactly edge-on).
BoxScene streetScene() {
  BoxScene s;
  s.addGround({-150.0f, -10.0f}, {150.0f, 400.0f});
  s.addBox({-12.0f, 25.0f, 0.0f}, {-4.0f, 33.0f, 18.0f}, {0.8f, 0.3f, 0.2f});
  s.addBox({3.0f, 40.0f, 0.0f}, {11.0f, 52.0f, 30.0f}, {0.2f, 0.5f, 0.8f});
  s.addBox({-20.0f, 110.0f, 0.0f}, {5.0f, 130.0f, 60.0f}, {0.9f, 0.8f, 0.3f});
  s.addBox({12.0f, 180.0f, 0.0f}, {40.0f, 210.0f, 90.0f}, {0.5f, 0.8f, 0.4f});
  s.addBox({-60.0f, 250.0f, 0.0f}, {-30.0f, 280.0f, 45.0f}, {0.7f, 0.4f, 0.8f});
  return s;
}

Camera streetCamera(int size) {
  return test::makeCamera({-3.0f, -5.0f, 2.0f}, {4.0f, 100.0f, 12.0f}, size, 0.5f, 2000.0f);
}

double footprint(const Camera& camera, double distance) {
  return distance * 2.0 * std::tan(camera.fov_y * 0.5) / camera.height;
}

TEST_F(ImpostorGpuTest, EveryVertexLiesOnTheGeometry) {
  const BoxScene s = streetScene();
  const gpu::GpuScene gpu_scene(s.scene);
  const Camera camera = streetCamera(256);
  const std::vector<uint32_t> ids = {1, 2, 3, 4, 5, 6};
  const ImpostorCapture capture = captureView(*renderer_, gpu_scene, ids, camera);
  const DepthMeshImpostor impostor = buildDepthMesh(capture);
  ASSERT_FALSE(impostor.empty());
  EXPECT_EQ(impostor.stats.vertices_without_depth, 0u);
  EXPECT_GT(impostor.stats.chains, 0u);
  size_t checked = 0;
  for (const Vec3& p : impostor.mesh.positions) {
    const double d = glm::length(DVec3(p - camera.eye));
    // Within two pixel footprints at that distance (a pixel-corner vertex is extrapolated along its face's plane
    // by less than a pixel; a wrong side or the background would be metres off).
    EXPECT_LE(s.distanceToSurface(p), 2.0 * footprint(camera, d) + 1e-3 * d)
        << "vertex (" << p.x << ", " << p.y << ", " << p.z << ") at " << d << " m";
    ++checked;
  }
  EXPECT_EQ(checked, impostor.mesh.vertexCount());
}

TEST_F(ImpostorGpuTest, CreationViewReproducesTheCapture) {
  const scene::Scene cubes = scene::builtinScene("cubes");  // textured ground, 25 coloured boxes
  const gpu::GpuScene gpu_scene(cubes);
  std::vector<uint32_t> ids;
  for (const scene::Object& o : cubes.objects) ids.push_back(o.id);
  const Camera camera = test::makeCamera({-14.0f, -16.0f, 4.0f}, {2.0f, 2.0f, 0.5f}, 256, 0.5f, 500.0f);
  const ImpostorCapture capture = captureView(*renderer_, gpu_scene, ids, camera);
  ASSERT_GT(capture.data_pixels, 0u);
  EXPECT_EQ(capture.seen_from_below_pixels, 0u);

  const DepthMeshImpostor impostor = buildDepthMesh(capture);
  ASSERT_FALSE(impostor.empty());
  const GpuImpostor gpu_impostor(impostor);
  std::vector<gpu::DrawItem> items;
  gpu_impostor.appendDrawItems(items, 1);
  const test::Frame frame = test::renderItems(*renderer_, camera, items);
  const image::ImageMetrics m = image::compareImages(frame.color, capture.color);
  std::printf("depth mesh: %zu triangles, PSNR %.2f dB, %.3f%% over 8/255\n", impostor.stats.triangles, m.psnr_db,
              100.0 * m.bad_pixel_share);
  EXPECT_GE(m.psnr_db, 35.0);
  EXPECT_LE(m.bad_pixel_share, 0.01);
  if (m.psnr_db < 35.0 || m.bad_pixel_share > 0.01) {
    const auto dir = farfield::test::scratchDir("impostor_creation_view");
    image::writePng((dir / "capture.png").string(), capture.color);
    image::writePng((dir / "impostor.png").string(), frame.color);
    image::writePng((dir / "diff.png").string(), image::diffHeatmap(frame.color, capture.color));
  }

  // Drawn with the mesh's interpolated uvs instead (a renderer without projective texturing), the texture warp
  // refinement keeps the same bar, at the cost of more triangles.
  DepthMeshOptions refined;
  refined.max_texture_warp_px = 0.2;
  const DepthMeshImpostor uv_impostor = buildDepthMesh(capture, refined);
  GpuImpostorOptions uv_options;
  uv_options.projective_texture = false;
  const GpuImpostor gpu_uv(uv_impostor, uv_options);
  items.clear();
  gpu_uv.appendDrawItems(items, 1);
  const image::ImageMetrics u = image::compareImages(test::renderItems(*renderer_, camera, items).color, capture.color);
  std::printf("depth mesh with uvs: %zu triangles (%zu refinement vertices), PSNR %.2f dB, %.3f%% over 8/255\n",
              uv_impostor.stats.triangles, uv_impostor.stats.refinement_vertices, u.psnr_db,
              100.0 * u.bad_pixel_share);
  EXPECT_GT(uv_impostor.stats.refinement_vertices, 0u);
  EXPECT_GE(u.psnr_db, 35.0);
  EXPECT_LE(u.bad_pixel_share, 0.01);

  // The grid baseline covers the same pixels.
  const DepthMeshImpostor grid = buildGridMesh(capture);
  const GpuImpostor gpu_grid(grid);
  items.clear();
  gpu_grid.appendDrawItems(items, 1);
  const image::ImageMetrics g = image::compareImages(test::renderItems(*renderer_, camera, items).color, capture.color);
  std::printf("grid mesh: %zu triangles, PSNR %.2f dB, %.3f%% over 8/255\n", grid.stats.triangles, g.psnr_db,
              100.0 * g.bad_pixel_share);
  EXPECT_GE(g.psnr_db, 35.0);
  EXPECT_LE(g.bad_pixel_share, 0.01);
}

TEST_F(ImpostorGpuTest, EmptyCaptureGivesAnEmptyImpostor) {
  const BoxScene s = streetScene();
  const gpu::GpuScene gpu_scene(s.scene);
  const Camera camera = streetCamera(64);
  const ImpostorCapture nothing = captureView(*renderer_, gpu_scene, {}, camera);
  EXPECT_EQ(nothing.data_pixels, 0u);
  const DepthMeshImpostor empty = buildDepthMesh(nothing);
  EXPECT_TRUE(empty.empty());
  EXPECT_EQ(empty.mesh.vertexCount(), 0u);
  EXPECT_EQ(empty.texture, nullptr);
  EXPECT_TRUE(buildGridMesh(nothing).empty());
  const GpuImpostor gpu_empty(empty);
  std::vector<gpu::DrawItem> items;
  gpu_empty.appendDrawItems(items);
  EXPECT_TRUE(items.empty());
  // Objects behind the camera: drawn, but nothing lands in the image.
  const Camera backwards = test::makeCamera({0.0f, -5.0f, 2.0f}, {0.0f, -100.0f, 2.0f}, 64);
  const std::vector<uint32_t> boxes = {2, 3, 4};
  EXPECT_TRUE(buildDepthMesh(captureView(*renderer_, gpu_scene, boxes, backwards)).empty());
}

TEST_F(ImpostorGpuTest, BadInputIsReported) {
  const Camera camera = streetCamera(32);
  const image::ColorImage color(32, 32, image::Rgba8(0, 0, 0, 255));
  EXPECT_THROW(buildDepthMesh(color, image::DepthImage(16, 16, 0.5f), camera), Error);
  EXPECT_THROW(buildDepthMesh(image::ColorImage(16, 32), image::DepthImage(32, 32, 0.5f), camera), Error);
  image::DepthImage bad(32, 32, 0.5f);
  bad.at(3, 4) = std::nanf("");
  EXPECT_THROW(buildDepthMesh(color, bad, camera), Error);
  bad.at(3, 4) = 1.5f;
  EXPECT_THROW(buildGridMesh(color, bad, camera), Error);
  Camera broken = camera;
  broken.at = broken.eye;
  EXPECT_THROW(buildDepthMesh(color, image::DepthImage(32, 32, 0.5f), broken), Error);
  EXPECT_THROW(creationCamera(Vec3(5.0f), Vec3(5.0f), DepthMeshOptions{}, 1.0f, 100.0f), Error);  // zero-length
  EXPECT_THROW(creationCamera(Vec3(0.0f), Vec3(0.0f, 0.0f, 10.0f), DepthMeshOptions{}, 1.0f, 100.0f), Error);
  const Camera made = creationCamera(Vec3(0.0f), Vec3(0.0f, 10.0f, 0.0f), DepthMeshOptions{}, 1.0f, 100.0f);
  EXPECT_EQ(made.width, 512);
  EXPECT_EQ(made.height, 512);
  GridMeshOptions zero;
  zero.grid_spacing_px = 0.0;
  EXPECT_THROW(buildGridMesh(color, image::DepthImage(32, 32, 0.5f), camera, zero), Error);
}

}  // namespace
}  // namespace farfield::impostor
