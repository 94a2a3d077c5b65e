// The fill estimate of the frame cost model (core/object_fill.h): against the projected corners of the box seen
// straight on (the screen area of its convex hull, brute force), and from a region against every sampled eye in it.
#include "farfield/core/object_fill.h"

#include <gtest/gtest.h>

#include <random>

#include "farfield/core/camera.h"
#include "farfield/core/polygon2d.h"

namespace farfield {
namespace {

Box3 randomBox(std::mt19937& rng) {
  std::uniform_real_distribution<float> pos(-50.0f, 50.0f), size(0.2f, 30.0f);
  const Vec3 lo(pos(rng), pos(rng), pos(rng) * 0.1f);
  return Box3::fromPoints(lo, lo + Vec3(size(rng), size(rng), size(rng)));
}

TEST(ObjectFill, CoversTheProjectedBoxSeenStraightOn) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), far(1.0f, 400.0f);
  size_t capped = 0, measured = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Box3 box = randomBox(rng);
    const Vec3 dir = glm::normalize(Vec3(u(rng), u(rng), 0.3f * u(rng)) + Vec3(0.0f, 0.0f, 1e-3f));
    Camera camera;
    camera.width = 320;
    camera.height = 200;
    camera.fov_y = float(degToRad(45.0));
    camera.near_plane = 0.01f;
    camera.eye = box.center() - dir * far(rng);
    camera.at = box.center();
    const FillLens lens = FillLens::of(camera.width, camera.height, double(camera.fov_y));
    const double estimate = lens.objectPixels(box, camera.eye);
    ASSERT_LE(estimate, lens.frame_pixels);
    std::vector<Vec2> corners;
    const Mat4 vp = camera.viewProjection();
    bool behind = false;
    for (int i = 0; i < 8; ++i) {
      const Vec4 c = vp * Vec4((i & 1) ? box.hi.x : box.lo.x, (i & 2) ? box.hi.y : box.lo.y,
                               (i & 4) ? box.hi.z : box.lo.z, 1.0f);
      if (c.w <= 1e-4f) behind = true;
      corners.emplace_back((c.x / c.w * 0.5f + 0.5f) * float(camera.width), (c.y / c.w * 0.5f + 0.5f) * float(camera.height));
    }
    if (behind) {  // the eye is within the box's depth: only the whole frame bounds it
      EXPECT_EQ(estimate, lens.frame_pixels) << "trial " << trial;
      ++capped;
      continue;
    }
    const double hull = std::abs(signedArea(convexHull(corners)));
    EXPECT_GE(estimate, std::min(hull, lens.frame_pixels) * (1.0 - 1e-4)) << "trial " << trial;
    capped += estimate == lens.frame_pixels;
    ++measured;
  }
  EXPECT_GT(measured, 1000u);
  EXPECT_GT(capped, 20u);
}

TEST(ObjectFill, FromARegionAtLeastFromEveryEyeInIt) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const FillLens lens = FillLens::of(512, 512, degToRad(45.0));
  for (int trial = 0; trial < 300; ++trial) {
    const Box3 object = randomBox(rng);
    Box3 region = randomBox(rng);
    region.hi.z = region.lo.z + 0.5f;
    const double bound = lens.objectPixels(object, region);
    for (int k = 0; k < 50; ++k) {
      const Vec3 eye = region.lo + region.extent() * Vec3(u(rng), u(rng), u(rng));
      EXPECT_GE(bound, lens.objectPixels(object, eye)) << "trial " << trial;
    }
  }
  EXPECT_EQ(lens.objectPixels(Box3{}, Vec3(0.0f)), 0.0);
  const Box3 unit = Box3::fromPoints(Vec3(0.0f), Vec3(1.0f));
  EXPECT_EQ(lens.objectPixels(unit, Vec3(0.5f)), lens.frame_pixels);  // from inside
  EXPECT_LT(lens.objectPixels(unit, Vec3(0.5f, 0.5f, 1000.0f)), 1.0);
}

}  // namespace
}  // namespace farfield
