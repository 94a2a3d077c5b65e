#include "farfield/core/bounds.h"

#include <gtest/gtest.h>

#include <random>

using namespace farfield;

TEST(Bounds, EmptyAndExpand) {
  Box3 b;
  EXPECT_TRUE(b.empty());
  EXPECT_EQ(b.extent(), Vec3(0.0f));
  EXPECT_FALSE(b.contains(Vec3(0.0f)));
  EXPECT_EQ(surfaceArea(b), 0.0f);
  b.expand(Vec3(1, 2, 3));
  EXPECT_FALSE(b.empty());
  EXPECT_EQ(b.lo, Vec3(1, 2, 3));
  EXPECT_EQ(b.hi, Vec3(1, 2, 3));
  b.expand(Vec3(-1, 5, 0));
  EXPECT_EQ(b.lo, Vec3(-1, 2, 0));
  EXPECT_EQ(b.hi, Vec3(1, 5, 3));
  EXPECT_EQ(b.center(), Vec3(0, 3.5f, 1.5f));
  EXPECT_EQ(b.extent(), Vec3(2, 3, 3));
  // Expanding by an empty box changes nothing.
  Box3 c = b;
  c.expand(Box3{});
  EXPECT_EQ(c.lo, b.lo);
  EXPECT_EQ(c.hi, b.hi);
  // 2 x 3 x 3 box: 2 (6 + 9 + 6).
  EXPECT_FLOAT_EQ(surfaceArea(b), 42.0f);
  EXPECT_EQ(b.longestAxis(), 1);
}

TEST(Bounds, ContainsAndOverlaps) {
  Box3 a = Box3::fromPoints(Vec3(0, 0, 0), Vec3(2, 2, 2));
  EXPECT_TRUE(a.contains(Vec3(2, 0, 1)));  // closed box
  EXPECT_FALSE(a.contains(Vec3(2.01f, 1, 1)));
  EXPECT_TRUE(a.overlaps(Box3::fromPoints(Vec3(2, 2, 2), Vec3(3, 3, 3))));  // touching corner
  EXPECT_FALSE(a.overlaps(Box3::fromPoints(Vec3(2.1f, 0, 0), Vec3(3, 1, 1))));
  EXPECT_TRUE(a.overlaps(Box3::fromPoints(Vec3(0.5f, 0.5f, -5), Vec3(1, 1, 5))));
  Box2 q = Box2::fromPoints(Vec2(3, 1), Vec2(1, 4));  // order of the points does not matter
  EXPECT_EQ(q.lo, Vec2(1, 1));
  EXPECT_EQ(q.hi, Vec2(3, 4));
}

TEST(Bounds, TransformBoxRotationMatchesAbsMatrix) {
  // For a rotation R and translation t, the tight box of a box with centre c and half extents e has centre
  // R c + t and half extents |R| e (entrywise absolute values).
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-1, 1);
  for (int i = 0; i < 50; ++i) {
    Vec3 axis = glm::normalize(Vec3(u(rng), u(rng), u(rng)) + Vec3(0, 0, 1e-3f));
    float angle = u(rng) * 3.0f;
    Vec3 t(u(rng) * 100, u(rng) * 100, u(rng) * 100);
    Mat4 m = glm::translate(Mat4(1.0f), t) * glm::rotate(Mat4(1.0f), angle, axis);
    Box3 b = Box3::fromPoints(Vec3(u(rng), u(rng), u(rng)) * 5.0f, Vec3(u(rng), u(rng), u(rng)) * 5.0f);
    Box3 out = transformBox(b, m);
    Mat3 r(m);
    Vec3 c = r * b.center() + t;
    Vec3 e = b.extent() * 0.5f;
    for (int k = 0; k < 3; ++k) {
      float he = std::abs(r[0][k]) * e.x + std::abs(r[1][k]) * e.y + std::abs(r[2][k]) * e.z;
      EXPECT_NEAR(out.lo[k], c[k] - he, 1e-3f);
      EXPECT_NEAR(out.hi[k], c[k] + he, 1e-3f);
    }
    // Every transformed interior sample stays inside.
    for (int s = 0; s < 20; ++s) {
      Vec3 f((u(rng) + 1) / 2, (u(rng) + 1) / 2, (u(rng) + 1) / 2);
      Vec3 p = Vec3(m * Vec4(b.lo + f * (b.hi - b.lo), 1.0f));
      Box3 grown = out;
      grown.lo -= Vec3(1e-3f);
      grown.hi += Vec3(1e-3f);
      EXPECT_TRUE(grown.contains(p));
    }
  }
  EXPECT_TRUE(transformBox(Box3{}, Mat4(1.0f)).empty());
}

TEST(Bounds, TransformBoxQuarterTurn) {
  Box3 b = Box3::fromPoints(Vec3(0, 0, 0), Vec3(1, 1, 1));
  Box3 out = transformBox(b, glm::rotate(Mat4(1.0f), float(kPi / 4), Vec3(0, 0, 1)));
  float s = float(std::sqrt(0.5));
  EXPECT_NEAR(out.lo.x, -s, 1e-6f);
  EXPECT_NEAR(out.hi.x, s, 1e-6f);
  EXPECT_NEAR(out.lo.y, 0.0f, 1e-6f);
  EXPECT_NEAR(out.hi.y, 2 * s, 1e-6f);
  EXPECT_NEAR(out.hi.z, 1.0f, 1e-6f);
}
