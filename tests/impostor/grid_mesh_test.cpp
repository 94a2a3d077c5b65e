#include "farfield/impostor/grid_mesh.h"

#include <gtest/gtest.h>

#include "farfield/impostor/contour.h"

namespace farfield::impostor {
namespace {

Camera camera64() {
  Camera c;
  c.eye = Vec3(0.0f, 0.0f, 2.0f);
  c.at = Vec3(0.0f, 100.0f, 2.0f);
  c.width = c.height = 64;
  c.near_plane = 1.0f;
  c.far_plane = 1000.0f;
  return c;
}

TEST(GridMeshTest, FullImageGivesTheWholeGridOnAPlane) {
  const Camera camera = camera64();
  // Every pixel at 50 m: a plane facing the camera.
  const float z = camera.project(camera.eye + camera.forward() * 50.0f).z;
  const image::ColorImage color(64, 64, image::Rgba8(100, 100, 100, 255));
  const image::DepthImage depth(64, 64, z);
  GridMeshOptions options;
  options.grid_spacing_px = 16.0;
  const DepthMeshImpostor grid = buildGridMesh(color, depth, camera, options);
  EXPECT_EQ(grid.mesh.triangleCount(), 4u * 4u * 2u);
  EXPECT_EQ(grid.mesh.vertexCount(), 5u * 5u);
  for (const Vec3& p : grid.mesh.positions) EXPECT_NEAR(p.y, 50.0f, 0.05f);  // the plane y = 50
  // uvs are the grid's image positions over the size: multiples of 16 / 64.
  for (const Vec2& uv : grid.mesh.uvs) {
    EXPECT_FLOAT_EQ(uv.x * 4.0f, std::round(uv.x * 4.0f));
    EXPECT_FLOAT_EQ(uv.y * 4.0f, std::round(uv.y * 4.0f));
  }
}

TEST(GridMeshTest, BackgroundCellsAreDroppedAndEdgeVerticesTakeTheNearestData) {
  const Camera camera = camera64();
  const float z = camera.project(camera.eye + camera.forward() * 80.0f).z;
  image::ColorImage color(64, 64, image::Rgba8(0, 0, 0, 255));
  image::DepthImage depth(64, 64, 0.0f);
  // Data in the block [10, 30) x [20, 40): touches grid cells 0..1 in x and 1..2 in y (spacing 16).
  for (int y = 20; y < 40; ++y)
    for (int x = 10; x < 30; ++x) depth.at(x, y) = z;
  GridMeshOptions options;
  options.grid_spacing_px = 16.0;
  const DepthMeshImpostor grid = buildGridMesh(color, depth, camera, options);
  // Brute force: a triangle is kept when a data pixel centre lies in it; count over the 2 x 16 x 16 triangles.
  size_t expected = 0;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i)
      for (int half = 0; half < 2; ++half) {
        bool any = false;
        for (int y = 20; y < 40; ++y)
          for (int x = 10; x < 30; ++x) {
            const double u = x + 0.5 - 16.0 * i, v = y + 0.5 - 16.0 * j;
            if (u < 0 || v < 0 || u > 16 || v > 16) continue;
            // Cell split along its (0,0)-(16,16) diagonal: half 0 above it (v <= u), half 1 below (v >= u).
            if (half == 0 ? v <= u : v >= u) any = true;
          }
        expected += any ? 1 : 0;
      }
  EXPECT_EQ(grid.mesh.triangleCount(), expected);
  EXPECT_EQ(grid.stats.vertices_without_depth, 0u);
  // All vertices, even those on background, lie on the data's plane (nearest-data depth).
  for (const Vec3& p : grid.mesh.positions) EXPECT_NEAR(p.y, 80.0f, 0.1f);
  // Alpha of the texture is the data mask.
  ASSERT_NE(grid.texture, nullptr);
  EXPECT_EQ(grid.texture->at(15, 25).a, 255);
  EXPECT_EQ(grid.texture->at(5, 5).a, 0);
}

}  // namespace
}  // namespace farfield::impostor
