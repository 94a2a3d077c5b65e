// Parallax (Sillion et al. 1997, section 5: "the church towers in the background correctly recede behind the closer
// buildings"): a near tall box in front of a far tower, the viewer moves 10 m sideways.
#include <gtest/gtest.h>

#include <cstdio>

#include "farfield/impostor/capture.h"
#include "farfield/impostor/depth_mesh.h"
#include "farfield/impostor/drawable.h"
#include "farfield/impostor/grid_mesh.h"
#include "impostor/impostor_fixture.h"

namespace farfield::impostor {
namespace {

using test::BoxScene;
using test::ImpostorGpuTest;

struct Agreement {
  double share = 0.0;        // pixels with the same id, among pixels where either render shows an object
  size_t tower_pixels = 0;   // pixels showing the tower
};

Agreement compareIds(const image::IdImage& reference, const image::IdImage& frame, uint32_t tower) {
  size_t same = 0, counted = 0;
  Agreement a;

  for (size_t i = 0; i < reference.pixelCount(); ++i) {
    const uint32_t r = reference.pixels()[i], f = frame.pixels()[i];
    a.tower_pixels += f == tower ? 1 : 0;
    if (r == 0 && f == 0) continue;
    ++counted;
    same += r == f ? 1 : 0;
  }
  a.share = counted ? double(same) / double(counted) : 1.0;
  return a;
}

size_t countId(const image::IdImage& ids, uint32_t id) {
  size_t n = 0;
  for (uint32_t v : ids.pixels()) n += v == id ? 1 : 0;
  return n;
}

TEST_F(ImpostorGpuTest, TowerRecedesBehindTheNearBoxOnlyWithTheDepthMesh) {
  BoxScene s;
  // The box hides the tower's left end from the creation point and still covers it after the move, so the move
  // only hides more of the tower (no disocclusion, which no impostor made from one image could show).
  const uint32_t box = s.addBox({-12.0f, 30.0f, 0.0f}, {4.0f, 31.0f, 40.0f}, {0.8f, 0.3f, 0.2f});
  const uint32_t tower = s.addBox({10.0f, 150.0f, 0.0f}, {100.0f, 170.0f, 100.0f}, {0.3f, 0.5f, 0.9f});
  const gpu::GpuScene gpu_scene(s.scene);
  const int size = 256;
  Camera creation = test::makeCamera({0.0f, 0.0f, 2.0f}, {0.0f, 100.0f, 2.0f}, size, 0.5f, 1000.0f);
  creation.fov_y = float(degToRad(90.0));  // room on the right for the tower to slide into view with a flat quad
  Camera moved = creation;
  moved.eye.x -= 10.0f;
  moved.at.x -= 10.0f;

  const std::vector<uint32_t> ids = {box, tower};
  const ImpostorCapture capture = captureView(*renderer_, gpu_scene, ids, creation);
  std::vector<gpu::DrawItem> items;
  gpu_scene.appendDrawItems(ids, items);
  const test::Frame geometry = test::renderItems(*renderer_, moved, items);
  const size_t tower_before = countId(capture.ids, tower);
  const size_t tower_after = countId(geometry.ids, tower);
  // The scene does what the test needs: the tower loses most of its pixels to the box.
  ASSERT_GT(tower_before, size_t(size * size) / 16);
  ASSERT_LT(tower_after, tower_before * 3 / 4);
  ASSERT_GT(tower_after, 0u);

  auto renderImpostor = [&](const DepthMeshImpostor& impostor) {
    GpuImpostorOptions options;
    options.split_by_object_id = true;
    const GpuImpostor gpu_impostor(impostor, options);
    std::vector<gpu::DrawItem> impostor_items;
    gpu_impostor.appendDrawItems(impostor_items);
    return test::renderItems(*renderer_, moved, impostor_items);
  };

  const DepthMeshImpostor depth_mesh = buildDepthMesh(capture);
  ASSERT_FALSE(depth_mesh.empty());
  ASSERT_EQ(depth_mesh.triangle_ids.size(), depth_mesh.mesh.triangleCount());
  const Agreement mesh_agreement = compareIds(geometry.ids, renderImpostor(depth_mesh).ids, tower);

  // Flat textured quads: the same capture on a plane facing the creation camera, at the box's or at the tower's
  // distance (finely tessellated only so that each piece carries the object id of its pixels).
  auto flatQuad = [&](float distance) {
    const float window_depth = creation.project(creation.eye + creation.forward() * distance).z;
    image::DepthImage flat(size, size, 0.0f);
    for (size_t i = 0; i < flat.pixelCount(); ++i)
      if (capture.depth.pixels()[i] > 0.0f) flat.pixels()[i] = window_depth;
    GridMeshOptions options;
    options.grid_spacing_px = 2.0;
    return buildGridMesh(capture.color, flat, creation, options, &capture.ids);
  };
  const Agreement near_quad = compareIds(geometry.ids, renderImpostor(flatQuad(30.0f)).ids, tower);
  const Agreement far_quad = compareIds(geometry.ids, renderImpostor(flatQuad(150.0f)).ids, tower);
  const Agreement grid = compareIds(geometry.ids, renderImpostor(buildGridMesh(capture)).ids, tower);

  std::printf("tower pixels: creation %zu, moved geometry %zu, depth mesh %zu, near quad %zu, far quad %zu, grid %zu\n",
              tower_before, tower_after, mesh_agreement.tower_pixels, near_quad.tower_pixels, far_quad.tower_pixels,
              grid.tower_pixels);
  std::printf("id agreement: depth mesh %.4f, near quad %.4f, far quad %.4f, grid mesh %.4f\n", mesh_agreement.share,
              near_quad.share, far_quad.share, grid.share);
  EXPECT_GE(mesh_agreement.share, 0.97);
  EXPECT_NEAR(double(mesh_agreement.tower_pixels), double(tower_after), 0.1 * double(tower_after));
  // A flat quad keeps the picture rigid: at the box's distance the tower slides along with the box and stays in
  // view; at the tower's distance the box stays where it was and the tower does not go behind it.
  EXPECT_LT(near_quad.share, 0.92);
  EXPECT_GT(near_quad.tower_pixels, tower_after * 3 / 2);
  EXPECT_LT(far_quad.share, 0.92);
  EXPECT_GT(far_quad.tower_pixels, tower_after * 3 / 2);
}

}  // namespace
}  // namespace farfield::impostor
