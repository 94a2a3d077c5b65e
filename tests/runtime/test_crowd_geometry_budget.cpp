// The crowd runtime's geometry budget under Mixed: in triangles (nearest agents first, or the least error on
// screen with levels of detail) and in milliseconds (GL test: the shared headless context).
#include "farfield/runtime/crowd_runtime.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/gpu/render_target.h"
#include "farfield/scene/gltf_skin.h"
#include "runtime/crowd_runtime_fixture.h"
#include "support/test_support.h"

namespace farfield::runtime {
namespace {

using crowd_runtime_test::CrowdRuntimeGl;
using crowd_runtime_test::foxOptions;
using crowd_runtime_test::manOptions;
using crowd_runtime_test::same;
using crowd_runtime_test::smallAtlas;
using crowd_runtime_test::viewCamera;

// Mixed under a geometry budget: of the agents inside their switch distance, the nearest are drawn as geometry while
// their triangles fit and the rest as impostors, whatever the agents' order. Brute force: the frame equals the one
// drawn by Geometry for the nearest agents and Impostor for the others, and differs from the opposite assignment.
TEST_F(CrowdRuntimeGl, AGeometryBudgetDrawsTheNearestAgentsAsGeometry) {
  FF_SHARED_FILE_OR_SKIP(fox_glb, "models/Fox.glb");
  const scene::SkinnedModel fox = scene::importSkinnedModel(fox_glb.string());
  const CrowdModelOptions mo = foxOptions();
  CrowdRuntimeOptions options = smallAtlas(8);
  const uint64_t fox_triangles = fox.mesh.triangleCount();
  options.max_geometry_triangles = 2 * fox_triangles + fox_triangles / 2;  // two foxes fit, not three
  CrowdRuntime rt(std::span(&fox, 1), std::span(&mo, 1), options);
  CrowdRuntimeOptions unbudgeted_options = smallAtlas(8);
  CrowdRuntime unbudgeted(std::span(&fox, 1), std::span(&mo, 1), unbudgeted_options);

  Camera camera = viewCamera(Vec3(0, 0, 1.2f), Vec3(10, 0, 0.4f), 128);
  const double d = rt.switchDistances(0, camera).both();
  ASSERT_GT(d, 3.0);
  // Four agents inside the switch, listed far to near, spread across the view.
  std::vector<CrowdAgentState> agents(4);
  for (size_t i = 0; i < agents.size(); ++i) {
    const double x = d * (0.85 - 0.15 * double(i));
    agents[i].position = Vec3(float(x), float(x * (double(i) - 1.5) * 0.15), 0.0f);
    agents[i].heading = 0.7f * float(i);
    agents[i].object_id = uint32_t(i + 1);
  }
  gpu::RenderTarget target(128, 128);
  gpu::LightSettings light;
  const auto frame = [&](const std::vector<std::pair<CrowdRuntime*, CrowdPolicy>>& passes,
                         const std::vector<std::vector<CrowdAgentState>>& lists, CrowdFrameStats* stats) {
    target.bindForOpaquePass();
    target.clear(light.sky_color);
    for (size_t k = 0; k < passes.size(); ++k) {
      const CrowdFrameStats s = passes[k].first->draw(camera, lists[k], passes[k].second, light);
      if (stats) *stats = s;
    }
    rt.finish();
    return target.readColor();
  };
  CrowdFrameStats st;
  const image::ColorImage budgeted = frame({{&rt, CrowdPolicy::Mixed}}, {agents}, &st);
  EXPECT_EQ(st.in_view, 4u);
  EXPECT_EQ(st.geometry, 2u);
  EXPECT_EQ(st.impostors, 2u);
  EXPECT_EQ(st.over_budget, 2u);
  EXPECT_EQ(st.draw.triangles, 2 * fox_triangles + 4);
  const std::vector<CrowdAgentState> near(agents.begin() + 2, agents.end()), far(agents.begin(), agents.begin() + 2);
  const image::ColorImage expected =
      frame({{&unbudgeted, CrowdPolicy::Geometry}, {&unbudgeted, CrowdPolicy::Impostor}}, {near, far}, nullptr);
  const image::ColorImage opposite =
      frame({{&unbudgeted, CrowdPolicy::Impostor}, {&unbudgeted, CrowdPolicy::Geometry}}, {near, far}, nullptr);
  EXPECT_TRUE(same(budgeted, expected));
  EXPECT_FALSE(same(budgeted, opposite));
  // Without the budget every agent inside the switch is geometry.
  const image::ColorImage all = frame({{&unbudgeted, CrowdPolicy::Mixed}}, {agents}, &st);
  EXPECT_EQ(st.geometry, 4u);
  EXPECT_EQ(st.over_budget, 0u);
  EXPECT_TRUE(same(all, frame({{&unbudgeted, CrowdPolicy::Geometry}}, {agents}, nullptr)));
}

// A budget in milliseconds: the first frame allows the estimator's first triangles, the skinned draws are timed, and
// the next frame's budget is the milliseconds over the measured time per triangle; the skinned triangles drawn never
// exceed the frame's budget.
TEST_F(CrowdRuntimeGl, AGeometryBudgetInMillisecondsFollowsTheMeasuredTimePerTriangle) {
  FF_SHARED_FILE_OR_SKIP(man_glb, "models/CesiumMan.glb");
  const scene::SkinnedModel man = scene::importSkinnedModel(man_glb.string());
  const CrowdModelOptions mo = manOptions();
  CrowdRuntimeOptions options = smallAtlas(8);
  options.geometry_ms = 1000.0;  // every agent fits once the cost is measured
  CrowdRuntime rt(std::span(&man, 1), std::span(&mo, 1), options);
  Camera camera = viewCamera(Vec3(0, 0, 1.5f), Vec3(10, 0, 1.0f), 96);
  const double d = rt.switchDistances(0, camera).both();
  std::vector<CrowdAgentState> agents(4);  // 4 x 4,672 triangles, more than the first 10,000
  for (size_t i = 0; i < agents.size(); ++i) {
    const double x = std::min(d * 0.8, 8.0) - 1.0 * double(i);
    agents[i].position = Vec3(float(x), float(double(i) - 1.5), 0.0f);
    agents[i].object_id = uint32_t(i + 1);
  }
  gpu::RenderTarget target(96, 96);
  gpu::LightSettings light;
  target.bindForOpaquePass();
  CrowdFrameStats first = rt.draw(camera, agents, CrowdPolicy::Mixed, light);
  rt.finish();
  EXPECT_EQ(first.budget_triangles, 10000u);
  EXPECT_EQ(first.geometry, 2u);  // two meshes fit the first budget
  EXPECT_LE(first.draw.triangles - 2 * first.impostors, first.budget_triangles);
  const double ms = rt.collectGeometryMs();
  EXPECT_GT(ms, 0.0);
  EXPECT_NEAR(rt.msPerSkinnedTriangle(), ms / double(2 * man.mesh.triangleCount()), 1e-12);
  const CrowdFrameStats second = rt.draw(camera, agents, CrowdPolicy::Mixed, light);
  rt.finish();
  EXPECT_EQ(second.budget_triangles, uint64_t(std::floor(1000.0 / rt.msPerSkinnedTriangle() + 1e-9)));  // factor 1
  EXPECT_EQ(second.geometry, 4u);
  EXPECT_DOUBLE_EQ(second.geometry_ms, ms);
  CrowdRuntimeOptions bad = smallAtlas(8);
  bad.geometry_ms = -1.0;
  EXPECT_THROW(CrowdRuntime(std::span(&man, 1), std::span(&mo, 1), bad), farfield::Error);
}

// Under a geometry budget with levels of detail and budget_coarsens, agents take coarser levels or become impostors,
// the least error on screen first (a level's distance to the mesh, an impostor's bound scaled from its switch, both
// over the agent's distance): the choice drawn keeps the budget, and its largest error on screen is the smallest any
// choice keeps within the budget (brute force over every choice of levels at least as coarse as the bound's, and
// impostors).
TEST_F(CrowdRuntimeGl, AGeometryBudgetTakesTheLeastErrorOnScreenFirst) {
  FF_SHARED_FILE_OR_SKIP(man_glb, "models/CesiumMan.glb");
  const scene::SkinnedModel man = scene::importSkinnedModel(man_glb.string());
  const CrowdModelOptions mo = manOptions();
  CrowdRuntimeOptions options = smallAtlas(8);
  options.error_px = 0.005;  // the switch beyond every agent here: all inside it
  options.geometry_lod_px = 0.05;
  options.lod_ratios = {0.5, 0.25, 0.125};
  CrowdRuntime unbudgeted(std::span(&man, 1), std::span(&mo, 1), options);
  const std::span<const double> level_m = unbudgeted.levelDistances(0);
  const gpu::SkinnedGpuModel& gm = unbudgeted.gpuModel(0);
  ASSERT_EQ(gm.levelCount(), 4u);

  Camera camera = viewCamera(Vec3(0, 0, 1.7f), Vec3(10, 0, 1.0f), 128);
  std::vector<CrowdAgentState> agents(4);
  std::vector<float> distance(agents.size());
  for (size_t i = 0; i < agents.size(); ++i) {
    agents[i].position = Vec3(4.0f + 5.0f * float(i), (float(i) - 1.5f) * 1.5f, 0.0f);
    agents[i].object_id = uint32_t(i + 1);
    distance[i] = glm::length(camera.eye - (agents[i].position + Vec3(0, 0, 0.875f)));
  }
  const double focal = 128.0 / (2.0 * std::tan(double(camera.fov_y) / 2.0));
  const double switch_m = unbudgeted.switchDistances(0, camera).both();
  ASSERT_GT(switch_m, double(distance.back()) + 2.0);
  const double impostor_m = options.error_px * switch_m / focal;  // an impostor's error, metres over the distance
  gpu::RenderTarget target(128, 128);
  gpu::LightSettings light;
  target.bindForOpaquePass();
  const CrowdFrameStats free_st = unbudgeted.draw(camera, agents, CrowdPolicy::Mixed, light);
  ASSERT_EQ(free_st.geometry, 4u);
  // Each agent's choices: the bound's level, the coarser ones that show less than an impostor, the impostor (-1).
  std::vector<std::vector<int>> rungs(agents.size());
  for (size_t i = 0; i < agents.size(); ++i) {
    const int bound = unbudgeted.drawnLevel(i);
    rungs[i].push_back(bound);
    for (int l = bound + 1; l < 4; ++l)
      if (level_m[size_t(l)] < impostor_m) rungs[i].push_back(l);
    rungs[i].push_back(-1);
  }
  auto errorOf = [&](size_t i, int l) { return (l < 0 ? impostor_m : level_m[size_t(l)]) / double(distance[i]); };
  auto trianglesOf = [&](int l) { return l < 0 ? uint64_t(0) : gm.triangleCount(size_t(l)); };
  auto bestMax = [&](uint64_t budget) {  // brute force over every choice
    double best = 1e30;
    std::vector<size_t> pick(agents.size(), 0);
    for (;;) {
      uint64_t triangles = 0;
      double worst = 0.0;
      for (size_t i = 0; i < agents.size(); ++i) {
        triangles += trianglesOf(rungs[i][pick[i]]);
        worst = std::max(worst, errorOf(i, rungs[i][pick[i]]));
      }
      if (triangles <= budget) best = std::min(best, worst);
      size_t i = 0;
      while (i < pick.size() && ++pick[i] == rungs[i].size()) pick[i++] = 0;
      if (i == pick.size()) return best;
    }
  };
  const uint64_t coarsest = 4 * gm.triangleCount(3);
  ASSERT_LT(coarsest, free_st.draw.triangles);
  size_t impostors_seen = 0, coarsened_seen = 0;
  // Budgets: shares of the unbudgeted triangles, under the coarsest levels of all four, and one triangle.
  const uint64_t f = free_st.draw.triangles;
  for (const uint64_t budget : {f * 9 / 10, f * 6 / 10, f * 35 / 100, 3 * gm.triangleCount(3) - 1, uint64_t(1)}) {
    CrowdRuntimeOptions o = options;
    o.max_geometry_triangles = budget;
    o.budget_coarsens = true;
    const double share = double(budget) / double(f);
    CrowdRuntime rt(std::span(&man, 1), std::span(&mo, 1), o);
    const CrowdFrameStats st = rt.draw(camera, agents, CrowdPolicy::Mixed, light);
    EXPECT_EQ(st.geometry + st.impostors, 4u) << share;
    EXPECT_EQ(st.over_budget, st.impostors) << share;
    EXPECT_LE(st.draw.triangles - 2 * st.impostors, o.max_geometry_triangles) << share;
    double worst = 0.0;
    for (size_t i = 0; i < agents.size(); ++i) {
      const int l = rt.drawnLevel(i);
      EXPECT_TRUE(std::find(rungs[i].begin(), rungs[i].end(), l) != rungs[i].end()) << share << " " << i;
      worst = std::max(worst, errorOf(i, l));
    }
    const double best = bestMax(o.max_geometry_triangles);
    EXPECT_NEAR(worst, best, 1e-6 * best) << share;
    impostors_seen += st.impostors;
    coarsened_seen += st.coarsened;
    if (budget == 1) {
      EXPECT_EQ(st.impostors, 4u);  // a budget of one triangle: all impostors
    }
  }
  EXPECT_GT(coarsened_seen, 0u);  // both kinds of step were taken
  EXPECT_GT(impostors_seen, 4u);
  // Without budget_coarsens the agents keep the bound's levels and the farthest become impostors, as many as the
  // budget asks and no more.
  CrowdRuntimeOptions o = options;
  o.max_geometry_triangles = f * 6 / 10;
  CrowdRuntime rt(std::span(&man, 1), std::span(&mo, 1), o);
  const CrowdFrameStats st = rt.draw(camera, agents, CrowdPolicy::Mixed, light);
  EXPECT_EQ(st.coarsened, 0u);
  ASSERT_GT(st.impostors, 0u);
  uint64_t kept = 0;
  for (size_t i = 0; i < agents.size(); ++i) {  // agents[i] nearer than agents[i + 1]
    const bool impostor = i >= agents.size() - st.impostors;
    EXPECT_EQ(rt.drawnLevel(i), impostor ? -1 : rungs[i].front()) << i;
    if (!impostor) kept += gm.triangleCount(size_t(rungs[i].front()));
  }
  EXPECT_LE(kept, o.max_geometry_triangles);
  const size_t next = agents.size() - st.impostors;
  EXPECT_GT(kept + gm.triangleCount(size_t(rungs[next].front())), o.max_geometry_triangles);
}

}  // namespace
}  // namespace farfield::runtime
