#include "farfield/placement/view_space.h"

#include <gtest/gtest.h>

#include <random>

#include "farfield/core/error.h"

using namespace farfield;
using namespace farfield::placement;

namespace {

// A scene of point objects with a cost each: a sparse field and a dense cluster to the north-east.
struct PointScene {
  std::vector<Vec3> points;
  std::vector<double> cost;
};

PointScene makeScene(uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  PointScene s;
  for (int k = 0; k < 150; ++k) {
    s.points.push_back(Vec3(-200.0f + 400.0f * uni(rng), -200.0f + 400.0f * uni(rng), 10.0f * uni(rng)));
    s.cost.push_back(0.01);
  }
  for (int k = 0; k < 60; ++k) {
    s.points.push_back(Vec3(120.0f + 30.0f * uni(rng), 120.0f + 30.0f * uni(rng), 20.0f * uni(rng)));
    s.cost.push_back(0.05);
  }
  return s;
}

const Lens kLens{float(degToRad(60.0)), 1.0f, 0.5f, 300.0f};

ViewSpaceOptions options() {
  ViewSpaceOptions o;
  o.box = Box3::fromPoints(Vec3(-50.0f, -50.0f, 1.0f), Vec3(50.0f, 50.0f, 3.0f));
  o.min_region_size = 25.0f;
  o.min_vdi_angle = float(degToRad(22.5));
  o.t_max = 1.5;
  return o;
}

// The rendering time of a view: the cost of the points in its frustum.
double viewTime(const PointScene& s, const Vec3& eye, const Vec3& dir) {
  Camera cam;
  cam.eye = eye;
  cam.at = eye + dir;
  cam.up = Vec3(0, 0, 1);
  cam.fov_y = kLens.fov_y;
  cam.near_plane = kLens.near_plane;
  cam.far_plane = kLens.far_plane;
  const Frustum f = Frustum::fromMatrix(cam.viewProjection());
  double t = 0.0;
  for (size_t k = 0; k < s.points.size(); ++k)
    if (f.contains(s.points[k])) t += s.cost[k];
  return t;
}

// t_enc: the cost of the points in the enclosing frustum (conservative because the enclosing frustum is).
ViewSpaceCallbacks frustumEstimate(const PointScene& s) {
  ViewSpaceCallbacks cb;
  cb.estimate = [&s](const Box3& region, const Vdi& vdi, const std::vector<uint32_t>*) {
    const Frustum f = enclosingFrustum(region, vdi, kLens);
    double t = 0.0;
    for (size_t k = 0; k < s.points.size(); ++k)
      if (f.contains(s.points[k])) t += s.cost[k];
    return t;
  };
  return cb;
}

}  // namespace

TEST(ViewSpace, VdiLevels) {
  ViewSpaceOptions o = options();
  o.min_vdi_angle = float(degToRad(11.25));
  EXPECT_EQ(o.vdiLevels(), 3);
  o.min_vdi_angle = float(degToRad(12.0));
  EXPECT_EQ(o.vdiLevels(), 3);
  o.min_vdi_angle = float(degToRad(90.0));
  EXPECT_EQ(o.vdiLevels(), 0);
  o.min_vdi_angle = float(degToRad(360.0));
  EXPECT_EQ(o.vdiLevels(), 0);
}

// Conservative: every sampled view whose real time exceeds t_max is found in a CPV that holds it.
TEST(ViewSpace, EveryProblemViewIsInACpv) {
  const PointScene scene = makeScene(5);
  const ViewSpaceOptions o = options();
  const ViewSpace vs = approximateProblemViewSpace(o, frustumEstimate(scene));
  ASSERT_GT(vs.cpvs.size(), 0u);
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  int problems = 0, views = 0, in_cpv = 0;
  for (int k = 0; k < 20000; ++k) {
    const Vec3 eye = o.box.lo + Vec3(uni(rng), uni(rng), uni(rng)) * o.box.extent();
    const float azimuth = float(2.0 * kPi) * uni(rng), elevation = 1.2f * (uni(rng) - 0.5f);
    const Vec3 dir(std::cos(azimuth) * std::cos(elevation), std::sin(azimuth) * std::cos(elevation), std::sin(elevation));
    ++views;
    const std::optional<uint32_t> cpv = vs.lookup(eye, dir);
    if (cpv) {
      ++in_cpv;
      EXPECT_TRUE(vs.cpvs[*cpv].region.contains(eye));
      EXPECT_TRUE(vs.cpvs[*cpv].vdi.contains(dir));
      EXPECT_GT(vs.cpvs[*cpv].t_enc, o.t_max);
    }
    if (viewTime(scene, eye, dir) > o.t_max) {
      ++problems;
      EXPECT_TRUE(cpv.has_value()) << "problem view not in a CPV: eye " << eye.x << "," << eye.y << "," << eye.z;
    }
  }
  std::printf("%d views: %d problem views, %d in CPVs (%zu CPVs, %zu regions visited, %zu estimates)\n", views,
              problems, in_cpv, vs.cpvs.size(), vs.counts.regions, vs.counts.estimates);
  EXPECT_GT(problems, 500);
  EXPECT_LT(in_cpv, views * 3 / 4);  // views away from the cluster are not problems
}

TEST(ViewSpace, CpvsAreEquallySizedAndSubtreesContiguous) {
  const PointScene scene = makeScene(7);
  const ViewSpace vs = approximateProblemViewSpace(options(), frustumEstimate(scene));
  ASSERT_FALSE(vs.cpvs.empty());
  const Vec3 size = vs.cpvs[0].region.extent();
  for (const Cpv& c : vs.cpvs) {
    EXPECT_EQ(c.region.extent(), size);
    EXPECT_FLOAT_EQ(c.vdi.u1 - c.vdi.u0, 0.5f);  // two levels below a face: 2 / 2^2
    EXPECT_FLOAT_EQ(c.vdi.v1 - c.vdi.v0, 0.5f);
    EXPECT_LE(std::max({size.x, size.y, size.z}), options().min_region_size);
  }
  EXPECT_EQ(vs.counts.cpvs, vs.cpvs.size());
  for (size_t n = 0; n < vs.nodes.size(); ++n) {
    const ViewSpaceNode& node = vs.nodes[n];
    for (uint32_t k = node.cpv_first; k < node.cpv_first + node.cpv_count; ++k) {
      const Box3& r = vs.cpvs[k].region;
      EXPECT_TRUE(node.box.contains(r.lo) && node.box.contains(r.hi));
    }
    if (node.children[0] >= 0) {
      EXPECT_EQ(node.cpv_count,
                vs.nodes[size_t(node.children[0])].cpv_count + vs.nodes[size_t(node.children[1])].cpv_count);
    }
  }
  EXPECT_EQ(vs.nodes[0].cpv_count, vs.cpvs.size());
}

TEST(ViewSpace, StopsEarlyWhereNothingIsSlowAndCountsEverythingWhereAllIs) {
  const ViewSpaceOptions o = options();
  ViewSpaceCallbacks fast;
  fast.estimate = [](const Box3&, const Vdi&, const std::vector<uint32_t>*) { return 1.0; };
  const ViewSpace none = approximateProblemViewSpace(o, fast);
  EXPECT_EQ(none.counts.regions, 1u);
  EXPECT_EQ(none.counts.estimates, 6u);
  EXPECT_TRUE(none.cpvs.empty());
  EXPECT_FALSE(none.lookup(Vec3(0, 0, 2), Vec3(1, 0, 0)).has_value());

  ViewSpaceCallbacks slow;
  int visible_calls = 0;
  slow.visible_set = [&](const Box3&) {
    ++visible_calls;
    return std::vector<uint32_t>{42};
  };
  slow.estimate = [](const Box3&, const Vdi&, const std::vector<uint32_t>* visible) {
    EXPECT_TRUE(visible && visible->size() == 1 && (*visible)[0] == 42);
    return 2.0;
  };
  const ViewSpace all = approximateProblemViewSpace(o, slow);
  // 100 x 100 x 2 m split at the longest side down to <= 25 m: 4 x 4 regions of 25 x 25 x 2, 31 regions visited.
  EXPECT_EQ(all.counts.problem_regions, 16u);
  EXPECT_EQ(all.counts.regions, 31u);
  EXPECT_EQ(visible_calls, 31);
  EXPECT_EQ(all.cpvs.size(), 16u * 6u * 16u);
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  for (int k = 0; k < 2000; ++k) {
    const Vec3 eye = o.box.lo + Vec3(uni(rng), uni(rng), uni(rng)) * o.box.extent();
    const Vec3 dir(uni(rng) - 0.5f, uni(rng) - 0.5f, uni(rng) - 0.5f);
    const std::optional<uint32_t> cpv = all.lookup(eye, dir);
    ASSERT_TRUE(cpv.has_value());
    EXPECT_TRUE(all.cpvs[*cpv].region.contains(eye));
    EXPECT_TRUE(all.cpvs[*cpv].vdi.contains(dir));
  }
  EXPECT_FALSE(all.lookup(Vec3(0, 0, 10), Vec3(1, 0, 0)).has_value());  // above the box
  Camera cam;
  cam.eye = Vec3(10, 10, 2);
  cam.at = Vec3(20, 10, 2);
  EXPECT_EQ(all.lookup(cam), all.lookup(cam.eye, Vec3(1, 0, 0)));
}

TEST(ViewSpace, RejectsBadOptions) {
  ViewSpaceCallbacks cb;
  cb.estimate = [](const Box3&, const Vdi&, const std::vector<uint32_t>*) { return 1.0; };
  auto bad = [&](auto edit) {
    ViewSpaceOptions o = options();
    edit(o);
    EXPECT_THROW(approximateProblemViewSpace(o, cb), Error);
  };
  bad([](ViewSpaceOptions& o) { o.box = Box3{}; });
  bad([](ViewSpaceOptions& o) { o.min_region_size = 0.0f; });
  bad([](ViewSpaceOptions& o) { o.min_region_size = -1.0f; });
  bad([](ViewSpaceOptions& o) { o.min_region_size = 1e-9f; });
  bad([](ViewSpaceOptions& o) { o.min_vdi_angle = 0.0f; });
  bad([](ViewSpaceOptions& o) { o.t_max = 0.0; });
  bad([](ViewSpaceOptions& o) { o.t_max = -2.0; });
  EXPECT_THROW(approximateProblemViewSpace(options(), ViewSpaceCallbacks{}), Error);
  ViewSpaceCallbacks nan;
  nan.estimate = [](const Box3&, const Vdi&, const std::vector<uint32_t>*) { return std::nan(""); };
  EXPECT_THROW(approximateProblemViewSpace(options(), nan), Error);
}
