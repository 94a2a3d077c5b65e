#include "farfield/scene/animation.h"

#include <gtest/gtest.h>

#include <cmath>

namespace farfield::scene {
namespace {

TEST(Animation, LinearAndStepTranslation) {
  AnimationChannel c;
  c.times = {1.0f, 3.0f};
  c.values = {Vec4(0, 0, 0, 0), Vec4(4, 2, 0, 0)};
  EXPECT_FLOAT_EQ(sampleChannel(c, 2.0f).x, 2.0f);
  EXPECT_FLOAT_EQ(sampleChannel(c, 2.5f).y, 1.5f);
  EXPECT_FLOAT_EQ(sampleChannel(c, 0.0f).x, 0.0f);  // clamped before the first key
  EXPECT_FLOAT_EQ(sampleChannel(c, 9.0f).x, 4.0f);  // and after the last
  c.interpolation = Interpolation::Step;
  EXPECT_FLOAT_EQ(sampleChannel(c, 2.9f).x, 0.0f);
  EXPECT_FLOAT_EQ(sampleChannel(c, 3.0f).x, 4.0f);
}

TEST(Animation, RotationBySlerpMatchesTheAngleAxisFormula) {
  AnimationChannel c;
  c.path = AnimationPath::Rotation;
  c.times = {0.0f, 1.0f};
  const Quat a = glm::angleAxis(0.2f, Vec3(0, 0, 1)), b = glm::angleAxis(1.4f, Vec3(0, 0, 1));
  // b stored negated: the same rotation, the interpolation must take the short arc anyway.
  c.values = {Vec4(a.x, a.y, a.z, a.w), -Vec4(b.x, b.y, b.z, b.w)};
  for (float s : {0.1f, 0.5f, 0.8f}) {
    const Vec4 v = sampleChannel(c, s);
    const Quat want = glm::angleAxis(0.2f + 1.2f * s, Vec3(0, 0, 1));
    EXPECT_NEAR(std::abs(glm::dot(Quat(v.w, v.x, v.y, v.z), want)), 1.0f, 1e-5f) << s;
  }
}

TEST(Animation, TimeWrapsOverTheDuration) {
  Animation anim;
  AnimationChannel c;
  c.times = {0.5f, 1.5f};
  c.values = {Vec4(0, 0, 0, 0), Vec4(10, 0, 0, 0)};
  anim.channels.push_back(c);
  anim.start = 0.5f;
  anim.duration = 1.0f;
  std::vector<NodePose> poses(1);
  applyAnimation(anim, 1.0f, poses);
  EXPECT_FLOAT_EQ(poses[0].translation.x, 5.0f);
  applyAnimation(anim, 3.0f, poses);  // 3.0 = 1.0 + two durations
  EXPECT_FLOAT_EQ(poses[0].translation.x, 5.0f);
}

}  // namespace
}  // namespace farfield::scene
