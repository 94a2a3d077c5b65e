// The crowd's models (eval/crowd_walk.h): without files the built-in figures with their own heights, facings and
// shares, the heights those the figures are made at (so that a walk cycle covers their stride at the nominal speed);
// with files, the files (bad ones are errors naming them).
#include "farfield/eval/crowd_walk.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "farfield/core/error.h"

namespace farfield::eval {
namespace {

constexpr float kNominalSpeed = 1.3f;  // m/s at which crowdAgentStates plays a walk cycle at its own rate

// How far joint `name`'s origin moves along x over the walk (figure space, where the figure does not advance).
float sweepAlongX(const scene::SkinnedModel& m, const std::string& name) {
  size_t j = 0;
  while (j < m.skeleton.joints.size() && m.skeleton.nodes[m.skeleton.joints[j]].name != name) ++j;
  EXPECT_LT(j, m.skeleton.joints.size()) << name;
  if (j == m.skeleton.joints.size()) return 0.0f;
  const scene::Animation& walk = m.animations.at(0);
  const Vec3 bind = Vec3(glm::inverse(m.skeleton.inverse_bind[j])[3]);
  float lo = 1e9f, hi = -1e9f;
  for (int i = 0; i < 128; ++i) {
    const std::vector<Mat4> joints = scene::jointMatrices(m, &walk, walk.start + walk.duration * float(i) / 128.0f);
    const float x = Vec3(joints[j] * Vec4(bind, 1.0f)).x;
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  return hi - lo;
}

TEST(CrowdWalk, WithoutFilesTheCrowdIsTheBuiltInFigures) {
  const CrowdModels c = crowdModels({}, kCrowdModelHeights, kCrowdModelFacingDeg, kCrowdModelShares);
  ASSERT_EQ(c.models.size(), 2u);
  EXPECT_EQ(c.names, (std::vector<std::string>{"builtin:walker", "builtin:quadruped"}));
  EXPECT_EQ(c.shares, kBuiltinCrowdModelShares);
  ASSERT_EQ(c.options.size(), 2u);
  for (size_t m = 0; m < 2; ++m) {
    EXPECT_EQ(c.options[m].height_m, kBuiltinCrowdModelHeights[m]);
    EXPECT_EQ(c.options[m].facing_deg, kBuiltinCrowdModelFacingDeg[m]);
    EXPECT_EQ(c.models[m].findAnimation(c.options[m].animation), 0);
    // The figure is made at its crowd height: the runtime scales it by at most 2 %.
    const Box3 box = scene::animatedBounds(c.models[m], &c.models[m].animations[0], 32);
    EXPECT_NEAR(box.hi.z - box.lo.z, kBuiltinCrowdModelHeights[m], 0.02f * kBuiltinCrowdModelHeights[m]);
  }
  // A cycle at the nominal speed covers the figure's stride: each foot sweeps back over half the cycle, so the
  // cycle covers twice a foot's sweep (within 10 %: the feet do not move at a constant speed).
  const float walker_stride = 2.0f * sweepAlongX(c.models[0], "foot.L");
  const float animal_stride = 2.0f * sweepAlongX(c.models[1], "paw_hind.L");
  EXPECT_NEAR(walker_stride, kNominalSpeed * c.models[0].animations[0].duration, 0.1f * walker_stride);
  EXPECT_NEAR(animal_stride, kNominalSpeed * c.models[1].animations[0].duration, 0.1f * animal_stride);
  // The same as builtinCrowdModels.
  EXPECT_EQ(builtinCrowdModels().models[1].mesh.positions, c.models[1].mesh.positions);
}

TEST(CrowdWalk, FilesAreLoadedAndBadOnesNamed) {
  const std::vector<std::string> missing{"no-such-figure.glb"};
  try {
    crowdModels(missing, kCrowdModelHeights, kCrowdModelFacingDeg, kCrowdModelShares);
    ADD_FAILURE() << "a missing file must be an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no-such-figure.glb"), std::string::npos) << e.what();
  }
  const std::vector<std::string> three{"a.glb", "b.glb", "c.glb"};
  EXPECT_THROW(loadCrowdModels(three, kCrowdModelHeights, kCrowdModelFacingDeg, kCrowdModelShares), Error);
  EXPECT_THROW(loadCrowdModels({}, kCrowdModelHeights, kCrowdModelFacingDeg, kCrowdModelShares), Error);
}

}  // namespace
}  // namespace farfield::eval
