#include "farfield/placement/candidates.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>

#include "farfield/core/error.h"

using namespace farfield;
using namespace farfield::placement;

namespace {

const Lens kLens{float(degToRad(60.0)), 1.0f, 0.5f, 400.0f};

ObjectHierarchy randomHierarchy(uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  std::vector<HierarchyItem> items;
  for (int k = 0; k < 40; ++k) {
    // Buildings around a 60 x 60 m square of streets in the middle.
    Vec3 lo(-250.0f + 500.0f * uni(rng), -250.0f + 500.0f * uni(rng), 0.0f);
    if (std::abs(lo.x) < 40.0f && std::abs(lo.y) < 40.0f) lo.x += 100.0f;
    items.push_back({uint32_t(k + 1), Box3::fromPoints(lo, lo + Vec3(4.0f + 8.0f * uni(rng), 4.0f + 8.0f * uni(rng), 3.0f + 10.0f * uni(rng))), 100});
  }
  return ObjectHierarchy::build(items, {.max_levels = 5});
}

// Every direction from every region is a problem: 4 regions x 6 faces x 4 VDIs.
ViewSpace allProblems() {
  ViewSpaceOptions o;
  o.box = Box3::fromPoints(Vec3(-30.0f, -30.0f, 1.0f), Vec3(30.0f, 30.0f, 2.0f));
  o.min_region_size = 30.0f;
  o.min_vdi_angle = float(degToRad(45.0));
  o.t_max = 1.0;
  ViewSpaceCallbacks cb;
  cb.estimate = [](const Box3&, const Vdi&, const std::vector<uint32_t>*) { return 2.0; };
  return approximateProblemViewSpace(o, cb);
}

CandidateOptions smallOptions() {
  CandidateOptions o;
  o.apex_angles = {float(degToRad(22.5)), float(degToRad(45.0)), float(degToRad(90.0))};
  o.direction_step = float(degToRad(22.5));
  o.distance_steps = 6;
  o.drop_identical = false;
  return o;
}

}  // namespace

// The monotone shortcut against brute force: every (node, axis, angle, distance) shaft built by hand, its served CPVs
// found by testing every CPV with Shaft::containsBox and the enclosing frustum, dropped by the same two rules.
TEST(Candidates, ShaftsAgreeWithBruteForce) {
  const ObjectHierarchy h = randomHierarchy(1);
  const ViewSpace vs = allProblems();
  ASSERT_EQ(vs.cpvs.size(), 96u);
  const CandidateOptions o = smallOptions();
  const CandidateSet set = generateCandidates(h, vs, kLens, o);

  std::map<std::tuple<int, int, int, int>, std::vector<uint32_t>> expected;  // node, azimuth step, angle, distance
  size_t intersecting = 0, no_cpv = 0;
  for (int n = 0; n < int(h.nodes().size()); ++n) {
    const Box3& b = h.nodes()[size_t(n)].bounds;
    for (int d = 0; d < 16; ++d) {
      const double az = degToRad(22.5 * d);
      for (int a = 0; a < 3; ++a)
        for (int k = 0; k < 6; ++k) {
          const Shaft s = Shaft::make(b.center(), Vec3(float(std::cos(az)), float(std::sin(az)), 0.0f),
                                      o.apex_angles[size_t(a)], h.size(n) * float(1 << k));
          std::vector<uint32_t> served;
          for (uint32_t c = 0; c < vs.cpvs.size(); ++c)
            if (s.containsBox(vs.cpvs[c].region) && enclosingFrustum(vs.cpvs[c].region, vs.cpvs[c].vdi, kLens).intersects(b))
              served.push_back(c);
          if (s.mayIntersectBox(b)) ++intersecting;
          else if (served.empty()) ++no_cpv;
          else expected[{n, d, a, k}] = served;
        }
    }
  }
  EXPECT_EQ(set.counts.considered, h.nodes().size() * 16 * 3 * 6);
  EXPECT_EQ(set.counts.intersecting, intersecting);
  EXPECT_EQ(set.counts.no_cpv, no_cpv);
  ASSERT_EQ(set.candidates.size(), expected.size());
  EXPECT_GT(expected.size(), 100u);
  for (const Candidate& cand : set.candidates) {
    const Shaft& s = std::get<Shaft>(cand.cell);
    const int d = int(std::lround(radToDeg(std::atan2(s.axis.y, s.axis.x)) / 22.5 + 16)) % 16;
    const int a = int(std::find(o.apex_angles.begin(), o.apex_angles.end(), s.apex_angle) - o.apex_angles.begin());
    const int k = int(std::lround(std::log2(s.min_distance / h.size(cand.node))));
    auto it = expected.find({cand.node, d, a, k});
    ASSERT_NE(it, expected.end());
    EXPECT_EQ(cand.cpvs, it->second);
    EXPECT_EQ(s.apex, h.nodes()[size_t(cand.node)].bounds.center());
  }
}

// Dropping identical cells keeps one candidate per distinct served set of a node's axis: the smallest cell.
TEST(Candidates, DropIdenticalKeepsEachServedSetOnce) {
  const ObjectHierarchy h = randomHierarchy(2);
  const ViewSpace vs = allProblems();
  CandidateOptions o = smallOptions();
  const CandidateSet all = generateCandidates(h, vs, kLens, o);
  o.drop_identical = true;
  const CandidateSet fewer = generateCandidates(h, vs, kLens, o);
  EXPECT_LT(fewer.candidates.size(), all.candidates.size());
  EXPECT_EQ(fewer.candidates.size() + fewer.counts.identical, all.candidates.size());
  auto key = [](const Candidate& c) {
    const Shaft& s = std::get<Shaft>(c.cell);
    return std::make_tuple(c.node, std::lround(std::atan2(s.axis.y, s.axis.x) * 1000.0), c.cpvs);
  };
  std::map<decltype(key(all.candidates[0])), const Candidate*> smallest;
  for (const Candidate& c : all.candidates) {
    auto [it, inserted] = smallest.emplace(key(c), &c);
    const Shaft& s = std::get<Shaft>(c.cell);
    const Shaft& best = std::get<Shaft>(it->second->cell);
    if (!inserted && (s.apex_angle < best.apex_angle || (s.apex_angle == best.apex_angle && s.min_distance > best.min_distance)))
      it->second = &c;
  }
  ASSERT_EQ(smallest.size(), fewer.candidates.size());
  for (const Candidate& c : fewer.candidates) {
    const Shaft& s = std::get<Shaft>(c.cell);
    const Shaft& best = std::get<Shaft>(smallest.at(key(c))->cell);
    EXPECT_EQ(s.apex_angle, best.apex_angle);
    EXPECT_EQ(s.min_distance, best.min_distance);
  }
}

namespace {
// Box cells only: every region of the partition, or its leaves.
CandidateSet boxCellsOnly(const ObjectHierarchy& h, const ViewSpace& vs, bool leaves_only) {
  CandidateOptions o;
  o.shafts = false;
  o.rectangular_cells = true;
  o.box_leaves_only = leaves_only;
  return generateCandidates(h, vs, kLens, o);
}
}  // namespace

TEST(Candidates, RectangularCellsServeTheCpvsInside) {
  const ObjectHierarchy h = randomHierarchy(3);
  const ViewSpace vs = allProblems();
  const CandidateSet set = boxCellsOnly(h, vs, false);
  ASSERT_FALSE(set.candidates.empty());
  size_t planned = 0;
  for (const Candidate& c : set.candidates) {
    const Box3& cell = std::get<Box3>(c.cell);
    const Box3& bounds = h.nodes()[size_t(c.node)].bounds;
    EXPECT_FALSE(cell.overlaps(bounds));
    std::vector<uint32_t> expected;
    for (uint32_t k = 0; k < vs.cpvs.size(); ++k) {
      const Box3& r = vs.cpvs[k].region;
      if (cell.contains(r.lo) && cell.contains(r.hi) &&
          enclosingFrustum(r, vs.cpvs[k].vdi, kLens).intersects(bounds))
        expected.push_back(k);
    }
    EXPECT_EQ(c.cpvs, expected);
    // The shaft an impostor of the box cell is planned for holds the cell, with its apex at the cluster's centre.
    const std::optional<Shaft> shaft = planningShaft(c, h);
    if (shaft) {
      ++planned;
      EXPECT_TRUE(shaft->containsBox(cell));
      EXPECT_EQ(shaft->apex, bounds.center());
    }
  }
  EXPECT_GT(planned, set.candidates.size() / 2);
  // 7 regions hold CPVs: the root, its two halves and their four 30 x 30 m leaves.
  EXPECT_EQ(set.counts.considered, h.nodes().size() * 7);
  EXPECT_EQ(set.counts.considered, set.counts.kept + set.counts.intersecting + set.counts.no_cpv);
}

// Per-cell placement (the paper's test 14): box cells from the partition's leaves only, each serving the CPVs inside.
TEST(Candidates, LeafBoxesAreTheSmallestRegionsOnly) {
  const ObjectHierarchy h = randomHierarchy(3);
  const ViewSpace vs = allProblems();
  const CandidateSet set = boxCellsOnly(h, vs, true);
  ASSERT_FALSE(set.candidates.empty());
  for (const Candidate& c : set.candidates) {
    const Box3& cell = std::get<Box3>(c.cell);
    const auto leaf = std::find_if(vs.nodes.begin(), vs.nodes.end(), [&](const ViewSpaceNode& n) {
      return n.children[0] < 0 && n.box.lo == cell.lo && n.box.hi == cell.hi;
    });
    EXPECT_NE(leaf, vs.nodes.end());
  }
  EXPECT_EQ(set.counts.considered, h.nodes().size() * 4);  // the four 30 x 30 m leaves
}

TEST(Candidates, DefaultsFollowThePaper) {
  const CandidateOptions o;
  EXPECT_EQ(o.apex_angles.size(), 4u);
  EXPECT_NEAR(radToDeg(o.apex_angles[0]), 11.25, 1e-4);
  EXPECT_NEAR(radToDeg(o.apex_angles[3]), 90.0, 1e-4);
  EXPECT_EQ(o.distance_steps, 11);  // 1 .. 2^10
  const ObjectHierarchy h = randomHierarchy(4);
  const CandidateSet set = generateCandidates(h, allProblems(), kLens, o);
  EXPECT_EQ(set.counts.considered, h.nodes().size() * 32 * 4 * 11);
  EXPECT_EQ(set.counts.kept, set.candidates.size());
  EXPECT_EQ(set.counts.considered, set.counts.kept + set.counts.intersecting + set.counts.no_cpv + set.counts.identical);
}

TEST(Candidates, RejectsBadOptions) {
  const ObjectHierarchy h = randomHierarchy(5);
  const ViewSpace vs = allProblems();
  auto bad = [&](auto edit) {
    CandidateOptions o;
    edit(o);
    EXPECT_THROW(generateCandidates(h, vs, kLens, o), Error);
  };
  bad([](CandidateOptions& o) { o.apex_angles = {}; });
  bad([](CandidateOptions& o) { o.apex_angles = {0.0f}; });
  bad([](CandidateOptions& o) { o.apex_angles = {4.0f}; });
  bad([](CandidateOptions& o) { o.direction_step = 0.0f; });
  bad([](CandidateOptions& o) { o.elevations = {2.0f}; });
  bad([](CandidateOptions& o) { o.first_distance_factor = -1.0f; });
  bad([](CandidateOptions& o) { o.distance_steps = 0; });
  EXPECT_THROW(generateCandidates(h, vs, Lens{0.0f, 1.0f, 0.5f, 10.0f}, CandidateOptions{}), Error);
}
