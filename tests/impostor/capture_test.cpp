#include "farfield/impostor/capture.h"

#include <gtest/gtest.h>

#include <cmath>

#include "farfield/core/error.h"
#include "farfield/impostor/contour.h"
#include "farfield/impostor/depth_mesh.h"
#include "impostor/impostor_fixture.h"

namespace farfield::impostor {
namespace {

using test::BoxScene;
using test::ImpostorGpuTest;

// Where the ray through the centre of pixel (x, y) meets the plane z = height, if in front of the camera.
std::optional<Vec3> rayHitsPlane(const Camera& camera, int x, int y, float height) {
  const Vec3 a = camera.unproject(x + 0.5f, y + 0.5f, 1.0f);  // near plane
  const Vec3 b = camera.unproject(x + 0.5f, y + 0.5f, 0.5f);
  const Vec3 dir = b - a;
  if (std::abs(dir.z) < 1e-9f) return std::nullopt;
  const float t = (height - a.z) / dir.z;
  if (t <= 0.0f) return std::nullopt;
  return a + t * dir;
}

TEST_F(ImpostorGpuTest, GroundSeenFromBelowIsMarkedAndLeftOutOfTheContour) {
  // A ground element on a terrace 10 m above the viewer (single-sided, facing up) and a box standing below it.
  BoxScene s;
  scene::Material m;
  m.base_color = Vec4(0.4f, 0.7f, 0.3f, 1.0f);
  scene::Object terrace;
  terrace.parts.push_back({s.scene.addMesh(scene::makeGroundQuad({-30.0f, 40.0f}, {30.0f, 120.0f}, 10.0f)),
                           s.scene.addMaterial(m)});
  terrace.transform = glm::translate(Mat4(1.0f), Vec3(0.0f, 0.0f, 10.0f));
  const uint32_t terrace_id = s.scene.addObject(terrace);
  const uint32_t box_id = s.addBox({-3.0f, 20.0f, 0.0f}, {3.0f, 26.0f, 6.0f}, {0.8f, 0.3f, 0.2f});
  const gpu::GpuScene gpu_scene(s.scene);
  const Camera camera = test::makeCamera({0.0f, 0.0f, 2.0f}, {0.0f, 100.0f, 12.0f}, 128, 0.5f, 1000.0f);
  const std::vector<uint32_t> ids = {terrace_id, box_id};
  const ImpostorCapture capture = captureView(*renderer_, gpu_scene, ids, camera);
  ASSERT_GT(capture.seen_from_below_pixels, 100u);

  // Independently: a pixel is seen from below where its ray meets the terrace's rectangle and the box does not
  // hide it. Pixels within a pixel of the rectangle's outline are skipped (partial coverage).
  size_t checked = 0;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const auto hit = rayHitsPlane(camera, x, y, 10.0f);
      const bool inside = hit && hit->x > -29.0f && hit->x < 29.0f && hit->y > 41.0f && hit->y < 119.0f;
      const bool outside = !hit || hit->x < -31.0f || hit->x > 31.0f || hit->y < 39.0f || hit->y > 121.0f;
      if (!inside && !outside) continue;
      const uint32_t id = capture.ids.at(x, y);
      if (id == box_id) {
        EXPECT_NE(capture.color.at(x, y), kSeenFromBelowColor);
        continue;
      }
      if (inside) {
        EXPECT_EQ(capture.color.at(x, y), kSeenFromBelowColor) << x << ", " << y;
      } else {
        EXPECT_NE(capture.color.at(x, y), kSeenFromBelowColor) << x << ", " << y;
      }
      ++checked;
    }
  EXPECT_GT(checked, 1000u);

  // The contour keeps the box and leaves the terrace's underside out.
  const image::Image<uint8_t> mask = dataMask(capture.color, capture.depth);
  size_t data = 0;
  for (size_t i = 0; i < mask.pixelCount(); ++i) {
    data += mask.pixels()[i];
    if (mask.pixels()[i]) {
      EXPECT_EQ(capture.ids.pixels()[i], box_id);
    }
  }
  EXPECT_EQ(data, capture.data_pixels);
  EXPECT_GT(data, 100u);
  const DepthMeshImpostor impostor = buildDepthMesh(capture);
  for (uint32_t id : impostor.triangle_ids) EXPECT_EQ(id, box_id);

  // Without the detection the underside's pixels are just what lies behind them (the sky here): the terrace is
  // not drawn at all from below by the culled render.
  CaptureOptions off;
  off.detect_seen_from_below = false;
  const ImpostorCapture plain = captureView(*renderer_, gpu_scene, ids, camera, off);
  EXPECT_EQ(plain.seen_from_below_pixels, 0u);
  EXPECT_EQ(plain.data_pixels, capture.data_pixels);
}

TEST_F(ImpostorGpuTest, CaptureMatchesAPlainRenderAndChecksItsInput) {
  BoxScene s;
  const uint32_t a = s.addBox({-5.0f, 20.0f, 0.0f}, {5.0f, 30.0f, 8.0f}, {0.2f, 0.6f, 0.3f});
  const uint32_t b = s.addBox({8.0f, 40.0f, 0.0f}, {14.0f, 46.0f, 20.0f}, {0.7f, 0.2f, 0.6f});
  const gpu::GpuScene gpu_scene(s.scene);
  const Camera camera = test::makeCamera({0.0f, 0.0f, 2.0f}, {0.0f, 100.0f, 5.0f}, 96);
  const std::vector<uint32_t> only_b = {b};
  const ImpostorCapture capture = captureView(*renderer_, gpu_scene, only_b, camera);
  std::vector<gpu::DrawItem> items;
  gpu_scene.appendDrawItems(only_b, items);
  const test::Frame frame = test::renderItems(*renderer_, camera, items);
  EXPECT_EQ(capture.color.pixels(), frame.color.pixels());
  EXPECT_EQ(capture.depth.pixels(), frame.depth.pixels());
  EXPECT_EQ(capture.ids.pixels(), frame.ids.pixels());
  size_t drawn = 0;
  for (uint32_t id : capture.ids.pixels()) {
    EXPECT_NE(id, a);
    drawn += id == b ? 1 : 0;
  }
  EXPECT_EQ(capture.data_pixels, drawn);
  EXPECT_EQ(capture.camera.eye, camera.eye);
  const std::vector<uint32_t> bad = {99};
  EXPECT_THROW(captureView(*renderer_, gpu_scene, bad, camera), Error);
  Camera broken = camera;
  broken.width = 0;
  EXPECT_THROW(captureView(*renderer_, gpu_scene, only_b, broken), Error);
}

}  // namespace
}  // namespace farfield::impostor
