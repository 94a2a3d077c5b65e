#include "farfield/scene/skin_regions.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "farfield/core/error.h"
#include "farfield/scene/gltf_skin.h"
#include "support/expect_error.h"
#include "support/test_support.h"

namespace farfield::scene {
namespace {

// n triangles, triangle t bound wholly to joint joint_of[t] of a flat skeleton of `joints` joints.
SkinnedModel strip(const std::vector<uint16_t>& joint_of, size_t joints) {
  SkinnedModel m;
  m.name = "strip";
  for (size_t t = 0; t < joint_of.size(); ++t) {
    for (int c = 0; c < 3; ++c) {
      m.mesh.indices.push_back(uint32_t(m.mesh.positions.size()));
      m.mesh.positions.emplace_back(float(t) + float(c == 1), float(c == 2), 0.0f);
      m.joints.push_back({joint_of[t], 0, 0, 0});
      m.weights.emplace_back(1.0f, 0.0f, 0.0f, 0.0f);
    }
  }
  m.skeleton.nodes.resize(joints);
  for (size_t j = 0; j < joints; ++j) {
    m.skeleton.joints.push_back(uint32_t(j));
    m.skeleton.inverse_bind.emplace_back(1.0f);
  }
  return m;
}

TEST(SkinRegions, OneMaterialIsSplitByDominantJointOverTheSixteenRegions) {
  // Joints 0..39, of which 2, 5 and 39 dominate triangles: ranks 0, 1, 2 of 3 -> regions 0, 5, 10.
  const SkinnedModel m = strip({5, 2, 39, 5, 2}, 40);
  EXPECT_EQ(colorRegions(m, {}), (std::vector<uint8_t>{5, 0, 10, 5, 0}));
  // 32 used joints: two per region, in joint order.
  std::vector<uint16_t> all;
  for (uint16_t j = 0; j < 32; ++j) all.push_back(j);
  const std::vector<uint8_t> r = colorRegions(strip(all, 32), {});
  for (size_t t = 0; t < 32; ++t) EXPECT_EQ(r[t], t / 2);
  // A triangle shared by two joints goes to the one of larger summed weight.
  SkinnedModel mixed = strip({0, 0}, 2);
  for (size_t v = 0; v < 3; ++v) {
    mixed.joints[v] = {0, 1, 0, 0};
    mixed.weights[v] = Vec4(0.2f, 0.8f, 0, 0);
  }
  EXPECT_EQ(colorRegions(mixed, {}), (std::vector<uint8_t>{8, 0}));  // joint 1 (rank 1 of 2), joint 0
}

TEST(SkinRegions, SeveralPrimitivesGiveTheirOwnRegions) {
  const SkinnedModel m = strip({0, 0, 0, 0}, 1);
  const std::vector<uint32_t> primitives{0, 1, 17, 1};
  EXPECT_EQ(colorRegions(m, primitives), (std::vector<uint8_t>{0, 1, 1, 1}));
  const std::vector<uint32_t> short_list{0, 1};
  EXPECT_THROW(colorRegions(m, short_list), Error);
}

TEST(SkinRegions, ValidationRejectsRegionsOutOfRangeOrMiscounted) {
  SkinnedModel m = strip({0, 0}, 1);
  m.regions = {0, 15};
  EXPECT_NO_THROW(validateSkinnedModel(m));
  m.regions = {0, 16};
  farfield::test::expectErrorMentions([&] { validateSkinnedModel(m); }, {"strip", "colour region 16"});
  m.regions = {0};
  farfield::test::expectErrorMentions([&] { validateSkinnedModel(m); }, {"strip", "1 colour regions for 2"});
}

TEST(SkinRegions, RealModelsGetSeveralRegionsDeterministically) {
  FF_SHARED_FILE_OR_SKIP(man_glb, "models/CesiumMan.glb");
  FF_SHARED_FILE_OR_SKIP(fox_glb, "models/Fox.glb");
  for (const std::filesystem::path& glb : {man_glb, fox_glb}) {
    const std::string file = glb.filename().string();
    const SkinnedModel a = importSkinnedModel(glb.string()), b = importSkinnedModel(glb.string());
    ASSERT_EQ(a.regions.size(), a.mesh.triangleCount()) << file;
    EXPECT_EQ(a.regions, b.regions) << file;
    std::vector<bool> seen(kColorRegions, false);
    for (uint8_t r : a.regions) seen[r] = true;
    EXPECT_GE(std::count(seen.begin(), seen.end(), true), 8) << file;
  }
}

}  // namespace
}  // namespace farfield::scene
