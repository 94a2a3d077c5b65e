// impostor/billboard.h: quads face the eye (spherical) or its horizontal direction (cylindrical) within a tolerance;
// errorAngle bounds the displacement of sampled points reprojected through the capture camera onto the drawn quad;
// seen from its capture direction a billboard draws what the geometry draws, and a single view turned a quarter
// round does not.
#include "farfield/impostor/billboard.h"

#include <random>

#include "farfield/core/error.h"
#include "farfield/image/metrics.h"
#include "impostor/impostor_fixture.h"

namespace farfield::impostor {
namespace {

Vec3 randomUnit(std::mt19937& rng) {
  std::normal_distribution<float> g;
  return glm::normalize(Vec3(g(rng), g(rng), g(rng)));
}

TEST(BillboardTest, QuadsFaceTheCamera) {
  std::mt19937 rng(1);
  const Box3 box = Box3::fromPoints(Vec3(-2, -2, 0), Vec3(2, 2, 9));
  for (const BillboardKind kind : {BillboardKind::Spherical, BillboardKind::Cylindrical}) {
    BillboardOptions o;
    o.kind = kind;
    const BillboardShape s = billboardShape(box, o);
    for (int i = 0; i < 500; ++i) {
      const Vec3 eye = s.centre + (10.0f + 200.0f * float(i) / 500.0f) * randomUnit(rng);
      const std::array<Vec3, 4> c = s.corners(eye);
      const Vec3 n = glm::normalize(glm::cross(c[1] - c[0], c[3] - c[0]));
      EXPECT_NEAR(glm::dot(n, s.orient(eye).normal), 1.0f, 1e-5f);
      EXPECT_NEAR(glm::length(0.25f * (c[0] + c[1] + c[2] + c[3]) - s.centre), 0.0f, 1e-4f);
      Vec3 to_eye = eye - s.centre;
      if (kind == BillboardKind::Cylindrical) {
        to_eye.z = 0.0f;
        EXPECT_NEAR(n.z, 0.0f, 1e-5f);
        EXPECT_NEAR(glm::length(c[3] - c[0]), 2 * s.half_size, 1e-4f);
        EXPECT_NEAR(glm::normalize(c[3] - c[0]).z, 1.0f, 1e-5f);  // upright
      }
      EXPECT_GT(glm::dot(n, glm::normalize(to_eye)), std::cos(1e-3f)) << billboardKindName(kind);
    }
  }
}

// Where the billboard shows point p for an eye: p's pixel in the capture of the view drawn, placed on the drawn quad.
Vec3 shownAt(const BillboardShape& s, const Vec3& p, const Vec3& eye) {
  const Camera cap = s.captureCamera(s.nearestView(eye), 1024);
  const Vec3 px = cap.project(p);
  const float u = px.x / 1024.0f, v = px.y / 1024.0f;
  const BillboardFrame f = s.orient(eye);
  return s.centre + (2 * u - 1) * s.half_size * f.right + (1 - 2 * v) * s.half_size * f.up;
}

TEST(BillboardTest, ErrorAngleBoundsReprojectedPoints) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const Box3 box = Box3::fromPoints(Vec3(-3, -2, 0), Vec3(3, 2, 8));
  for (const BillboardKind kind : {BillboardKind::Spherical, BillboardKind::Cylindrical}) {
    BillboardOptions o;
    o.kind = kind;
    o.views = 6;
    o.elevation = 0.2;
    const BillboardShape s = billboardShape(box, o);
    double worst_ratio = 0.0;
    for (int i = 0; i < 300; ++i) {
      const Vec3 eye = s.centre + s.radius * (1.5f + 40.0f * u(rng)) * randomUnit(rng);
      const double bound = s.errorAngle(eye);
      double brute = 0.0;
      for (int j = 0; j < 200; ++j) {
        const Vec3 p = s.centre + s.radius * std::cbrt(u(rng)) * randomUnit(rng);
        const DVec3 a = glm::normalize(DVec3(p) - DVec3(eye));
        const DVec3 b = glm::normalize(DVec3(shownAt(s, p, eye)) - DVec3(eye));
        brute = std::max(brute, std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)));
      }
      EXPECT_LE(brute, bound * 1.001 + 2e-5) << billboardKindName(kind) << " eye " << i;
      worst_ratio = std::max(worst_ratio, brute / std::max(bound, 1e-12));
    }
    EXPECT_GT(worst_ratio, 0.3);  // not vacuous
    // From a capture eye the image is exact.
    EXPECT_NEAR(s.errorAngle(s.captureCamera(0, 64).eye), 0.0, 1e-5);
  }
}

TEST(BillboardTest, BadOptionsAreErrors) {
  BillboardOptions o;
  o.views = 0;
  EXPECT_THROW(billboardShape(Box3::fromPoints(Vec3(0), Vec3(1)), o), Error);
  EXPECT_THROW(billboardShape(Box3{}, BillboardOptions{}), Error);
}

using BillboardGpuTest = test::ImpostorGpuTest;

TEST_F(BillboardGpuTest, FromItsCaptureDirectionItMatchesTheGeometry) {
  test::BoxScene s;
  const uint32_t a = s.addBox(Vec3(-2, -1, 0), Vec3(0, 1, 5), Vec3(0.8f, 0.2f, 0.2f));
  const uint32_t b = s.addBox(Vec3(0.5f, -1.5f, 1), Vec3(2, 0.5f, 3), Vec3(0.2f, 0.7f, 0.3f));
  const uint32_t c = s.addBox(Vec3(-1, 0.5f, 4), Vec3(1.5f, 2, 7), Vec3(0.2f, 0.3f, 0.9f));
  const gpu::GpuScene scene(s.scene);
  Box3 box;
  for (const Box3& bb : s.boxes) box.expand(bb);
  const std::vector<uint32_t> ids{a, b, c};
  BillboardOptions o;
  o.kind = BillboardKind::Spherical;
  o.views = 4;
  o.elevation = 0.3;
  o.texels = 256;
  const std::vector<Billboard> boards{captureBillboard(*renderer_, scene, ids, box, o)};
  impostor::BillboardBatch batch(boards);
  EXPECT_EQ(batch.textureBytes(), size_t(4096) * 256 * 4);

  Camera cam = boards[0].shape.captureCamera(1, 256);
  gpu::RenderTarget target(256, 256);
  std::vector<gpu::DrawItem> geometry;
  scene.appendDrawItems(ids, geometry);
  renderer_->render(cam, geometry, target);
  const image::ColorImage reference = target.readColor();
  std::vector<gpu::DrawItem> quads;
  const uint32_t which[] = {0};
  EXPECT_GT(batch.build(which, cam.eye, quads), 0u);
  renderer_->render(cam, quads, target);
  const image::ColorImage drawn = target.readColor();
  const double same_view = image::shareOverThreshold(reference, drawn, 24);
  // The lit geometry against the unlit capture of the same lit geometry: equal but for filtering at edges.
  EXPECT_LT(same_view, 0.02);

  // A quarter turn away with only the view captured a quarter turn back: the image is the wrong side.
  Camera side = cam;
  const Vec3 off = cam.eye - boards[0].shape.centre;
  side.eye = boards[0].shape.centre + Vec3(-off.y, off.x, off.z);
  std::vector<gpu::DrawItem> side_geometry;
  scene.appendDrawItems(ids, side_geometry);
  renderer_->render(side, side_geometry, target);
  const image::ColorImage side_reference = target.readColor();
  BillboardOptions one = o;
  one.views = 1;
  const std::vector<Billboard> single{captureBillboard(*renderer_, scene, ids, box, one)};
  impostor::BillboardBatch single_batch(single);
  quads.clear();
  single_batch.build(which, side.eye, quads);
  renderer_->render(side, quads, target);
  const double wrong_view = image::shareOverThreshold(side_reference, target.readColor(), 24);
  std::printf("billboard: %.4f of pixels differ from its capture direction, %.4f a quarter turn away\n", same_view,
              wrong_view);
  EXPECT_GT(wrong_view, 5 * same_view + 0.02);
  EXPECT_GT(single[0].shape.errorAngle(side.eye), 0.1);
}

}  // namespace
}  // namespace farfield::impostor
