#include "farfield/gen/walker_figure.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "farfield/gen/figure_builder.h"

namespace farfield::gen {
namespace {

float deg(double d) { return float(degToRad(d)); }
scene::Quat turn(float radians, Vec3 axis) { return glm::angleAxis(radians, axis); }
const Vec3 kX(1, 0, 0), kY(0, 1, 0), kZ(0, 0, 1);

struct Limb {
  uint16_t upper, lower, end;  // thigh, shin, foot; or upper arm, forearm, hand
};

}  // namespace

scene::SkinnedModel makeWalkerFigure() {
  FigureBuilder b("builtin:walker");
  const uint16_t hips = b.addJoint("hips", -1, Vec3(0, 0, 0.98f));
  const uint16_t spine = b.addJoint("spine", hips, Vec3(0, 0, 1.10f));
  const uint16_t chest = b.addJoint("chest", spine, Vec3(0, 0, 1.32f));
  const uint16_t head = b.addJoint("head", chest, Vec3(0, 0, 1.50f));
  Limb arm[2], leg[2];  // [0] left (+y), [1] right
  for (int i = 0; i < 2; ++i) {
    const float s = i == 0 ? 1.0f : -1.0f;
    const std::string suffix = i == 0 ? ".L" : ".R";
    arm[i].upper = b.addJoint("upper_arm" + suffix, chest, Vec3(0, 0.205f * s, 1.44f));
    arm[i].lower = b.addJoint("forearm" + suffix, arm[i].upper, Vec3(0, 0.215f * s, 1.16f));
    arm[i].end = b.addJoint("hand" + suffix, arm[i].lower, Vec3(0, 0.22f * s, 0.91f));
  }
  for (int i = 0; i < 2; ++i) {
    const float s = i == 0 ? 1.0f : -1.0f;
    const std::string suffix = i == 0 ? ".L" : ".R";
    leg[i].upper = b.addJoint("thigh" + suffix, hips, Vec3(0, 0.095f * s, 0.93f));
    leg[i].lower = b.addJoint("shin" + suffix, leg[i].upper, Vec3(0.005f, 0.095f * s, 0.51f));
    leg[i].end = b.addJoint("foot" + suffix, leg[i].lower, Vec3(0, 0.095f * s, 0.09f));
  }

  const uint32_t skin = b.addMaterial(kWalkerSkin, {224, 172, 138, 255});
  const uint32_t hair = b.addMaterial(kWalkerHair, {78, 56, 40, 255});
  const uint32_t top = b.addMaterial(kWalkerTop, {206, 206, 212, 255});
  const uint32_t trousers = b.addMaterial(kWalkerTrousers, {92, 102, 134, 255});
  const uint32_t shoes = b.addMaterial(kWalkerShoes, {56, 48, 44, 255});

  for (int i = 0; i < 2; ++i) {
    const float y = i == 0 ? 0.095f : -0.095f;
    const Limb& l = leg[i];
    const TubeRing rings[] = {{Vec3(0, y, 0.99f), Vec2(0.085f, 0.09f), {l.upper, hips, 0.25f}},
                              {Vec3(0, y, 0.75f), Vec2(0.07f, 0.075f), {l.upper, l.upper, 0.0f}},
                              {Vec3(0.005f, y, 0.51f), Vec2(0.056f, 0.06f), {l.upper, l.lower, 0.5f}},
                              {Vec3(0, y, 0.30f), Vec2(0.05f, 0.052f), {l.lower, l.lower, 0.0f}},
                              {Vec3(0, y, 0.11f), Vec2(0.04f, 0.042f), {l.lower, l.end, 0.3f}}};
    b.addTube(rings, 6, trousers);
    b.addBox(Vec3(0.05f, y, 0.045f), Vec3(0.12f, 0.05f, 0.045f), {l.end, l.end, 0.0f}, shoes);
  }
  {
    const TubeRing pelvis[] = {{Vec3(0, 0, 0.88f), Vec2(0.165f, 0.10f), {hips, hips, 0.0f}},
                               {Vec3(0, 0, 1.05f), Vec2(0.16f, 0.10f), {hips, spine, 0.3f}}};
    b.addTube(pelvis, 8, trousers);
    const TubeRing torso[] = {{Vec3(0, 0, 1.02f), Vec2(0.155f, 0.098f), {hips, spine, 0.5f}},
                              {Vec3(0, 0, 1.20f), Vec2(0.16f, 0.10f), {spine, spine, 0.0f}},
                              {Vec3(0, 0, 1.33f), Vec2(0.185f, 0.11f), {spine, chest, 0.5f}},
                              {Vec3(0, 0, 1.45f), Vec2(0.20f, 0.105f), {chest, chest, 0.0f}},
                              {Vec3(0, 0, 1.52f), Vec2(0.10f, 0.07f), {chest, chest, 0.0f}}};
    b.addTube(torso, 8, top);
    const TubeRing neck[] = {{Vec3(0, 0, 1.49f), Vec2(0.05f, 0.05f), {chest, head, 0.5f}},
                             {Vec3(0, 0, 1.60f), Vec2(0.046f, 0.046f), {head, head, 0.0f}}};
    b.addTube(neck, 6, skin, false, false);
    const TubeRing face[] = {{Vec3(0.01f, 0, 1.56f), Vec2(0.06f, 0.065f), {head, head, 0.0f}},
                             {Vec3(0.01f, 0, 1.62f), Vec2(0.08f, 0.095f), {head, head, 0.0f}},
                             {Vec3(0.0f, 0, 1.69f), Vec2(0.083f, 0.10f), {head, head, 0.0f}},
                             {Vec3(0.0f, 0, 1.74f), Vec2(0.06f, 0.075f), {head, head, 0.0f}}};
    b.addTube(face, 8, skin);
    const TubeRing scalp[] = {{Vec3(-0.012f, 0, 1.665f), Vec2(0.089f, 0.106f), {head, head, 0.0f}},
                              {Vec3(-0.01f, 0, 1.72f), Vec2(0.085f, 0.101f), {head, head, 0.0f}},
                              {Vec3(-0.005f, 0, 1.765f), Vec2(0.045f, 0.06f), {head, head, 0.0f}}};
    b.addTube(scalp, 8, hair);
    b.addBox(Vec3(-0.075f, 0, 1.635f), Vec3(0.03f, 0.08f, 0.05f), {head, head, 0.0f}, hair);  // the back of the head
    b.addBox(Vec3(0.095f, 0, 1.64f), Vec3(0.018f, 0.014f, 0.02f), {head, head, 0.0f}, skin);  // the nose
  }
  for (int i = 0; i < 2; ++i) {
    const float s = i == 0 ? 1.0f : -1.0f;
    const Limb& l = arm[i];
    const TubeRing rings[] = {{Vec3(0, 0.2f * s, 1.445f), Vec2(0.05f, 0.058f), {l.upper, chest, 0.25f}},
                              {Vec3(0, 0.21f * s, 1.30f), Vec2(0.05f, 0.055f), {l.upper, l.upper, 0.0f}},
                              {Vec3(0, 0.215f * s, 1.16f), Vec2(0.045f, 0.05f), {l.upper, l.lower, 0.5f}},
                              {Vec3(0, 0.22f * s, 0.93f), Vec2(0.037f, 0.04f), {l.lower, l.end, 0.2f}}};
    b.addTube(rings, 6, top);
    b.addBox(Vec3(0, 0.22f * s, 0.855f), Vec3(0.03f, 0.022f, 0.055f), {l.end, l.end, 0.0f}, skin);
  }

  // The walk: phase 0..1 over the cycle, the left leg forward in its first half.
  auto pose = [&](float phase, std::vector<scene::NodePose>& poses) {
    const float a = float(2.0 * kPi) * phase;
    for (int i = 0; i < 2; ++i) {
      const float side = i == 0 ? 1.0f : -1.0f;
      const float al = a + (i == 0 ? 0.0f : float(kPi));
      // Thigh about +y: negative swings the leg forward. The knee bends most early in the swing (while the leg moves
      // forward, cos al > 0), a little in the stance; the foot is held about level.
      const float hip = -deg(22) * std::sin(al);
      const float c = std::max(0.0f, std::cos(al + 0.35f));
      const float knee = deg(5) + deg(45) * c * c;
      poses[leg[i].upper].rotation = turn(hip, kY);
      poses[leg[i].lower].rotation = turn(knee, kY);
      poses[leg[i].end].rotation = turn(-0.85f * (hip + knee), kY);
      // The arm swings against the leg of its side, a little out from the body, the elbow bent more forward.
      const float swing = deg(18) * std::sin(al);
      poses[arm[i].upper].rotation = turn(swing, kY) * turn(side * deg(6), kX);
      poses[arm[i].lower].rotation = turn(-deg(15) - deg(15) * (0.5f - 0.5f * std::sin(al)), kY);
    }
    // The hips turn with the forward leg and sway over the standing one; the chest turns against them, the head
    // keeps looking ahead.
    poses[hips].rotation = turn(-deg(5) * std::sin(a), kZ);
    poses[hips].translation.y -= 0.012f * std::cos(a);
    poses[spine].rotation = turn(deg(3), kY);
    poses[chest].rotation = turn(deg(9) * std::sin(a), kZ);
    poses[head].rotation = turn(-deg(4) * std::sin(a), kZ) * turn(-deg(3), kY);
  };
  std::vector<scene::Animation> animations;
  animations.push_back(b.loopingAnimation("walk", kWalkerCycleSeconds, 33, pose, true));
  return b.build(std::move(animations));
}

}  // namespace farfield::gen
