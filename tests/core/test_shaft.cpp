#include "farfield/core/shaft.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "farfield/core/error.h"

using namespace farfield;

TEST(Shaft, ContainsByHand) {
  const Shaft s = Shaft::make(Vec3(0.0f), Vec3(2, 0, 0), static_cast<float>(degToRad(90.0)), 10.0f);
  EXPECT_EQ(s.axis, Vec3(1, 0, 0));
  EXPECT_TRUE(s.contains(Vec3(20, 0, 0)));
  EXPECT_TRUE(s.contains(Vec3(20, 19.9f, 0)));   // 44.9 degrees off the axis
  EXPECT_FALSE(s.contains(Vec3(20, 20.2f, 0)));  // 45.3 degrees
  EXPECT_FALSE(s.contains(Vec3(9, 0, 0)));       // closer than the minimum distance
  EXPECT_FALSE(s.contains(Vec3(-20, 0, 0)));
}

TEST(Shaft, RejectsBadParameters) {
  EXPECT_THROW(Shaft::make(Vec3(0.0f), Vec3(0.0f), 1.0f, 1.0f), Error);
  EXPECT_THROW(Shaft::make(Vec3(0.0f), Vec3(1, 0, 0), 0.0f, 1.0f), Error);
  EXPECT_THROW(Shaft::make(Vec3(0.0f), Vec3(1, 0, 0), 4.0f, 1.0f), Error);
  EXPECT_THROW(Shaft::make(Vec3(0.0f), Vec3(1, 0, 0), 1.0f, -1.0f), Error);
  EXPECT_THROW(Shaft::make(Vec3(NAN, 0, 0), Vec3(1, 0, 0), 1.0f, 1.0f), Error);
}

// Box tests against dense sampling of the box: containsBox only when every sample is inside, mayIntersectBox
// whenever some sample is inside.
TEST(Shaft, BoxTestsAgreeWithSampling) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const float angles[] = {11.25f, 22.5f, 45.0f, 90.0f, 180.0f};
  int enclosed = 0, touching = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const Vec3 axis(uni(rng) - 0.5f, uni(rng) - 0.5f, 0.3f * (uni(rng) - 0.5f));
    const Shaft s = Shaft::make(Vec3(0.0f), axis, static_cast<float>(degToRad(angles[trial % 5])), 5.0f + 20.0f * uni(rng));
    const Vec3 c = s.apex + s.axis * (40.0f * uni(rng)) + Vec3(uni(rng) - 0.5f, uni(rng) - 0.5f, uni(rng) - 0.5f) * 30.0f;
    const Vec3 half = Vec3(uni(rng), uni(rng), uni(rng)) * 6.0f + Vec3(0.1f);
    const Box3 box = Box3::fromPoints(c - half, c + half);
    bool all = true, any = false;
    for (int i = 0; i <= 6; ++i)
      for (int j = 0; j <= 6; ++j)
        for (int k = 0; k <= 6; ++k) {
          const Vec3 p = box.lo + (box.hi - box.lo) * Vec3(i / 6.0f, j / 6.0f, k / 6.0f);
          const bool in = s.contains(p);
          all = all && in;
          any = any || in;
        }
    if (s.containsBox(box)) {
      ++enclosed;
      EXPECT_TRUE(all) << "trial " << trial;
    }
    if (any) {
      ++touching;
      EXPECT_TRUE(s.mayIntersectBox(box)) << "trial " << trial;
    }
  }
  EXPECT_GT(enclosed, 10);  // the trials exercise both answers
  EXPECT_GT(touching, 50);
}

TEST(Shaft, SamplesLieInside) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const Shaft s = Shaft::make(Vec3(5, 5, 1), Vec3(0, 1, 0), static_cast<float>(degToRad(22.5)), 8.0f);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 p = s.sample(uni(rng), uni(rng), uni(rng), 100.0f);
    EXPECT_TRUE(s.contains(p));
    EXPECT_LE(glm::length(p - s.apex), 100.0f + 1e-3f);
  }
}

// The shaft around a box view cell holds every point sampled in the box, and is the narrowest and nearest shaft with
// its apex and axis: some corner lies on its rim and the box's nearest point at its minimum distance.
TEST(Shaft, EnclosingShaftHoldsTheBoxAndIsTight) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  int made = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Vec3 apex(40.0f * uni(rng), 40.0f * uni(rng), 10.0f * uni(rng));
    const Vec3 c = apex + Vec3(uni(rng) - 0.5f, uni(rng) - 0.5f, 0.2f * (uni(rng) - 0.5f)) * 200.0f;
    const Vec3 half = Vec3(uni(rng) * 30.0f, uni(rng) * 30.0f, uni(rng) * 3.0f) + Vec3(0.1f);
    const Box3 box = Box3::fromPoints(c - half, c + half);
    const std::optional<Shaft> s = Shaft::enclosing(apex, box);
    if (box.contains(apex)) {
      EXPECT_FALSE(s.has_value()) << "trial " << trial;
      continue;
    }
    if (!s) continue;  // a box wider than a half-space seen from the apex
    ++made;
    EXPECT_TRUE(s->containsBox(box)) << "trial " << trial;
    float widest = 0.0f, nearest = 1e30f;
    for (int i = 0; i <= 6; ++i)
      for (int j = 0; j <= 6; ++j)
        for (int k = 0; k <= 6; ++k) {
          const Vec3 p = box.lo + (box.hi - box.lo) * Vec3(i / 6.0f, j / 6.0f, k / 6.0f);
          EXPECT_TRUE(s->contains(p)) << "trial " << trial;
          const Vec3 d = p - apex;
          widest = std::max(widest, std::acos(std::clamp(glm::dot(d, s->axis) / glm::length(d), -1.0f, 1.0f)));
          nearest = std::min(nearest, glm::length(d));
        }
    EXPECT_NEAR(2.0f * widest, s->apex_angle, 1e-3f) << "trial " << trial;  // the corners are among the samples
    EXPECT_LE(s->min_distance, nearest);
    EXPECT_GE(s->min_distance, nearest - 0.1f * glm::length(box.extent())) << "trial " << trial;
  }
  EXPECT_GT(made, 200);
  EXPECT_FALSE(Shaft::enclosing(Vec3(0.0f), Box3::fromPoints(Vec3(-1.0f), Vec3(1.0f))).has_value());
  EXPECT_FALSE(Shaft::enclosing(Vec3(0.0f), Box3{}).has_value());
}
