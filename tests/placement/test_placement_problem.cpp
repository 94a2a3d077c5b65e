#include "farfield/placement/placement_problem.h"

#include <gtest/gtest.h>

#include <map>
#include <random>
#include <set>

#include "farfield/core/error.h"

using namespace farfield;
using namespace farfield::placement;

namespace {

const Lens kLens{float(degToRad(60.0)), 1.0f, 0.5f, 400.0f};
constexpr double kObjectTime = 0.02;   // per object drawn (a draw-call bound renderer, as in the paper's section 6.1)
constexpr double kImpostorTime = 0.002;

struct City {
  std::vector<HierarchyItem> items;
};

City makeCity(uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  City city;
  while (city.items.size() < 300) {
    const Vec3 lo(-300.0f + 600.0f * uni(rng), -300.0f + 600.0f * uni(rng), 0.0f);
    if (std::abs(lo.x) < 70.0f && std::abs(lo.y) < 70.0f) continue;  // a square around the view space
    city.items.push_back({uint32_t(city.items.size() + 1),
                          Box3::fromPoints(lo, lo + Vec3(6.0f + 6.0f * uni(rng), 6.0f + 6.0f * uni(rng), 5.0f + 25.0f * uni(rng))),
                          1000});
  }
  return city;
}

double frustumTime(const City& city, const Frustum& f) {
  double t = 0.0;
  for (const HierarchyItem& it : city.items)
    if (f.intersects(it.bounds)) t += kObjectTime;
  return t;
}

}  // namespace

// End to end on a synthetic city: CPVs, hierarchy, candidates, estimates, greedy; then every sampled view, drawn
// with the impostors of its CPV instead of their objects, meets t_max (the paper's frame-time guarantee).
TEST(PlacementProblem, EndToEndViewsMeetTmax) {
  const City city = makeCity(11);
  ViewSpaceOptions vo;
  vo.box = Box3::fromPoints(Vec3(-40.0f, -40.0f, 1.5f), Vec3(40.0f, 40.0f, 2.0f));
  vo.min_region_size = 20.0f;
  vo.min_vdi_angle = float(degToRad(22.5));
  vo.t_max = 1.0;
  ViewSpaceCallbacks cb;
  cb.estimate = [&](const Box3& region, const Vdi& vdi, const std::vector<uint32_t>*) {
    return frustumTime(city, enclosingFrustum(region, vdi, kLens));
  };
  const ViewSpace vs = approximateProblemViewSpace(vo, cb);
  ASSERT_GT(vs.cpvs.size(), 20u);

  const ObjectHierarchy h = ObjectHierarchy::build(city.items);
  CandidateOptions co;
  co.apex_angles = {float(degToRad(22.5)), float(degToRad(45.0)), float(degToRad(90.0))};
  co.direction_step = float(degToRad(22.5));
  co.distance_steps = 6;
  const CandidateSet cands = generateCandidates(h, vs, kLens, co);
  ASSERT_GT(cands.candidates.size(), 100u);

  const std::vector<Frustum> frusta = cpvFrusta(vs, kLens);
  std::map<uint32_t, const HierarchyItem*> by_id;
  for (const HierarchyItem& it : city.items) by_id[it.id] = &it;
  PlacementEstimates est;
  int t_object_calls = 0;
  est.t_object = [&](int node, uint32_t cpv) {
    ++t_object_calls;
    double t = 0.0;
    for (uint32_t id : h.objects(node))
      if (frusta[cpv].intersects(by_id.at(id)->bounds)) t += kObjectTime;
    return t;
  };
  est.t_impostor = [](const Candidate&, uint32_t) { return kImpostorTime; };
  est.memory = [&](const Candidate& c) {  // texels: cluster size on screen from the cell's nearest viewpoint
    const Shaft& s = std::get<Shaft>(c.cell);
    const double size = h.size(c.node);
    return 1.0 + (1.0 + s.apex_angle) * 1e4 * size * size / (double(s.min_distance) * s.min_distance + 1.0);
  };
  const GreedyProblem problem = makeGreedyProblem(vs, h, cands, est);
  ASSERT_EQ(problem.candidates.size(), cands.candidates.size());
  std::set<std::pair<int, uint32_t>> pairs;
  for (const Candidate& c : cands.candidates)
    for (uint32_t cpv : c.cpvs) pairs.insert({c.node, cpv});
  EXPECT_EQ(size_t(t_object_calls), pairs.size());  // asked once per (node, CPV)

  const GreedyResult r = placeGreedy(problem, estimatesAsGenerated(problem));
  EXPECT_TRUE(r.unsolved.empty()) << r.unsolved.size() << " of " << vs.cpvs.size() << " CPVs unsolved";
  std::printf("%zu CPVs, %zu candidates, %zu impostors, %zu recalculations, memory %.0f\n", vs.cpvs.size(),
              cands.candidates.size(), r.impostors.size(), r.counters.recalculations, r.memory);

  std::mt19937 rng(12);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  int in_cpv = 0, over_without = 0;
  for (int k = 0; k < 3000; ++k) {
    Camera cam;
    cam.eye = vo.box.lo + Vec3(uni(rng), uni(rng), uni(rng)) * vo.box.extent();
    const float azimuth = float(2.0 * kPi) * uni(rng), elevation = 0.6f * (uni(rng) - 0.5f);
    cam.at = cam.eye + Vec3(std::cos(azimuth) * std::cos(elevation), std::sin(azimuth) * std::cos(elevation), std::sin(elevation));
    cam.fov_y = kLens.fov_y;
    cam.near_plane = kLens.near_plane;
    cam.far_plane = kLens.far_plane;
    const Frustum f = Frustum::fromMatrix(cam.viewProjection());
    std::set<uint32_t> replaced;
    double t = 0.0;
    if (const std::optional<uint32_t> cpv = vs.lookup(cam)) {
      ++in_cpv;
      for (uint32_t imp : r.cpv_impostors[*cpv]) {
        const Candidate& c = cands.candidates[r.impostors[imp].candidate];
        EXPECT_TRUE(std::get<Shaft>(c.cell).contains(cam.eye));  // the impostor is valid from here
        for (uint32_t id : h.objects(c.node)) EXPECT_TRUE(replaced.insert(id).second);  // no object twice
        t += kImpostorTime;
      }
    }
    for (const HierarchyItem& it : city.items)
      if (!replaced.count(it.id) && f.intersects(it.bounds)) t += kObjectTime;
    EXPECT_LE(t, vo.t_max + 1e-9) << "view " << k;
    if (frustumTime(city, f) > vo.t_max) ++over_without;
  }
  EXPECT_GT(in_cpv, 300);
  EXPECT_GT(over_without, 100);  // without the impostors these views would break t_max
}

TEST(PlacementProblem, RequiresEveryEstimate) {
  const ViewSpace vs;
  const ObjectHierarchy h;
  const CandidateSet cands;
  PlacementEstimates est;
  EXPECT_THROW(makeGreedyProblem(vs, h, cands, est), Error);
  est.t_object = [](int, uint32_t) { return 0.0; };
  est.t_impostor = [](const Candidate&, uint32_t) { return 0.0; };
  EXPECT_THROW(makeGreedyProblem(vs, h, cands, est), Error);
  est.memory = [](const Candidate&) { return 1.0; };
  EXPECT_NO_THROW(makeGreedyProblem(vs, h, cands, est));
}
