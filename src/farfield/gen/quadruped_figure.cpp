#include "farfield/gen/quadruped_figure.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "farfield/gen/figure_builder.h"

namespace farfield::gen {
namespace {

float deg(double d) { return float(degToRad(d)); }
scene::Quat turn(float radians, Vec3 axis) { return glm::angleAxis(radians, axis); }
const Vec3 kY(0, 1, 0), kZ(0, 0, 1);

struct Leg {
  uint16_t upper, lower, paw;
  float phase;  // its offset in the cycle (0, 0.25, 0.5, 0.75)
};

}  // namespace

scene::SkinnedModel makeQuadrupedFigure() {
  FigureBuilder b("builtin:quadruped");
  const uint16_t pelvis = b.addJoint("pelvis", -1, Vec3(-0.20f, 0, 0.40f));
  const uint16_t chest = b.addJoint("chest", pelvis, Vec3(0.17f, 0, 0.41f));
  const uint16_t neck = b.addJoint("neck", chest, Vec3(0.25f, 0, 0.45f));
  const uint16_t head = b.addJoint("head", neck, Vec3(0.34f, 0, 0.55f));
  const uint16_t tail = b.addJoint("tail", pelvis, Vec3(-0.31f, 0, 0.44f));
  const uint16_t tail_tip = b.addJoint("tail_tip", tail, Vec3(-0.46f, 0, 0.48f));
  // Legs in the order of the walk's footfalls: hind left, front left, hind right, front right.
  Leg legs[4];
  const char* names[4] = {"hind.L", "front.L", "hind.R", "front.R"};
  for (int i = 0; i < 4; ++i) {
    const bool front = i % 2 == 1;
    const float y = i < 2 ? 0.075f : -0.075f;
    const float x = front ? 0.18f : -0.21f;
    const std::string n = names[i];
    legs[i].upper = b.addJoint("upper_" + n, front ? chest : pelvis, Vec3(x, y, 0.37f));
    legs[i].lower = b.addJoint("lower_" + n, legs[i].upper, Vec3(front ? x : x - 0.02f, y, 0.20f));
    legs[i].paw = b.addJoint("paw_" + n, legs[i].lower, Vec3(x + 0.005f, y, 0.04f));
    legs[i].phase = 0.25f * float(i);
  }

  const uint32_t fur = b.addMaterial(kQuadrupedFur, {190, 112, 58, 255});
  const uint32_t pale = b.addMaterial(kQuadrupedPale, {238, 228, 210, 255});
  const uint32_t dark = b.addMaterial(kQuadrupedDark, {54, 44, 40, 255});

  const TubeRing body[] = {{Vec3(-0.35f, 0, 0.43f), Vec2(0.07f, 0.075f), {pelvis, pelvis, 0.0f}},
                           {Vec3(-0.26f, 0, 0.42f), Vec2(0.10f, 0.11f), {pelvis, pelvis, 0.0f}},
                           {Vec3(-0.03f, 0, 0.41f), Vec2(0.095f, 0.11f), {pelvis, chest, 0.5f}},
                           {Vec3(0.15f, 0, 0.42f), Vec2(0.105f, 0.125f), {chest, chest, 0.0f}},
                           {Vec3(0.26f, 0, 0.44f), Vec2(0.08f, 0.095f), {chest, chest, 0.0f}}};
  b.addTube(body, 8, fur);
  const TubeRing neck_rings[] = {{Vec3(0.22f, 0, 0.45f), Vec2(0.06f, 0.07f), {chest, neck, 0.5f}},
                                 {Vec3(0.33f, 0, 0.54f), Vec2(0.05f, 0.055f), {neck, head, 0.5f}}};
  b.addTube(neck_rings, 6, fur, false, false);
  const TubeRing skull[] = {{Vec3(0.29f, 0, 0.57f), Vec2(0.06f, 0.06f), {head, head, 0.0f}},
                            {Vec3(0.36f, 0, 0.58f), Vec2(0.068f, 0.065f), {head, head, 0.0f}},
                            {Vec3(0.42f, 0, 0.565f), Vec2(0.05f, 0.048f), {head, head, 0.0f}}};
  b.addTube(skull, 6, fur);
  const TubeRing snout[] = {{Vec3(0.41f, 0, 0.555f), Vec2(0.04f, 0.035f), {head, head, 0.0f}},
                            {Vec3(0.50f, 0, 0.54f), Vec2(0.02f, 0.018f), {head, head, 0.0f}}};
  b.addTube(snout, 6, pale);
  b.addBox(Vec3(0.505f, 0, 0.543f), Vec3(0.012f, 0.015f, 0.012f), {head, head, 0.0f}, dark);
  for (float s : {1.0f, -1.0f}) {
    const TubeRing ear[] = {{Vec3(0.345f, 0.04f * s, 0.62f), Vec2(0.025f, 0.014f), {head, head, 0.0f}},
                            {Vec3(0.35f, 0.05f * s, 0.70f), Vec2(0.003f, 0.002f), {head, head, 0.0f}}};
    b.addTube(ear, 4, dark, true, false);
  }
  for (const Leg& l : legs) {
    const Vec3 top = b.jointPosition(l.upper), knee = b.jointPosition(l.lower), paw = b.jointPosition(l.paw);
    const bool front = top.x > 0.0f;
    const uint16_t body_joint = front ? chest : pelvis;
    const Vec2 thick = front ? Vec2(0.04f, 0.05f) : Vec2(0.045f, 0.065f);
    const TubeRing rings[] = {{top + Vec3(0, 0, 0.03f), thick, {l.upper, body_joint, 0.25f}},
                              {0.5f * (top + knee), Vec2(0.032f, 0.04f), {l.upper, l.upper, 0.0f}},
                              {knee, Vec2(0.027f, 0.03f), {l.upper, l.lower, 0.5f}},
                              {paw + Vec3(0, 0, 0.02f), Vec2(0.022f, 0.024f), {l.lower, l.paw, 0.3f}}};
    b.addTube(rings, 6, fur);
    b.addBox(paw + Vec3(0.015f, 0, -0.015f), Vec3(0.035f, 0.026f, 0.025f), {l.paw, l.paw, 0.0f}, dark);
  }
  const TubeRing tail_rings[] = {{Vec3(-0.30f, 0, 0.44f), Vec2(0.03f, 0.035f), {tail, tail, 0.0f}},
                                 {Vec3(-0.40f, 0, 0.47f), Vec2(0.04f, 0.045f), {tail, tail_tip, 0.3f}},
                                 {Vec3(-0.48f, 0, 0.48f), Vec2(0.038f, 0.042f), {tail, tail_tip, 0.7f}},
                                 {Vec3(-0.55f, 0, 0.475f), Vec2(0.03f, 0.033f), {tail_tip, tail_tip, 0.0f}}};
  b.addTube(tail_rings, 6, fur, true, false);
  const TubeRing tip[] = {{Vec3(-0.55f, 0, 0.475f), Vec2(0.03f, 0.033f), {tail_tip, tail_tip, 0.0f}},
                          {Vec3(-0.62f, 0, 0.46f), Vec2(0.004f, 0.004f), {tail_tip, tail_tip, 0.0f}}};
  b.addTube(tip, 6, pale, false, true);

  // The walk: phase 0..1 over the cycle; leg i is a quarter cycle behind leg i - 1.
  auto pose = [&](float phase, std::vector<scene::NodePose>& poses) {
    const float a = float(2.0 * kPi) * phase;
    for (const Leg& l : legs) {
      const float al = a - float(2.0 * kPi) * l.phase;
      // About +y: negative swings the leg forward (while cos al > 0); the lower joint bends in the swing.
      const float swing = -deg(25) * std::sin(al);
      const float c = std::max(0.0f, std::cos(al + 0.3f));
      const float bend = deg(6) + deg(40) * c * c;
      poses[l.upper].rotation = turn(swing, kY);
      poses[l.lower].rotation = turn(bend, kY);
      poses[l.paw].rotation = turn(-0.8f * (swing + bend), kY);
    }
    poses[chest].rotation = turn(deg(3) * std::sin(a), kZ);
    poses[head].rotation = turn(deg(3) * std::sin(2.0f * a), kY);
    poses[tail].rotation = turn(deg(12) * std::sin(a), kZ) * turn(deg(10), kY);
    poses[tail_tip].rotation = turn(deg(10) * std::sin(a - 0.8f), kZ);
  };
  std::vector<scene::Animation> animations;
  animations.push_back(b.loopingAnimation("walk", kQuadrupedCycleSeconds, 33, pose, true));
  return b.build(std::move(animations));
}

}  // namespace farfield::gen
