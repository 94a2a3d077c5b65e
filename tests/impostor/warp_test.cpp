// impostor/warp.h: warping a depth image to its own camera is the identity; warped to a moved camera it leaves
// holes behind the occluder that a second image from the other side fills, and the result is closer to the
// geometry rendered from the moved camera.
#include "farfield/impostor/warp.h"

#include "farfield/core/error.h"
#include "farfield/image/metrics.h"
#include "impostor/impostor_fixture.h"

namespace farfield::impostor {
namespace {

using WarpGpuTest = test::ImpostorGpuTest;

struct Shot {
  image::ColorImage color;
  image::DepthImage depth;
  Camera camera;
  DepthView view() const { return {&color, &depth, camera}; }
};

Shot shoot(gpu::Renderer& r, const gpu::GpuScene& scene, const Camera& cam) {
  gpu::RenderTarget target(cam.width, cam.height);
  r.render(cam, scene.drawItems(), target);
  return {target.readColor(), target.readDepth(), cam};
}

// Pixels where the reference shows geometry and the warp has nothing, and the colour error where both have data.
struct Score {
  size_t holes = 0;
  double mean_abs = 0.0;
};
Score score(const WarpedImage& w, const Shot& ref) {
  Score s;
  size_t n = 0;
  for (int y = 0; y < ref.camera.height; ++y)
    for (int x = 0; x < ref.camera.width; ++x) {
      if (!(ref.depth.at(x, y) > 0.0f)) continue;
      if (w.source.at(x, y) == 0) {
        ++s.holes;
        continue;
      }
      for (int c = 0; c < 3; ++c) s.mean_abs += std::abs(int(w.color.at(x, y)[c]) - int(ref.color.at(x, y)[c]));
      ++n;
    }
  s.mean_abs /= double(std::max<size_t>(n, 1) * 3);
  return s;
}

TEST_F(WarpGpuTest, ToTheCaptureCameraIsTheIdentity) {
  test::BoxScene s;
  s.addGround(Vec2(-30, -30), Vec2(30, 30));
  s.addBox(Vec3(-2, -2, 0), Vec3(2, 2, 6), Vec3(0.8f, 0.2f, 0.2f));
  const gpu::GpuScene scene(s.scene);
  Camera cam;
  cam.eye = Vec3(5, -20, 8);
  cam.at = Vec3(0, 0, 2);
  cam.width = 160;
  cam.height = 120;
  const Shot a = shoot(*renderer_, scene, cam);
  const WarpedImage w = warpDepthImage(a.view(), cam);
  size_t data = 0, mismatched = 0;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const bool has = a.depth.at(x, y) > 0.0f;
      data += has;
      if (has != (w.source.at(x, y) == 1)) ++mismatched;
      else if (has && (w.depth.at(x, y) != a.depth.at(x, y) || glm::u8vec3(w.color.at(x, y)) !=
                                                                   glm::u8vec3(a.color.at(x, y))))
        ++mismatched;
    }
  EXPECT_GT(data, 5000u);
  EXPECT_EQ(mismatched, 0u);
  EXPECT_EQ(w.from_primary, data);
  Camera wrong = cam;
  wrong.width = 80;
  EXPECT_THROW(warpDepthImage(DepthView{&a.color, &a.depth, wrong}, cam), Error);
}

TEST_F(WarpGpuTest, ASecondImageFillsTheHolesOfAMovedViewpoint) {
  test::BoxScene s;
  s.addGround(Vec2(-40, -10), Vec2(40, 40));
  s.addBox(Vec3(-20, 20, 0), Vec3(20, 22, 12), Vec3(0.3f, 0.4f, 0.8f));  // a wall behind
  s.addBox(Vec3(-2, 0, 0), Vec3(2, 3, 7), Vec3(0.8f, 0.3f, 0.2f));      // an occluder in front
  const gpu::GpuScene scene(s.scene);
  Camera base;
  base.at = Vec3(0, 20, 4);
  base.width = 200;
  base.height = 120;
  Camera left = base, right = base, middle = base;
  left.eye = Vec3(-6, -18, 4);
  right.eye = Vec3(6, -18, 4);
  middle.eye = Vec3(3, -18, 4);
  const Shot l = shoot(*renderer_, scene, left), r = shoot(*renderer_, scene, right), m = shoot(*renderer_, scene, middle);
  const WarpedImage alone = warpDepthImage(l.view(), middle);
  const WarpedImage filled = warpWithHoleFilling(l.view(), r.view(), middle);
  const Score a = score(alone, m), f = score(filled, m);
  std::printf("warp: %zu holes from one image, %zu with the second (%zu pixels from it); colour error %.2f / %.2f\n",
              a.holes, f.holes, filled.from_second, a.mean_abs, f.mean_abs);
  EXPECT_GT(a.holes, 300u);          // disocclusion behind the occluder and magnification cracks
  EXPECT_LT(f.holes, a.holes / 3);
  EXPECT_GT(filled.from_second, a.holes / 2);
  EXPECT_LT(f.mean_abs, 12.0);
}

}  // namespace
}  // namespace farfield::impostor
