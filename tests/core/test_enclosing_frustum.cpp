#include "farfield/core/enclosing_frustum.h"

#include <gtest/gtest.h>

#include <random>

#include "farfield/core/error.h"

using namespace farfield;

namespace {

Vec3 randomUnit(std::mt19937& rng) {
  std::normal_distribution<float> g(0.0f, 1.0f);
  Vec3 d;
  do d = Vec3(g(rng), g(rng), g(rng));
  while (glm::length(d) < 1e-3f);
  return glm::normalize(d);
}

// A VDI reached by `levels` random quadtree steps from a random face.
Vdi randomVdi(std::mt19937& rng, int levels) {
  Vdi vdi = Vdi::fullFace(int(rng() % 6));
  for (int l = 0; l < levels; ++l) vdi = vdi.split()[rng() % 4];
  return vdi;
}

double planeValue(const Vec4& p, const Vec3& q) {
  return double(p.x) * q.x + double(p.y) * q.y + double(p.z) * q.z + double(p.w);
}

}  // namespace

TEST(Vdi, FacesCoverEveryDirectionAndChildrenCoverTheParent) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 5000; ++trial) {
    const Vec3 d = randomUnit(rng);
    int faces = 0;
    for (int f = 0; f < 6; ++f) faces += Vdi::fullFace(f).contains(d) ? 1 : 0;
    EXPECT_GE(faces, 1);
    const int face = Vdi::faceOf(d);
    EXPECT_TRUE(Vdi::fullFace(face).contains(d));
    const Vec2 uv = Vdi::faceCoords(face, d);
    EXPECT_NEAR(glm::dot(Vdi::fullFace(face).direction(uv.x, uv.y), d), 1.0f, 1e-5f);
    // Descend the quadtree along the children that contain d: at every level one of them does.
    Vdi vdi = Vdi::fullFace(face);
    for (int level = 0; level < 6; ++level) {
      int holding = -1;
      for (int k = 0; k < 4; ++k)
        if (vdi.split()[size_t(k)].contains(d)) holding = k;
      ASSERT_GE(holding, 0);
      vdi = vdi.split()[size_t(holding)];
    }
    EXPECT_LT(vdi.angularRadius(), float(degToRad(2.0)));
  }
  EXPECT_NEAR(radToDeg(Vdi::fullFace(0).angularRadius()), 54.7356, 1e-3);  // cube corner
}

// Every point of every sampled view frustum (eye in the box, direction in the VDI, random roll) is inside the
// enclosing frustum.
TEST(EnclosingFrustum, ContainsEverySampledViewFrustum) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  int points = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const Vec3 lo = (Vec3(uni(rng), uni(rng), uni(rng)) - 0.5f) * 200.0f;
    const Box3 box = Box3::fromPoints(lo, lo + Vec3(uni(rng), uni(rng), uni(rng)) * 40.0f + Vec3(0.01f));
    const Vdi vdi = randomVdi(rng, int(rng() % 5));
    Camera cam;
    cam.fov_y = float(degToRad(20.0 + 80.0 * uni(rng)));
    cam.width = 200 + int(rng() % 400);
    cam.height = 200 + int(rng() % 400);
    cam.near_plane = 0.1f + uni(rng);
    cam.far_plane = 50.0f + 500.0f * uni(rng);
    const Frustum ef = enclosingFrustum(box, vdi, Lens::fromCamera(cam));
    const double tol = 1e-5 * cam.far_plane;
    for (int view = 0; view < 20; ++view) {
      cam.eye = box.lo + Vec3(uni(rng), uni(rng), uni(rng)) * box.extent();
      if (view < 8) cam.eye = Vec3((view & 1) ? box.hi.x : box.lo.x, (view & 2) ? box.hi.y : box.lo.y,
                                   (view & 4) ? box.hi.z : box.lo.z);
      // Directions at the VDI's corners and inside it.
      const float u = view % 3 == 0 ? (uni(rng) < 0.5f ? vdi.u0 : vdi.u1) : vdi.u0 + uni(rng) * (vdi.u1 - vdi.u0);
      const float v = view % 3 == 0 ? (uni(rng) < 0.5f ? vdi.v0 : vdi.v1) : vdi.v0 + uni(rng) * (vdi.v1 - vdi.v0);
      const Vec3 dir = vdi.direction(u, v);
      cam.at = cam.eye + dir * 10.0f;
      Vec3 up = randomUnit(rng);
      if (view % 2 == 0) up = Vec3(0, 0, 1);
      if (glm::length(glm::cross(up, dir)) < 0.05f) up = glm::normalize(glm::cross(dir, Vec3(1, 0, 0)) + Vec3(0, 1e-3f, 0));
      cam.up = up;
      for (int s = 0; s < 40; ++s) {
        float px = uni(rng) * float(cam.width), py = uni(rng) * float(cam.height), depth = uni(rng);
        if (s < 8) {  // the view frustum's corners
          px = (s & 1) ? float(cam.width) : 0.0f;
          py = (s & 2) ? float(cam.height) : 0.0f;
          depth = (s & 4) ? 1.0f : 0.0f;
        }
        const Vec3 q = cam.unproject(px, py, depth);
        for (int k = 0; k < 6; ++k)
          ASSERT_GE(planeValue(ef.planes[size_t(k)], q), -tol)
              << "trial " << trial << " plane " << k << " face " << vdi.face << " [" << vdi.u0 << "," << vdi.u1
              << "]x[" << vdi.v0 << "," << vdi.v1 << "]";
        ++points;
      }
    }
  }
  EXPECT_EQ(points, 400 * 20 * 40);
}

// Not absurdly loose: for narrow VDIs, directions well outside the VDI widened by the lens cone are excluded, the
// opposite direction is excluded for every VDI below a full face, and points beyond the far reach are excluded.
TEST(EnclosingFrustum, ExcludesWhatNoViewSees) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const Lens lens{float(degToRad(60.0)), 1.0f, 0.5f, 1000.0f};
  const double rho = lens.halfDiagonal();
  int excluded = 0, sampled = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Vec3 lo = (Vec3(uni(rng), uni(rng), uni(rng)) - 0.5f) * 100.0f;
    const Box3 box = Box3::fromPoints(lo, lo + Vec3(5.0f));
    const Vdi vdi = randomVdi(rng, 3);  // 11.25 degrees
    const Frustum ef = enclosingFrustum(box, vdi, lens);
    const Vec3 center = vdi.centerDirection();
    EXPECT_FALSE(ef.contains(box.center() - center * 300.0f));
    EXPECT_FALSE(ef.contains(box.center() + center * 1300.0f));  // beyond far / cos(rho) = 1225 m
    EXPECT_TRUE(ef.contains(box.center() + center * 500.0f));
    const Vdi wide_vdi = randomVdi(rng, 1);  // a quarter face
    const Frustum wide = enclosingFrustum(box, wide_vdi, lens);
    const Vec3 opposite = box.center() - wide_vdi.centerDirection() * 400.0f;
    EXPECT_FALSE(wide.intersects(Box3::fromPoints(opposite - Vec3(2.0f), opposite + Vec3(2.0f))));
    for (int s = 0; s < 50; ++s) {
      const Vec3 d = randomUnit(rng);
      const double angle = std::acos(std::clamp(double(glm::dot(d, center)), -1.0, 1.0));
      if (angle < double(vdi.angularRadius()) + rho + degToRad(25.0)) continue;
      ++sampled;
      if (!ef.contains(box.center() + d * 400.0f)) ++excluded;
    }
  }
  EXPECT_GT(sampled, 5000);
  EXPECT_EQ(excluded, sampled);
}

TEST(EnclosingFrustum, BoxTests) {
  const Lens lens{float(degToRad(45.0)), 1.5f, 0.5f, 500.0f};
  const Box3 region = Box3::fromPoints(Vec3(0.0f), Vec3(10.0f, 10.0f, 2.0f));
  const Vdi east = Vdi::fullFace(0).split()[0].split()[3];  // +X face, u and v in [-0.5, 0]
  const Frustum ef = enclosingFrustum(region, east, lens);
  const Box3 ahead = Box3::fromPoints(Vec3(100.0f, -20.0f, -10.0f), Vec3(110.0f, -10.0f, 0.0f));
  const Box3 behind = Box3::fromPoints(Vec3(-110.0f, -5.0f, 0.0f), Vec3(-100.0f, 5.0f, 2.0f));
  EXPECT_TRUE(mayIntersect(ef, ahead));
  EXPECT_TRUE(containsBox(ef, ahead));
  EXPECT_FALSE(mayIntersect(ef, behind));
  EXPECT_FALSE(containsBox(ef, behind));
  EXPECT_FALSE(containsBox(ef, Box3{}));
  // containsBox agrees with its corners.
  const Box3 straddling = Box3::fromPoints(Vec3(100.0f, -20.0f, -10.0f), Vec3(1000.0f, -10.0f, 0.0f));  // beyond far / cos(rho) = 619 m
  EXPECT_TRUE(mayIntersect(ef, straddling));
  EXPECT_FALSE(containsBox(ef, straddling));
}

TEST(EnclosingFrustum, RejectsBadInput) {
  const Lens lens;
  const Box3 box = Box3::fromPoints(Vec3(0.0f), Vec3(1.0f));
  EXPECT_NO_THROW(enclosingFrustum(box, Vdi::fullFace(5), lens));
  EXPECT_THROW(enclosingFrustum(Box3{}, Vdi::fullFace(0), lens), Error);
  EXPECT_THROW(enclosingFrustum(box, Vdi::fullFace(6), lens), Error);
  EXPECT_THROW(enclosingFrustum(box, Vdi{0, 0.5f, 0.2f, -1.0f, 1.0f}, lens), Error);
  EXPECT_THROW(enclosingFrustum(box, Vdi{0, -1.5f, 0.2f, -1.0f, 1.0f}, lens), Error);
  EXPECT_THROW(enclosingFrustum(box, Vdi::fullFace(0), Lens{0.0f, 1.0f, 0.5f, 10.0f}), Error);
  EXPECT_THROW(enclosingFrustum(box, Vdi::fullFace(0), Lens{1.0f, 0.0f, 0.5f, 10.0f}), Error);
  EXPECT_THROW(enclosingFrustum(box, Vdi::fullFace(0), Lens{1.0f, 1.0f, 0.5f, 0.1f}), Error);
}
