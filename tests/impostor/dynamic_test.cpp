// impostor/dynamic.h: a planar impostor seen from its capture eye draws what the geometry draws (projective
// texturing on its best plane), both metrics are 0 there and grow as the eye moves, and from a moved eye the image
// is off by about what Shade's metric says.
#include "farfield/impostor/dynamic.h"

#include "farfield/core/error.h"
#include "farfield/image/metrics.h"
#include "impostor/impostor_fixture.h"

namespace farfield::impostor {
namespace {

using PlanarImpostorGpuTest = test::ImpostorGpuTest;

std::vector<DVec3> corners(const std::vector<Box3>& boxes) {
  std::vector<DVec3> out;
  for (const Box3& b : boxes)
    for (int i = 0; i < 8; ++i)
      out.push_back(DVec3(i & 1 ? b.hi.x : b.lo.x, i & 2 ? b.hi.y : b.lo.y, i & 4 ? b.hi.z : b.lo.z));
  return out;
}

TEST_F(PlanarImpostorGpuTest, FromItsCaptureEyeItMatchesTheGeometry) {
  test::BoxScene s;
  // A slanted facade-like row of boxes: its best plane is not the one facing the eye.
  const std::vector<uint32_t> ids{s.addBox(Vec3(0, 0, 0), Vec3(3, 2, 6), Vec3(0.8f, 0.3f, 0.2f)),
                                  s.addBox(Vec3(4, 3, 0), Vec3(7, 5, 4), Vec3(0.2f, 0.7f, 0.3f)),
                                  s.addBox(Vec3(8, 6, 0), Vec3(11, 8, 8), Vec3(0.2f, 0.3f, 0.8f))};
  const gpu::GpuScene scene(s.scene);
  Box3 box;
  for (const Box3& b : s.boxes) box.expand(b);
  std::vector<gpu::DrawItem> items;
  scene.appendDrawItems(ids, items);
  const std::vector<DVec3> samples = corners(s.boxes);

  Camera cam;
  cam.eye = Vec3(-25, 30, 6);
  cam.at = box.center();
  cam.width = cam.height = 256;
  cam.fov_y = float(degToRad(50.0));
  const double pixel = cam.fov_y / cam.height;
  const PlanarImpostor impostor(*renderer_, items, box, samples, cam.eye, pixel);
  EXPECT_GT(std::abs(glm::dot(impostor.plane().normal, glm::normalize(DVec3(cam.eye) - DVec3(box.center())))),
            0.5);
  EXPECT_EQ(impostor.error(ValidityMetric::Shade, cam.eye), 0.0);
  EXPECT_EQ(impostor.error(ValidityMetric::Schaufler, cam.eye), 0.0);

  gpu::RenderTarget target(256, 256);
  renderer_->render(cam, items, target);
  const image::ColorImage reference = target.readColor();
  std::vector<gpu::DrawItem> quad;
  impostor.appendDrawItems(quad);
  renderer_->render(cam, quad, target);
  const double same = image::shareOverThreshold(reference, target.readColor(), 24);
  EXPECT_LT(same, 0.01);

  // Moved: both metrics grow (Schaufler's sphere more than Shade's points on the fitted plane); the image is off.
  Camera moved = cam;
  moved.eye += Vec3(6, 6, 0);
  EXPECT_GT(impostor.error(ValidityMetric::Shade, moved.eye), 1.5 * pixel);
  EXPECT_GT(impostor.error(ValidityMetric::Schaufler, moved.eye), 3 * impostor.error(ValidityMetric::Shade, moved.eye));
  renderer_->render(moved, items, target);
  const image::ColorImage moved_reference = target.readColor();
  renderer_->render(moved, quad, target);
  const double off = image::shareOverThreshold(moved_reference, target.readColor(), 24);
  std::printf("planar impostor: %.4f of pixels differ at its capture eye, %.4f after moving 8.5 m (Shade %.1f px, "
              "Schaufler %.1f px)\n", same, off, impostor.error(ValidityMetric::Shade, moved.eye) / pixel,
              impostor.error(ValidityMetric::Schaufler, moved.eye) / pixel);
  EXPECT_GT(off, 2 * same);
  EXPECT_THROW(PlanarImpostor(*renderer_, items, box, samples, box.center(), pixel), Error);
  EXPECT_THROW(parseValidityMetric("psnr", "--metric"), Error);
}

}  // namespace
}  // namespace farfield::impostor
