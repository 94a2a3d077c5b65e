// Dynamic regular-grid impostors (Decoret et al. 1999, section 5.5): eight-bit inverse-depth quantisation against
// its half-step bound, Schaufler's error angle against brute force, covers() against dense ray sampling, and the
// impostor drawn alone against a reference render of the geometry it replaces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/render_target.h"
#include "farfield/image/metrics.h"
#include "farfield/runtime/dynamic_impostor.h"
#include "farfield/scene/builtin.h"

namespace farfield::runtime {
namespace {

constexpr uint32_t kImpostorId = 1000;

// Inverse linear depth of a reversed-Z window depth, from the projection (depth = n/(f-n) * (f/d - 1)), in double.
double inverseDepth(double z, const Camera& c) {
  const double n = c.near_plane, f = c.far_plane;
  return (z * (f - n) + n) / (n * f);
}
double windowDepthOf(double d, const Camera& c) {
  const double n = c.near_plane, f = c.far_plane;
  return n / (f - n) * (f / d - 1.0);
}

Camera viewerCamera(int size = 192) {
  Camera c;
  c.eye = Vec3(0.0f, -30.0f, 4.0f);
  c.at = Vec3(0.0f, 0.0f, 4.0f);
  c.width = c.height = size;
  c.near_plane = 0.5f;
  c.far_plane = 2000.0f;
  return c;
}

// Boxes at different depths and heights in front of the viewer, flat colours.
struct Boxes {
  scene::Scene scene;
  Box3 bounds;
  Boxes() {
    struct Spec {
      Vec3 lo, hi, color;
    };
    const Spec specs[] = {
        {{-14, 0, 0}, {-6, 8, 12}, {0.8f, 0.3f, 0.2f}},  {{-3, 4, 0}, {3, 10, 7}, {0.2f, 0.7f, 0.3f}},
        {{5, -6, 0}, {9, -2, 5}, {0.2f, 0.3f, 0.8f}},    {{-6, 30, 0}, {12, 40, 22}, {0.9f, 0.8f, 0.3f}},
        {{10, 12, 0}, {16, 18, 14}, {0.6f, 0.3f, 0.7f}}, {{-25, 60, 0}, {-5, 70, 30}, {0.4f, 0.7f, 0.8f}},
    };
    for (const Spec& s : specs) {
      scene::Material m;
      m.base_color = Vec4(s.color, 1.0f);
      scene::Object o;
      o.parts.push_back({scene.addMesh(scene::makeBox(s.lo, s.hi)), scene.addMaterial(m)});
      scene.addObject(o);
      bounds.expand(Box3::fromPoints(s.lo, s.hi));
    }
  }
};

struct Frame {
  image::ColorImage color;
  image::IdImage ids;
};
Frame render(gpu::Renderer& renderer, const Camera& camera, const std::vector<gpu::DrawItem>& items) {
  gpu::RenderTarget target(camera.width, camera.height);
  renderer.render(camera, items, target);
  return {target.readColor(), target.readIds()};
}

// Share of the reference's geometry pixels where the other image shows sky (cracks, missing coverage).
double missingCoverage(const Frame& reference, const Frame& other) {
  size_t geometry = 0, missing = 0;
  for (size_t i = 0; i < reference.ids.pixelCount(); ++i)
    if (reference.ids.pixels()[i] != 0) {
      ++geometry;
      missing += other.ids.pixels()[i] == 0 ? 1 : 0;
    }
  return geometry ? double(missing) / double(geometry) : 0.0;
}
// Share of all pixels where the other image shows geometry and the reference sky.
double extraCoverage(const Frame& reference, const Frame& other) {
  size_t extra = 0;
  for (size_t i = 0; i < reference.ids.pixelCount(); ++i)
    extra += reference.ids.pixels()[i] == 0 && other.ids.pixels()[i] != 0 ? 1 : 0;
  return double(extra) / double(reference.ids.pixelCount());
}

Camera yawed(Camera c, double degrees) {
  const Mat4 r = glm::rotate(Mat4(1.0f), float(degToRad(degrees)), Vec3(0, 0, 1));
  c.at = c.eye + Vec3(r * Vec4(c.at - c.eye, 0.0f));
  return c;
}

class DynamicImpostorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    gpu::sharedHeadlessContext();
    renderer_ = std::make_unique<gpu::Renderer>();
    gpu_scene_ = std::make_unique<gpu::GpuScene>(boxes_.scene);
    items_ = gpu_scene_->drawItems();
  }
  Boxes boxes_;
  std::unique_ptr<gpu::Renderer> renderer_;
  std::unique_ptr<gpu::GpuScene> gpu_scene_;
  std::vector<gpu::DrawItem> items_;
};

TEST(QuantizeDepthTest, RoundTripIsWithinHalfAStepInInverseDepthAndKeepsBackground) {
  Camera camera = viewerCamera(64);
  image::DepthImage depth(64, 64, 0.0f);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> dist(12.0, 480.0);
  std::vector<double> truth(depth.pixelCount(), 0.0);
  double d_lo = 1e30, d_hi = 0.0;
  for (size_t i = 0; i < depth.pixelCount(); ++i) {
    if (i % 5 == 0) continue;  // background
    truth[i] = dist(rng);
    depth.pixels()[i] = float(windowDepthOf(truth[i], camera));
  }
  // The bounds are those of the stored (float) depths.
  for (size_t i = 0; i < depth.pixelCount(); ++i)
    if (depth.pixels()[i] > 0.0f) {
      const double d = 1.0 / inverseDepth(depth.pixels()[i], camera);
      d_lo = std::min(d_lo, d);
      d_hi = std::max(d_hi, d);
    }
  for (int bits : {8, 4, 12}) {
    const QuantizedDepth q = quantizeDepth(depth, camera, bits);
    ASSERT_EQ(q.window_depth.width(), 64);
    EXPECT_EQ(q.data_pixels, depth.pixelCount() - (depth.pixelCount() + 4) / 5);
    EXPECT_NEAR(q.near_m, d_lo, 1e-3 * d_lo);
    EXPECT_NEAR(q.far_m, d_hi, 1e-3 * d_hi);
    const double step = (1.0 / d_lo - 1.0 / d_hi) / double((1 << bits) - 1);
    double worst = 0.0;
    for (size_t i = 0; i < depth.pixelCount(); ++i) {
      const float z = depth.pixels()[i], zq = q.window_depth.pixels()[i];
      if (z == 0.0f) {
        EXPECT_EQ(zq, 0.0f) << "background pixel " << i << " became data";
        EXPECT_EQ(q.codes[i], 0);
        continue;
      }
      ASSERT_GT(zq, 0.0f) << "data pixel " << i << " became background";
      EXPECT_LT(q.codes[i], 1 << bits);
      worst = std::max(worst, std::abs(inverseDepth(zq, camera) - inverseDepth(z, camera)));
    }
    // Half a step (plus float rounding of the window depth), and the quantisation did happen.
    EXPECT_LE(worst, 0.5 * step * (1.0 + 1e-3)) << bits << " bits";
    EXPECT_GE(worst, 0.3 * step) << bits << " bits";
  }
  EXPECT_THROW(quantizeDepth(depth, camera, 0), Error);
  EXPECT_THROW(quantizeDepth(depth, camera, 17), Error);
  const QuantizedDepth none = quantizeDepth(image::DepthImage(8, 8, 0.0f), camera, 8);
  EXPECT_EQ(none.data_pixels, 0u);
}

// Brute force: the largest angle, seen from `eye`, between the entry and exit points of capture rays through the
// box (the farthest-apart pair of points of the box on one ray; the angle only grows with the segment).
double bruteForceErrorAngle(const Vec3& capture_eye, const Vec3& eye, const Box3& box, int rays = 20000) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const DVec3 c(capture_eye), e(eye), lo(box.lo), hi(box.hi);
  double worst = 0.0;
  for (int k = 0; k < rays; ++k) {
    // Aim at a point inside the box (and at its corners, where the extremes tend to be).
    DVec3 target;
    if (k < 8)
      target = DVec3((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
    else
      target = lo + DVec3(u(rng), u(rng), u(rng)) * (hi - lo);
    const DVec3 dir = glm::normalize(target - c);
    double t0 = 0.0, t1 = 1e30;  // slab intersection
    for (int a = 0; a < 3; ++a) {
      if (std::abs(dir[a]) < 1e-15) continue;
      double ta = (lo[a] - c[a]) / dir[a], tb = (hi[a] - c[a]) / dir[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    if (t1 <= t0) continue;
    const DVec3 a = glm::normalize(c + t0 * dir - e), b = glm::normalize(c + t1 * dir - e);
    worst = std::max(worst, std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0)));
  }
  return worst;
}

TEST(ErrorAngleTest, BoundsTheBruteForceAngleAndIsTightForSidewaysMotion) {
  const Box3 box = Box3::fromPoints(Vec3(-5, 50, -5), Vec3(5, 60, 5));
  const Vec3 capture(0, 0, 0);
  EXPECT_EQ(errorAngle(capture, capture, box), 0.0);
  // Sideways (perpendicular to the view of the box): the closed form is close to the true maximum.
  const double sideways = errorAngle(capture, Vec3(1, 0, 0), box);
  const double brute_sideways = bruteForceErrorAngle(capture, Vec3(1, 0, 0), box);
  EXPECT_GE(sideways, brute_sideways);
  EXPECT_LE(sideways, 2.0 * brute_sideways);
  // Any direction, including straight towards the box (where the first-order form s (1/d_min - 1/d_max) would
  // underestimate) and up to a third of the way there.
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int k = 0; k < 40; ++k) {
    DVec3 dir(g(rng), g(rng), g(rng));
    if (k == 0) dir = DVec3(0, 1, 0);
    const double s = 0.5 + 16.0 * (k % 8) / 7.0;
    const Vec3 eye = Vec3(glm::normalize(dir) * s);
    const double closed = errorAngle(capture, eye, box), brute = bruteForceErrorAngle(capture, eye, box, 4000);
    EXPECT_GE(closed, brute * (1.0 - 1e-9)) << "eye " << eye.x << " " << eye.y << " " << eye.z;
  }
  // Monotone in the distance moved; pi inside (or when the move reaches the box); 0 for empty bounds.
  double previous = 0.0;
  for (double s : {0.1, 0.5, 1.0, 2.0, 5.0, 20.0}) {
    const double a = errorAngle(capture, Vec3(float(s), 0, 0), box);
    EXPECT_GT(a, previous);
    previous = a;
  }
  EXPECT_EQ(errorAngle(capture, Vec3(0, 50, 0), box), kPi);
  EXPECT_EQ(errorAngle(Vec3(0, 55, 0), Vec3(0, 55.1f, 0), box), kPi);
  EXPECT_EQ(errorAngle(capture, Vec3(1, 0, 0), Box3()), 0.0);
}

TEST_F(DynamicImpostorTest, ReproducesTheGeometryFromTheViewer) {
  // 192 px: the 240 px capture's texels fall exactly on the viewer's pixels; 200 px: a 256 px capture, resampled.
  for (int size : {192, 200}) {
    const Camera viewer = viewerCamera(size);
    const DynamicImpostor dyn(*renderer_, items_, viewer, boxes_.bounds);
    ASSERT_FALSE(dyn.empty());
    EXPECT_EQ(dyn.camera().width, size == 192 ? 240 : 256);  // size * 1.25 rounded up to a multiple of 8
    EXPECT_EQ(dyn.camera().eye, viewer.eye);
    EXPECT_GT(dyn.triangleCount(), 0u);
    EXPECT_GT(dyn.gpuBytes(), 0u);
    EXPECT_GT(dyn.updateMs(), 0.0);
    EXPECT_GT(dyn.dataPixels(), 0u);
    // Quantisation bounds: the nearest and farthest visible box surfaces along the view axis (the near box's front
    // face at y = -6 is 24 m away; the far box is seen only through its front face at y = 60, 90 m away).
    EXPECT_NEAR(dyn.depthNear(), 24.0, 0.5);
    EXPECT_NEAR(dyn.depthFar(), 90.0, 1.0);

    std::vector<gpu::DrawItem> drawn;
    dyn.appendDrawItems(drawn, kImpostorId);
    ASSERT_FALSE(drawn.empty());
    for (const gpu::DrawItem& item : drawn) EXPECT_EQ(item.object_id, kImpostorId);
    const Frame reference = render(*renderer_, viewer, items_);
    const Frame impostor = render(*renderer_, viewer, drawn);
    const double psnr = image::psnr(reference.color, impostor.color);
    const double missing = missingCoverage(reference, impostor), extra = extraCoverage(reference, impostor);
    std::printf("viewer %d px: dynamic impostor %dx%d, %llu triangles, update %.1f ms: PSNR %.2f dB, missing %.3f%%, "
                "extra %.3f%%\n",
                size, dyn.camera().width, dyn.camera().height, (unsigned long long)dyn.triangleCount(), dyn.updateMs(),
                psnr, 100.0 * missing, 100.0 * extra);
    EXPECT_GT(psnr, 25.0) << size;
    EXPECT_LT(missing, 0.01) << size;
    EXPECT_LT(extra, 0.01) << size;
  }
}

TEST_F(DynamicImpostorTest, SmallSidewaysMoveKeepsTheErrorSmall) {
  const Camera viewer = viewerCamera();
  const DynamicImpostor dyn(*renderer_, items_, viewer, boxes_.bounds);
  std::vector<gpu::DrawItem> drawn;
  dyn.appendDrawItems(drawn, kImpostorId);
  const Frame stale = render(*renderer_, viewer, items_);  // what showing the old frame would give

  Camera moved = viewer;
  moved.eye += Vec3(0.6f, 0.0f, 0.0f);
  moved.at += Vec3(0.6f, 0.0f, 0.0f);
  ASSERT_TRUE(dyn.covers(moved));
  const Frame reference = render(*renderer_, moved, items_);
  const Frame impostor = render(*renderer_, moved, drawn);
  const double psnr = image::psnr(reference.color, impostor.color);
  const double stale_psnr = image::psnr(reference.color, stale.color);
  const double missing = missingCoverage(reference, impostor);
  std::printf("moved 0.6 m: impostor PSNR %.2f dB (stale frame %.2f dB), missing %.3f%%, error angle %.2f mrad\n",
              psnr, stale_psnr, 100.0 * missing, 1000.0 * dyn.errorAngle(moved.eye));
  EXPECT_GT(psnr, 22.0);
  EXPECT_GT(psnr, stale_psnr + 3.0);  // the mesh's parallax beats no parallax at all
  EXPECT_LT(missing, 0.02);
  EXPECT_GT(dyn.errorAngle(moved.eye), 0.0);
  EXPECT_EQ(dyn.errorAngle(viewer.eye), 0.0);
  EXPECT_GT(dyn.errorAngle(viewer.eye + Vec3(2.0f, 0, 0)), dyn.errorAngle(moved.eye));
}

// Brute force for covers(): every border pixel ray of the viewer, at the window depths of the nearest and farthest
// view depth of the bounds, unprojected with Camera::unproject, projects into the capture image.
bool bruteForceCovers(const DynamicImpostor& dyn, const Camera& viewer, const Box3& bounds) {
  float d_lo = 1e30f, d_hi = 0.0f;
  for (int i = 0; i < 8; ++i) {
    const Vec3 c((i & 1) ? bounds.hi.x : bounds.lo.x, (i & 2) ? bounds.hi.y : bounds.lo.y,
                 (i & 4) ? bounds.hi.z : bounds.lo.z);
    const float d = glm::dot(c - viewer.eye, viewer.forward());
    d_lo = std::min(d_lo, d);
    d_hi = std::max(d_hi, d);
  }
  d_lo = std::clamp(d_lo, viewer.near_plane, viewer.far_plane);
  d_hi = std::clamp(d_hi, viewer.near_plane, viewer.far_plane);
  const Camera& cap = dyn.camera();
  for (float d : {d_lo, d_hi}) {
    const float z = float(windowDepthOf(d, viewer));
    for (int i = 0; i <= viewer.width; ++i)
      for (float y : {0.0f, float(viewer.height)})
        for (const Vec2& p : {Vec2(float(i), y), Vec2(y * float(viewer.width) / float(viewer.height),
                                                       float(i) * float(viewer.height) / float(viewer.width))}) {
          float w = 0.0f;
          const Vec3 q = cap.project(viewer.unproject(p.x, p.y, z), &w);
          if (w <= 0.0f || q.x < -0.01f || q.y < -0.01f || q.x > cap.width + 0.01f || q.y > cap.height + 0.01f)
            return false;
        }
  }
  return true;
}

TEST_F(DynamicImpostorTest, CoversSmallTurnsButNotLargeOnes) {
  const Camera viewer = viewerCamera();
  const DynamicImpostor dyn(*renderer_, items_, viewer, boxes_.bounds);
  EXPECT_TRUE(dyn.covers(viewer));
  EXPECT_TRUE(dyn.covers(yawed(viewer, 3.0)));
  EXPECT_TRUE(dyn.covers(yawed(viewer, -3.0)));
  EXPECT_FALSE(dyn.covers(yawed(viewer, 10.0)));
  EXPECT_FALSE(dyn.covers(yawed(viewer, -10.0)));
  Camera pitched = viewer;
  pitched.at.z += 30.0f * std::tan(float(degToRad(10.0)));
  EXPECT_FALSE(dyn.covers(pitched));
  Camera wider = viewer;
  wider.fov_y = float(degToRad(80.0));
  EXPECT_FALSE(dyn.covers(wider));
  // Against dense sampling of the viewer's border rays, away from the threshold (about 5.8 degrees of yaw).
  for (double deg = -9.0; deg <= 9.0; deg += 0.5) {
    if (std::abs(std::abs(deg) - 5.8) < 0.4) continue;
    const Camera turned = yawed(viewer, deg);
    EXPECT_EQ(dyn.covers(turned), bruteForceCovers(dyn, turned, boxes_.bounds)) << deg << " degrees";
  }
}

TEST_F(DynamicImpostorTest, CaptureCameraAndOptions) {
  Camera wide = viewerCamera();
  wide.width = 320;
  wide.height = 160;
  const Camera c = DynamicImpostor::captureCamera(wide, {});
  EXPECT_EQ(c.width, 400);
  EXPECT_EQ(c.height, 400);
  // Horizontal half-angle tangent is the wider one: margin times it.
  EXPECT_NEAR(std::tan(0.5 * c.fov_y), 1.25 * std::tan(0.5 * wide.fovX()), 1e-5);
  DynamicImpostorOptions o;
  o.resolution = 100;
  EXPECT_EQ(DynamicImpostor::captureCamera(wide, o).width, 100);
  o.fov_margin = 0.9f;
  EXPECT_THROW(DynamicImpostor::captureCamera(wide, o), Error);
  o = {};
  o.depth_bits = 0;
  EXPECT_THROW(DynamicImpostor(*renderer_, items_, viewerCamera(), boxes_.bounds, o), Error);
  o = {};
  o.grid_px = 0;
  EXPECT_THROW(DynamicImpostor(*renderer_, items_, viewerCamera(), boxes_.bounds, o), Error);
}

TEST_F(DynamicImpostorTest, NothingInViewGivesAnEmptyImpostor) {
  Camera away = viewerCamera();
  away.at = away.eye - Vec3(0.0f, 10.0f, 0.0f);  // looking away from every box
  const DynamicImpostor dyn(*renderer_, items_, away, boxes_.bounds);
  EXPECT_TRUE(dyn.empty());
  EXPECT_EQ(dyn.triangleCount(), 0u);
  EXPECT_EQ(dyn.dataPixels(), 0u);
  std::vector<gpu::DrawItem> drawn;
  dyn.appendDrawItems(drawn, kImpostorId);
  const Frame frame = render(*renderer_, away, drawn);
  for (uint32_t id : frame.ids.pixels()) ASSERT_EQ(id, 0u);
}

TEST_F(DynamicImpostorTest, FinerDepthAndGridReduceTheErrorAfterAMove) {
  // 8-bit depth on a coarse grid is the paper's trade; 16 bits on a fine grid should be at least as good from a
  // moved viewpoint (the quantisation and sub-sampling are the only differences).
  const Camera viewer = viewerCamera();
  Camera moved = viewer;
  moved.eye += Vec3(1.5f, 0.0f, 0.5f);
  moved.at += Vec3(1.5f, 0.0f, 0.5f);
  const Frame reference = render(*renderer_, moved, items_);
  auto psnrWith = [&](int bits, int grid) {
    DynamicImpostorOptions o;
    o.depth_bits = bits;
    o.grid_px = grid;
    const DynamicImpostor dyn(*renderer_, items_, viewer, boxes_.bounds, o);
    std::vector<gpu::DrawItem> drawn;
    dyn.appendDrawItems(drawn, kImpostorId);
    return image::psnr(reference.color, render(*renderer_, moved, drawn).color);
  };
  const double coarse = psnrWith(2, 16), paper = psnrWith(8, 8), fine = psnrWith(16, 4);
  std::printf("moved 1.6 m: PSNR 2-bit/16 px %.2f dB, 8-bit/8 px %.2f dB, 16-bit/4 px %.2f dB\n", coarse, paper, fine);
  EXPECT_GT(paper, coarse);
  EXPECT_GE(fine, paper - 0.5);
}

}  // namespace
}  // namespace farfield::runtime
