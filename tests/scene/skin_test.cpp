#include "farfield/scene/skin.h"

#include <gtest/gtest.h>

#include <cmath>

#include "farfield/core/error.h"

namespace farfield::scene {
namespace {

// Two joints in a chain: joint 0 at the origin, joint 1 one metre up x; vertices bound to one or both.
SkinnedModel chain() {
  SkinnedModel m;
  m.name = "chain";
  m.mesh.positions = {{0, 0, 0}, {2, 0, 0}, {1, 1, 0}};
  m.mesh.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  m.mesh.indices = {0, 1, 2};
  m.joints = {{0, 0, 0, 0}, {1, 0, 0, 0}, {0, 1, 0, 0}};
  m.weights = {{1, 0, 0, 0}, {1, 0, 0, 0}, {0.5f, 0.5f, 0, 0}};
  m.skeleton.nodes.resize(2);
  m.skeleton.nodes[1].parent = 0;
  m.skeleton.nodes[1].rest.translation = Vec3(1, 0, 0);
  m.skeleton.joints = {0, 1};
  // Bind pose = rest pose: the inverse bind matrices undo each joint's world transform.
  m.skeleton.inverse_bind = {Mat4(1.0f), glm::translate(Mat4(1.0f), Vec3(-1, 0, 0))};
  return m;
}

TEST(Skin, RestPoseGivesTheBindMesh) {
  const SkinnedModel m = chain();
  const Mesh posed = skinMesh(m, jointMatrices(m, nullptr, 0.0f));
  for (size_t v = 0; v < 3; ++v) EXPECT_NEAR(glm::length(posed.positions[v] - m.mesh.positions[v]), 0.0f, 1e-6f);
}

TEST(Skin, BentElbowAgainstHandComputation) {
  SkinnedModel m = chain();
  // Joint 1 turns 90 degrees about z: vertex 1 (x = 2, one metre beyond joint 1) goes to (1, 1, 0); vertex 2 half
  // follows: the mean of its rest position and of its position under joint 1 alone.
  Animation a;
  AnimationChannel c;
  c.node = 1;
  c.path = AnimationPath::Rotation;
  c.times = {0.0f};
  const Quat q = glm::angleAxis(float(kPi / 2), Vec3(0, 0, 1));
  c.values = {Vec4(q.x, q.y, q.z, q.w)};
  a.channels.push_back(c);
  const Mesh posed = skinMesh(m, jointMatrices(m, &a, 0.0f));
  EXPECT_NEAR(glm::length(posed.positions[1] - Vec3(1, 1, 0)), 0.0f, 1e-5f);
  // Vertex 2 (1, 1, 0) under joint 1 alone: relative (0, 1) turned to (-1, 0), plus (1, 0) -> (0, 0, 0).
  EXPECT_NEAR(glm::length(posed.positions[2] - 0.5f * (Vec3(1, 1, 0) + Vec3(0, 0, 0))), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::length(posed.normals[1] - Vec3(0, 0, 1)), 0.0f, 1e-5f);
}

TEST(Skin, ValidateNamesTheDefect) {
  SkinnedModel m = chain();
  m.joints[2][1] = 5;
  try {
    validateSkinnedModel(m);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("vertex 2: joint index 5"), std::string::npos) << e.what();
  }
  m = chain();
  m.weights[0].x = -1.0f;
  EXPECT_THROW(validateSkinnedModel(m), Error);
  m = chain();
  m.skeleton.inverse_bind.pop_back();
  EXPECT_THROW(validateSkinnedModel(m), Error);
}

}  // namespace
}  // namespace farfield::scene
