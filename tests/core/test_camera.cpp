#include "farfield/core/camera.h"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <utility>

#include "farfield/core/error.h"

using namespace farfield;

namespace {

// The camera frame built by hand: forward, right, up (independent of glm::lookAt).
struct Frame {
  DVec3 f, r, u;
};
Frame frameOf(const Camera& c) {
  DVec3 f = glm::normalize(DVec3(c.at) - DVec3(c.eye));
  DVec3 r = glm::normalize(glm::cross(f, DVec3(c.up)));
  return {f, r, glm::cross(r, f)};
}

// Inside the view volume by direct geometry: in front between near and far and within both half-angles.
bool insideByGeometry(const Camera& c, const Vec3& p) {
  Frame fr = frameOf(c);
  DVec3 q = DVec3(p) - DVec3(c.eye);
  double d = glm::dot(q, fr.f), x = glm::dot(q, fr.r), y = glm::dot(q, fr.u);
  double ty = std::tan(double(c.fov_y) / 2), tx = ty * double(c.width) / c.height;
  return d >= c.near_plane && d <= c.far_plane && std::abs(x) <= d * tx && std::abs(y) <= d * ty;
}

Camera testCamera() {
  Camera c;
  c.eye = Vec3(10, 20, 5);
  c.at = Vec3(30, 50, 8);
  c.up = Vec3(0, 0, 1);
  c.fov_y = float(degToRad(50.0));
  c.width = 640;
  c.height = 480;
  c.near_plane = 1.0f;
  c.far_plane = 500.0f;
  return c;
}

}  // namespace

TEST(Camera, PointStraightAheadMapsToCentre) {
  Camera c;
  c.eye = Vec3(0, 0, 0);
  c.at = Vec3(0, 10, 0);  // looking north
  c.width = 512;
  c.height = 256;
  float w = 0.0f;
  Vec3 p = c.project(Vec3(0, 25, 0), &w);
  EXPECT_NEAR(p.x, 256.0f, 1e-3f);
  EXPECT_NEAR(p.y, 128.0f, 1e-3f);
  EXPECT_NEAR(w, 25.0f, 1e-4f);
  EXPECT_NEAR(c.linearDepth(p.z), 25.0f, 25.0f * 1e-5f);
  // Reversed-Z formula by hand: depth(d) = n (f - d) / (d (f - n)).
  double n = c.near_plane, f = c.far_plane, d = 25.0;
  EXPECT_NEAR(p.z, n * (f - d) / (d * (f - n)), 1e-6);
}

// A resized camera keeps the pixel density: every point seen lands the same number of pixels from the image centre,
// whether the image grew (a guard band) or shrank.
TEST(Camera, ResizedKeepsThePixelDensity) {
  const Camera c = testCamera();
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (const auto& [w, h] : {std::pair{800, 600}, std::pair{320, 240}, std::pair{640, 700}}) {
    const Camera r = c.resized(w, h);
    EXPECT_EQ(r.width, w);
    EXPECT_EQ(r.height, h);
    for (int k = 0; k < 20; ++k) {
      const Vec3 p = c.eye + 60.0f * glm::normalize(c.at - c.eye) + Vec3(10.0f * u(rng), 10.0f * u(rng), 8.0f * u(rng));
      const Vec3 a = c.project(p), b = r.project(p);
      EXPECT_NEAR(a.x - 0.5f * float(c.width), b.x - 0.5f * float(w), 1e-2f) << w << "x" << h;
      EXPECT_NEAR(a.y - 0.5f * float(c.height), b.y - 0.5f * float(h), 1e-2f) << w << "x" << h;
    }
  }
}

TEST(Camera, AxesAndOffAxisPixels) {
  Camera c;
  c.eye = Vec3(0, 0, 0);
  c.at = Vec3(0, 1, 0);
  c.fov_y = float(degToRad(90.0));  // tan(fov/2) = 1
  c.width = 400;
  c.height = 200;
  // East (+x) is right, up (+z) is toward row 0. At distance 10 the half-height is 10 and half-width 20.
  Vec3 p = c.project(Vec3(10, 10, 5));
  EXPECT_NEAR(p.x, 200.0 + 200.0 * (10.0 / 20.0), 1e-3);
  EXPECT_NEAR(p.y, 100.0 - 100.0 * (5.0 / 10.0), 1e-3);
  EXPECT_NEAR(c.fovX(), 2.0 * std::atan(2.0), 1e-6);
  float w = 0.0f;
  c.project(Vec3(0, -5, 0), &w);
  EXPECT_LT(w, 0.0f);  // behind the camera
}

TEST(Camera, ReversedDepthNearIsOneFarIsZero) {
  Camera c = testCamera();
  Frame fr = frameOf(c);
  Vec3 at_near = Vec3(DVec3(c.eye) + fr.f * double(c.near_plane));
  Vec3 at_far = Vec3(DVec3(c.eye) + fr.f * double(c.far_plane));
  EXPECT_NEAR(c.project(at_near).z, 1.0f, 1e-5f);
  EXPECT_NEAR(c.project(at_far).z, 0.0f, 1e-5f);
  EXPECT_NEAR(c.linearDepth(1.0f), c.near_plane, 1e-5f);
  EXPECT_NEAR(c.linearDepth(0.0f), c.far_plane, 1e-2f);
  // Monotonically decreasing with distance.
  float prev = 2.0f;
  for (double d = 1.5; d < 500; d *= 1.3) {
    float z = c.project(Vec3(DVec3(c.eye) + fr.f * d)).z;
    EXPECT_LT(z, prev);
    prev = z;
  }
}

TEST(Camera, UnprojectProjectRoundTrip) {
  Camera c = testCamera();
  Frame fr = frameOf(c);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> px(0, 640), py(0, 480), dist(1.5f, 400.0f);
  for (int i = 0; i < 200; ++i) {
    float x = px(rng), y = py(rng), d = dist(rng);
    // Window depth for distance d by hand.
    double n = c.near_plane, f = c.far_plane;
    float depth = float(n * (f - d) / (double(d) * (f - n)));
    Vec3 world = c.unproject(x, y, depth);
    // The world point lies at distance d along the view axis.
    EXPECT_NEAR(glm::dot(DVec3(world) - DVec3(c.eye), fr.f), d, d * 1e-3);
    Vec3 back = c.project(world);
    EXPECT_NEAR(back.x, x, 2e-2f);
    EXPECT_NEAR(back.y, y, 2e-2f);
    EXPECT_NEAR(back.z, depth, 1e-5f);
  }
}

TEST(Camera, FrustumContainsMatchesGeometry) {
  Camera c = testCamera();
  Frustum fr = Frustum::fromMatrix(c.viewProjection());
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-300, 300);
  int inside = 0, checked = 0;
  for (int i = 0; i < 4000; ++i) {
    Vec3 p = c.eye + Vec3(u(rng), u(rng), u(rng) * 0.3f);
    // Skip points near a boundary, where float rounding may go either way.
    Vec3 q = p + Vec3(0.05f);
    Vec3 r = p - Vec3(0.05f);
    bool g = insideByGeometry(c, p);
    if (g != insideByGeometry(c, q) || g != insideByGeometry(c, r)) continue;
    ++checked;
    EXPECT_EQ(fr.contains(p), g) << p.x << " " << p.y << " " << p.z;
    inside += g;
  }
  EXPECT_GT(inside, 50);
  EXPECT_GT(checked, 3500);
}

TEST(Camera, FrustumIntersectsAgainstSampling) {
  Camera c = testCamera();
  Frustum fr = Frustum::fromMatrix(c.viewProjection());
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-250, 250), size(0.5f, 40.0f);
  int hits = 0, misses = 0;
  for (int i = 0; i < 400; ++i) {
    Vec3 lo = c.eye + Vec3(u(rng), u(rng), u(rng) * 0.3f);
    Box3 box = Box3::fromPoints(lo, lo + Vec3(size(rng), size(rng), size(rng)));
    // Brute force: any of 9^3 sample points inside the view volume means the box is visible.
    bool any_inside = false;
    for (int a = 0; a <= 8 && !any_inside; ++a)
      for (int b = 0; b <= 8 && !any_inside; ++b)
        for (int k = 0; k <= 8 && !any_inside; ++k) {
          Vec3 t(a / 8.0f, b / 8.0f, k / 8.0f);
          any_inside = insideByGeometry(c, box.lo + t * (box.hi - box.lo));
        }
    bool result = fr.intersects(box);
    if (any_inside) {
      EXPECT_TRUE(result);
      ++hits;
    }
    // Certainly outside: all 8 corners beyond one and the same plane (computed by hand from the frame).
    Frame f = frameOf(c);
    double ty = std::tan(double(c.fov_y) / 2), tx = ty * double(c.width) / c.height;
    bool all_behind = true, all_left = true, all_right = true, all_below = true, all_above = true;
    for (int j = 0; j < 8; ++j) {
      DVec3 v((j & 1) ? box.hi.x : box.lo.x, (j & 2) ? box.hi.y : box.lo.y, (j & 4) ? box.hi.z : box.lo.z);
      DVec3 q = v - DVec3(c.eye);
      double d = glm::dot(q, f.f), x = glm::dot(q, f.r), y = glm::dot(q, f.u);
      all_behind &= d < c.near_plane - 1e-3;
      all_left &= x < -d * tx - 1e-3;
      all_right &= x > d * tx + 1e-3;
      all_below &= y < -d * ty - 1e-3;
      all_above &= y > d * ty + 1e-3;
    }
    if (all_behind || all_left || all_right || all_below || all_above) {
      EXPECT_FALSE(result);
      ++misses;
    }
  }
  EXPECT_GT(hits, 20);
  EXPECT_GT(misses, 100);
  EXPECT_FALSE(fr.intersects(Box3{}));  // empty box
}

TEST(Camera, ValidateRejectsBadCameras) {
  Camera good = testCamera();
  EXPECT_NO_THROW(good.validate());
  auto expectError = [](const Camera& c, const char* name) {
    try {
      c.validate(name);
      ADD_FAILURE() << "no error for " << name;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  };
  Camera c = good;
  c.at = c.eye;
  expectError(c, "eye-equals-at");
  c = good;
  c.fov_y = 0.0f;
  expectError(c, "zero-fov");
  c = good;
  c.fov_y = float(kPi);
  expectError(c, "fov-180");
  c = good;
  c.fov_y = std::nanf("");
  expectError(c, "nan-fov");
  c = good;
  c.up = glm::normalize(c.at - c.eye);
  expectError(c, "up-parallel");
  c = good;
  c.width = 0;
  expectError(c, "zero-width");
  c = good;
  c.far_plane = c.near_plane;
  expectError(c, "near-equals-far");
  c = good;
  c.eye.x = std::numeric_limits<float>::infinity();
  expectError(c, "infinite-eye");
}
