// The crowd's built-in figures (walker_figure.h, quadruped_figure.h): valid skins, skinning equal to a CPU reference
// computed here from the animation's keys, walk cycles that loop without a jump, and the gaits they promise.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "farfield/gen/quadruped_figure.h"
#include "farfield/gen/walker_figure.h"

namespace farfield::gen {
namespace {

struct FigureCase {
  const char* name;
  std::function<scene::SkinnedModel()> make;
  size_t joints;
  float height_lo, height_hi;  // the animated figure's height, metres
  float step_bound;           // the most a vertex may move between 1/256 of a cycle and the next, metres
  std::set<uint8_t> regions;
};

std::string caseName(const ::testing::TestParamInfo<FigureCase>& info) { return info.param.name; }
void PrintTo(const FigureCase& c, std::ostream* os) { *os << c.name; }

const scene::SkinnedModel& walker() {
  static const scene::SkinnedModel m = makeWalkerFigure();
  return m;
}
const scene::SkinnedModel& quadruped() {
  static const scene::SkinnedModel m = makeQuadrupedFigure();
  return m;
}

uint16_t jointNamed(const scene::SkinnedModel& m, const std::string& name) {
  for (size_t j = 0; j < m.skeleton.joints.size(); ++j)
    if (m.skeleton.nodes[m.skeleton.joints[j]].name == name) return uint16_t(j);
  ADD_FAILURE() << m.name << ": no joint " << name;
  return 0;
}

// The reference: each channel interpolated between its keys here (translations linearly, rotations by glm::slerp
// along the shorter arc), the nodes' world matrices composed parent first, times the inverse bind matrices.
std::vector<Mat4> referenceJointMatrices(const scene::SkinnedModel& m, float t) {
  const scene::Animation& anim = m.animations.at(0);
  const float local = std::fmod(t - anim.start, anim.duration) + anim.start;
  std::vector<Vec3> translation(m.skeleton.nodes.size());
  std::vector<scene::Quat> rotation(m.skeleton.nodes.size());
  for (size_t i = 0; i < m.skeleton.nodes.size(); ++i) {
    translation[i] = m.skeleton.nodes[i].rest.translation;
    rotation[i] = m.skeleton.nodes[i].rest.rotation;
  }
  for (const scene::AnimationChannel& c : anim.channels) {
    size_t k = 0;
    while (k + 2 < c.times.size() && c.times[k + 1] <= local) ++k;
    const float s = std::clamp((local - c.times[k]) / (c.times[k + 1] - c.times[k]), 0.0f, 1.0f);
    const Vec4 a = c.values[k], b = c.values[k + 1];
    if (c.path == scene::AnimationPath::Translation) {
      translation[c.node] = Vec3(a) + s * (Vec3(b) - Vec3(a));
    } else if (c.path == scene::AnimationPath::Rotation) {
      const scene::Quat qa(a.w, a.x, a.y, a.z);
      scene::Quat qb(b.w, b.x, b.y, b.z);
      if (glm::dot(qa, qb) < 0.0f) qb = -qb;
      rotation[c.node] = glm::normalize(glm::slerp(qa, qb, s));
    }
  }
  std::vector<Mat4> world(m.skeleton.nodes.size());
  for (size_t i = 0; i < world.size(); ++i) {
    const Mat4 local_m = glm::translate(Mat4(1.0f), translation[i]) * glm::mat4_cast(rotation[i]);
    const int32_t p = m.skeleton.nodes[i].parent;
    world[i] = p < 0 ? local_m : world[size_t(p)] * local_m;
  }
  std::vector<Mat4> out;
  for (size_t j = 0; j < m.skeleton.joints.size(); ++j)
    out.push_back(m.skeleton.root * world[m.skeleton.joints[j]] * m.skeleton.inverse_bind[j]);
  return out;
}

std::vector<Vec3> posed(const scene::SkinnedModel& m, float t) {
  return scene::skinMesh(m, scene::jointMatrices(m, &m.animations.at(0), t)).positions;
}

float maxDistance(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  float d = 0.0f;
  for (size_t i = 0; i < a.size(); ++i) d = std::max(d, glm::length(a[i] - b[i]));
  return d;
}

class CrowdFigure : public ::testing::TestWithParam<FigureCase> {};

TEST_P(CrowdFigure, SkeletonWeightsAndRegionsAreValid) {
  const FigureCase& c = GetParam();
  const scene::SkinnedModel m = c.make();
  EXPECT_NO_THROW(scene::validateSkinnedModel(m));
  const size_t n = m.mesh.positions.size();
  ASSERT_EQ(m.joints.size(), n);
  ASSERT_EQ(m.weights.size(), n);
  EXPECT_EQ(m.skeleton.joints.size(), c.joints);
  EXPECT_EQ(m.skeleton.inverse_bind.size(), c.joints);
  for (size_t i = 0; i < m.skeleton.nodes.size(); ++i) EXPECT_LT(m.skeleton.nodes[i].parent, int32_t(i));
  EXPECT_GE(m.mesh.triangleCount(), 100u);
  EXPECT_LE(m.mesh.triangleCount(), 600u);
  std::set<uint32_t> used_joints;
  for (size_t v = 0; v < n; ++v) {
    const float sum = m.weights[v].x + m.weights[v].y + m.weights[v].z + m.weights[v].w;
    EXPECT_NEAR(sum, 1.0f, 1e-6f) << "vertex " << v;
    for (int k = 0; k < 4; ++k) {
      EXPECT_LT(m.joints[v][size_t(k)], c.joints) << "vertex " << v;
      EXPECT_GE(m.weights[v][k], 0.0f);
      if (m.weights[v][k] > 0.0f) used_joints.insert(m.joints[v][size_t(k)]);
    }
  }
  // Every joint but the roots of chains moves some vertex (the feet, hands and paws carry their boxes).
  EXPECT_GE(used_joints.size(), c.joints - 1);
  ASSERT_EQ(m.regions.size(), m.mesh.triangleCount());
  EXPECT_EQ(std::set<uint8_t>(m.regions.begin(), m.regions.end()), c.regions);
  // The materials' colours: every vertex's uv lands on a texel of one colour, the same for the triangles of a region.
  ASSERT_TRUE(m.texture);
  ASSERT_EQ(m.mesh.uvs.size(), n);
  std::vector<std::set<uint32_t>> colours(scene::kColorRegions);
  for (size_t t = 0; t < m.mesh.triangleCount(); ++t) {
    const Vec2 uv = m.mesh.uvs[m.mesh.indices[3 * t]];
    const image::Rgba8 p = m.texture->at(int(uv.x * float(m.texture->width())), int(uv.y * float(m.texture->height())));
    colours[m.regions[t]].insert(uint32_t(p.r) << 16 | uint32_t(p.g) << 8 | p.b);
    EXPECT_EQ(p.a, 255);
  }
  for (uint8_t r : c.regions) EXPECT_EQ(colours[r].size(), 1u) << "region " << int(r);
  EXPECT_EQ(m.findAnimation("walk"), 0);
}

TEST_P(CrowdFigure, TheBindPoseReproducesTheMesh) {
  const scene::SkinnedModel m = GetParam().make();
  const std::vector<Mat4> joints = scene::jointMatrices(m, nullptr, 0.0f);
  for (const Mat4& j : joints)
    for (int col = 0; col < 4; ++col)
      for (int row = 0; row < 4; ++row) EXPECT_NEAR(j[col][row], col == row ? 1.0f : 0.0f, 1e-6f);
  const scene::Mesh bind = scene::skinMesh(m, joints);
  ASSERT_EQ(bind.positions.size(), m.mesh.positions.size());
  EXPECT_LT(maxDistance(bind.positions, m.mesh.positions), 1e-5f);
  // Outward faces: the closed parts enclose a positive volume (the open neck adds little either way).
  double volume = 0.0;
  for (size_t t = 0; t < m.mesh.triangleCount(); ++t) {
    const Vec3 a = m.mesh.positions[m.mesh.indices[3 * t]], b = m.mesh.positions[m.mesh.indices[3 * t + 1]],
               c = m.mesh.positions[m.mesh.indices[3 * t + 2]];
    volume += double(glm::dot(a, glm::cross(b, c))) / 6.0;
  }
  EXPECT_GT(volume, 0.0);
}

TEST_P(CrowdFigure, SkinningEqualsAReferenceFromTheKeysJointsAndWeights) {
  const scene::SkinnedModel m = GetParam().make();
  const scene::Animation& anim = m.animations.at(0);
  size_t moved = 0;
  for (float f : {0.0f, 0.13f, 0.37f, 0.5f, 0.71f, 0.96f}) {
    const float t = anim.start + f * anim.duration;
    const std::vector<Mat4> reference = referenceJointMatrices(m, t);
    const std::vector<Mat4> library = scene::jointMatrices(m, &anim, t);
    ASSERT_EQ(reference.size(), library.size());
    for (size_t j = 0; j < reference.size(); ++j)
      for (int col = 0; col < 4; ++col)
        for (int row = 0; row < 4; ++row)
          EXPECT_NEAR(library[j][col][row], reference[j][col][row], 1e-4f) << "joint " << j << " at " << f;
    const scene::Mesh skinned = scene::skinMesh(m, library);
    // A few vertices by hand: each of its four joints' matrix applied to the bind position, weighted.
    for (size_t v = 0; v < m.mesh.positions.size(); v += 37) {
      Vec3 p(0.0f), nrm(0.0f);
      for (int k = 0; k < 4; ++k) {
        const Mat4& jm = reference[m.joints[v][size_t(k)]];
        p += m.weights[v][k] * Vec3(jm * Vec4(m.mesh.positions[v], 1.0f));
        nrm += m.weights[v][k] * (Mat3(jm) * m.mesh.normals[v]);
      }
      EXPECT_LT(glm::length(skinned.positions[v] - p), 1e-4f) << "vertex " << v << " at " << f;
      EXPECT_GT(glm::dot(skinned.normals[v], glm::normalize(nrm)), 0.9999f) << "vertex " << v << " at " << f;
      if (glm::length(p - m.mesh.positions[v]) > 0.01f) ++moved;
    }
  }
  EXPECT_GT(moved, 10u) << "the walk must move the vertices for the comparison to mean anything";
}

TEST_P(CrowdFigure, TheWalkCycleLoopsWithoutAJump) {
  const FigureCase& c = GetParam();
  const scene::SkinnedModel m = c.make();
  const scene::Animation& anim = m.animations.at(0);
  ASSERT_GT(anim.duration, 0.0f);
  // The keys: the last equals the first for every channel.
  for (const scene::AnimationChannel& ch : anim.channels) {
    ASSERT_GE(ch.times.size(), 2u);
    EXPECT_FLOAT_EQ(ch.times.front(), anim.start);
    EXPECT_FLOAT_EQ(ch.times.back(), anim.start + anim.duration);
    EXPECT_LT(glm::length(ch.values.back() - ch.values.front()), 1e-6f) << "node " << ch.node;
  }
  // Just before the end of the cycle (no wrap yet) the figure stands as at its start.
  const std::vector<Vec3> start = posed(m, anim.start);
  EXPECT_LT(maxDistance(posed(m, anim.start + anim.duration * (1.0f - 1e-4f)), start), 2e-3f);
  // 256 poses over the cycle, the last step through the wrap: no vertex jumps.
  const int steps = 256;
  std::vector<Vec3> previous = start;
  float largest = 0.0f;
  float lowest_max = 0.0f;  // the highest the lowest vertex gets (feet on the ground)
  for (int i = 1; i <= steps; ++i) {
    const std::vector<Vec3> now = posed(m, anim.start + anim.duration * float(i) / float(steps));
    largest = std::max(largest, maxDistance(now, previous));
    float lowest = 1e9f;
    for (const Vec3& p : now) lowest = std::min(lowest, p.z);
    lowest_max = std::max(lowest_max, std::abs(lowest));
    previous = now;
  }
  EXPECT_LT(largest, c.step_bound);
  EXPECT_GT(largest, 0.1f * c.step_bound) << "the figure must move";
  EXPECT_LT(maxDistance(previous, start), 1e-5f) << "the wrapped end is the start";
  EXPECT_LT(lowest_max, 0.01f) << "the lowest foot stays on the ground";
  const Box3 box = scene::animatedBounds(m, &anim, 32);
  EXPECT_GT(box.hi.z - box.lo.z, c.height_lo);
  EXPECT_LT(box.hi.z - box.lo.z, c.height_hi);
}

INSTANTIATE_TEST_SUITE_P(
    Builtin, CrowdFigure,
    ::testing::Values(FigureCase{"walker", makeWalkerFigure, 16, 1.70f, 1.85f, 0.03f,
                                 {kWalkerSkin, kWalkerHair, kWalkerTop, kWalkerTrousers, kWalkerShoes}},
                      FigureCase{"quadruped", makeQuadrupedFigure, 18, 0.6f, 0.8f, 0.012f,
                                 {kQuadrupedFur, kQuadrupedPale, kQuadrupedDark}}),
    caseName);

// Where joint j's origin is at phase f of the walk (figure space).
Vec3 jointAt(const scene::SkinnedModel& m, uint16_t j, float f) {
  const scene::Animation& anim = m.animations.at(0);
  const std::vector<Mat4> joints = scene::jointMatrices(m, &anim, anim.start + f * anim.duration);
  const Vec3 bind = Vec3(glm::inverse(m.skeleton.inverse_bind[j])[3]);
  return Vec3(joints[j] * Vec4(bind, 1.0f));
}

TEST(WalkerFigure, LegsAndArmsSwingInOppositePhaseAndTheHipsBob) {
  const scene::SkinnedModel& m = walker();
  const uint16_t foot_l = jointNamed(m, "foot.L"), foot_r = jointNamed(m, "foot.R");
  const uint16_t hand_l = jointNamed(m, "hand.L"), hand_r = jointNamed(m, "hand.R");
  const uint16_t hips = jointNamed(m, "hips"), knee_l = jointNamed(m, "shin.L");
  for (const char* name : {"spine", "head", "upper_arm.L", "forearm.R", "thigh.R", "shin.R"}) jointNamed(m, name);
  // A quarter of the cycle in, the left foot is ahead of the right and the left hand behind the right hand; three
  // quarters in, the other way round.
  const float feet_q1 = jointAt(m, foot_l, 0.25f).x - jointAt(m, foot_r, 0.25f).x;
  const float feet_q3 = jointAt(m, foot_l, 0.75f).x - jointAt(m, foot_r, 0.75f).x;
  const float hands_q1 = jointAt(m, hand_l, 0.25f).x - jointAt(m, hand_r, 0.25f).x;
  const float hands_q3 = jointAt(m, hand_l, 0.75f).x - jointAt(m, hand_r, 0.75f).x;
  EXPECT_GT(feet_q1, 0.4f);
  EXPECT_LT(feet_q3, -0.4f);
  EXPECT_LT(hands_q1, -0.15f);
  EXPECT_GT(hands_q3, 0.15f);
  // Over the cycle: the hips rise and fall by a few centimetres; the left knee bends (its forward offset from the
  // line hip-ankle changes sign never: it bends forward only).
  float lo = 1e9f, hi = -1e9f;
  for (int i = 0; i < 64; ++i) {
    const float z = jointAt(m, hips, float(i) / 64.0f).z;
    lo = std::min(lo, z);
    hi = std::max(hi, z);
    const Vec3 hip = jointAt(m, jointNamed(m, "thigh.L"), float(i) / 64.0f);
    const Vec3 ankle = jointAt(m, foot_l, float(i) / 64.0f), knee = jointAt(m, knee_l, float(i) / 64.0f);
    const Vec3 along = glm::normalize(ankle - hip);
    const Vec3 off = (knee - hip) - glm::dot(knee - hip, along) * along;
    EXPECT_GE(off.x, -1e-3f) << "the knee bends backwards at phase " << i << "/64";
  }
  EXPECT_GT(hi - lo, 0.01f);
  EXPECT_LT(hi - lo, 0.08f);
}

TEST(QuadrupedFigure, LegsFollowEachOtherAQuarterCycleApart) {
  const scene::SkinnedModel& m = quadruped();
  for (const char* name : {"pelvis", "chest", "neck", "head", "tail", "tail_tip"}) jointNamed(m, name);
  // Each paw is furthest forward of its shoulder or hip at the phase its leg's offset gives, a quarter after it.
  const char* legs[4] = {"hind.L", "front.L", "hind.R", "front.R"};
  for (int i = 0; i < 4; ++i) {
    const uint16_t paw = jointNamed(m, std::string("paw_") + legs[i]);
    const uint16_t top = jointNamed(m, std::string("upper_") + legs[i]);
    int best = 0;
    float best_x = -1e9f;
    float spread_lo = 1e9f;
    for (int s = 0; s < 64; ++s) {
      const float f = float(s) / 64.0f;
      const float x = jointAt(m, paw, f).x - jointAt(m, top, f).x;
      if (x > best_x) {
        best_x = x;
        best = s;
      }
      spread_lo = std::min(spread_lo, x);
    }
    const int expected = (16 * i + 16) % 64;
    const int off = std::min((best - expected + 64) % 64, (expected - best + 64) % 64);
    EXPECT_LE(off, 4) << legs[i] << ": furthest forward at " << best << "/64";
    EXPECT_GT(best_x - spread_lo, 0.2f) << legs[i] << " swings";
  }
  // The tail wags: its tip moves sideways over the cycle, to one side and back.
  const uint16_t tip = jointNamed(m, "tail_tip");
  EXPECT_GT(std::abs(jointAt(m, tip, 0.25f).y - jointAt(m, tip, 0.75f).y), 0.03f);
}

TEST(CrowdFigures, TheSameEveryCall) {
  const scene::SkinnedModel a = makeWalkerFigure(), b = makeWalkerFigure();
  EXPECT_EQ(a.mesh.positions, b.mesh.positions);
  EXPECT_EQ(a.mesh.indices, b.mesh.indices);
  EXPECT_EQ(a.name, "builtin:walker");
  EXPECT_EQ(quadruped().name, "builtin:quadruped");
}

}  // namespace
}  // namespace farfield::gen
