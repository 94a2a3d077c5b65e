#include "farfield/gen/crowd.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "farfield/core/error.h"
#include "farfield/gen/street_network.h"

namespace farfield::gen {
namespace {

float segmentDistance(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 ab = b - a;
  const float t = std::clamp(glm::dot(p - a, ab) / std::max(glm::dot(ab, ab), 1e-12f), 0.0f, 1.0f);
  return glm::length(p - (a + ab * t));
}

urban::StreetGraph streets() {
  StreetNetworkOptions o;
  o.blocks = 30;
  o.seed = 4;
  return generateStreetNetwork(o);
}

TEST(Crowd, DeterministicForASeed) {
  const urban::StreetGraph g = streets();
  CrowdOptions o;
  o.agents = 300;
  o.seed = 9;
  const Crowd a = generateCrowd(g, o), b = generateCrowd(g, o);
  o.seed = 10;
  const Crowd c = generateCrowd(g, o);
  ASSERT_EQ(a.agents.size(), 300u);
  size_t differ = 0;
  for (size_t i = 0; i < a.agents.size(); ++i) {
    for (float t : {0.0f, 7.5f}) {
      const AgentPose pa = agentPose(a, i, t), pb = agentPose(b, i, t), pc = agentPose(c, i, t);
      EXPECT_EQ(pa.position, pb.position);
      EXPECT_EQ(pa.heading, pb.heading);
      differ += glm::length(pa.position - pc.position) > 0.01f ? 1 : 0;
    }
    EXPECT_EQ(a.agents[i].model, b.agents[i].model);
    EXPECT_EQ(a.agents[i].tint, b.agents[i].tint);
    EXPECT_EQ(a.agents[i].phase, b.agents[i].phase);
    EXPECT_EQ(a.agents[i].outfit, b.agents[i].outfit);
    EXPECT_LT(a.agents[i].outfit, o.outfits);
  }
  EXPECT_EQ(a.region_tints, b.region_tints);
  EXPECT_EQ(a.region_tints, crowdRegionTints(9, o.outfits));
  EXPECT_GT(differ, 550u);  // another seed, another crowd
  // Both models appear, roughly in their shares (0.7 / 0.3).
  size_t model1 = 0;
  for (const CrowdAgent& ag : a.agents) model1 += ag.model == 1 ? 1 : 0;
  EXPECT_GT(model1, 50u);
  EXPECT_LT(model1, 130u);
}

// Every agent, at every sampled time, stands in a street (within half its width of its centreline), outside every
// block's kerb line, and within the sidewalk strip (its offset from its own block's kerb line; bevelled corners cut
// in to a fifth of it at sharp block corners).
TEST(Crowd, AgentsStayOnSidewalks) {
  const urban::StreetGraph g = streets();
  CrowdOptions o;
  o.agents = 200;
  o.seed = 3;
  const Crowd crowd = generateCrowd(g, o);
  std::vector<Polygon2> kerbs;
  for (const BlockFootprint& b : buildableBlocks(g)) kerbs.push_back(b.footprint);
  for (size_t i = 0; i < crowd.agents.size(); ++i)
    for (float t = 0.0f; t < 120.0f; t += 9.7f) {
      const AgentPose p = agentPose(crowd, i, t);
      const Vec2 q(p.position);
      float street = 1e30f;
      for (size_t s = 0; s < g.streetCount(); ++s) {
        const urban::Street& st = g.streets()[s];
        street = std::min(street, segmentDistance(q, g.position(st.a), g.position(st.b)) - 0.5f * st.width);
      }
      EXPECT_LE(street, 0.01f) << "agent " << i << " at t = " << t << " is off the streets";
      for (const Polygon2& k : kerbs) ASSERT_FALSE(pointInPolygon(q, k)) << "agent " << i << " inside a block";
      const Polygon2& kerb = crowd.routes[crowd.agents[i].route].kerb;
      float to_kerb = 1e30f;
      for (size_t v = 0; v < kerb.size(); ++v)
        to_kerb = std::min(to_kerb, segmentDistance(q, kerb[v], kerb[(v + 1) % kerb.size()]));
      EXPECT_LE(to_kerb, o.sidewalk_offset + 0.01f) << "agent " << i;
      EXPECT_GE(to_kerb, 0.2f * o.sidewalk_offset) << "agent " << i;
    }
}

TEST(Crowd, BadOptionsAreErrors) {
  const urban::StreetGraph g = streets();
  CrowdOptions o;
  o.model_shares.clear();
  EXPECT_THROW(generateCrowd(g, o), Error);
  o = CrowdOptions{};
  o.min_speed = 0.0f;
  EXPECT_THROW(generateCrowd(g, o), Error);
}

}  // namespace
}  // namespace farfield::gen

namespace farfield::gen {
namespace {

TEST(CrowdOutfits, OutfitsAreDeterministicAndTheTableDoesNotDependOnTheCrowdSize) {
  EXPECT_EQ(crowdRegionTints(4, 8).size(), 8 * kCrowdRegions);
  EXPECT_EQ(crowdRegionTints(4, 8), crowdRegionTints(4, 8));
  EXPECT_NE(crowdRegionTints(4, 8), crowdRegionTints(5, 8));
  const std::vector<Vec4> t = crowdRegionTints(4, 8);
  const size_t white = size_t(std::count(t.begin(), t.end(), Vec4(1.0f)));
  EXPECT_GT(white, t.size() / 8);  // about a third left white
  EXPECT_LT(white, t.size() / 2);
  EXPECT_THROW(crowdRegionTints(4, 0), Error);
}

}  // namespace
}  // namespace farfield::gen
