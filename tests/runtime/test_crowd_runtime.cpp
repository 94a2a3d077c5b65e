// The crowd runtime's choice of representation and its frames (GL test: the shared headless context).
#include "farfield/runtime/crowd_runtime.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/scene/gltf_skin.h"
#include "grey_quad.h"
#include "support/test_support.h"

namespace farfield::runtime {
namespace {

// A square view from eye towards at (the camera's other settings at their defaults).
Camera viewCamera(Vec3 eye, Vec3 at, int size) {
  Camera camera;
  camera.eye = eye;
  camera.at = at;
  camera.width = camera.height = size;
  return camera;
}

class CrowdRuntimeGl : public ::testing::Test {
 protected:
  void SetUp() override { gpu::sharedHeadlessContext(); }
};

// A small atlas (8 x 3 views up to 45 degrees, 4 frames, 2 cm texels) over a palette of `poses`.
CrowdRuntimeOptions smallAtlas(int poses) {
  CrowdRuntimeOptions o;
  o.palette_poses = poses;
  o.frames = 4;
  o.grid = impostor::ViewGrid{8, 3, float(kPi / 4)};
  o.texel_m = 0.02f;
  return o;
}

// Whether two frames have the same colours, pixel for pixel.
bool same(const image::ColorImage& a, const image::ColorImage& b) {
  return std::equal(a.pixels().begin(), a.pixels().end(), b.pixels().begin(),
                    [](const image::Rgba8& x, const image::Rgba8& y) {
                      return x.r == y.r && x.g == y.g && x.b == y.b;
                    });
}

CrowdModelOptions manOptions() {
  CrowdModelOptions mo;
  mo.facing_deg = 0.0f;
  return mo;
}

CrowdModelOptions foxOptions() {
  CrowdModelOptions mo;
  mo.height_m = 0.8f;
  return mo;
}

TEST_F(CrowdRuntimeGl, MixedDrawsGeometryNearImpostorsFarAndCullsWhatIsBehind) {
  FF_SHARED_FILE_OR_SKIP(fox_glb, "models/Fox.glb");
  const scene::SkinnedModel fox = scene::importSkinnedModel(fox_glb.string());
  const CrowdModelOptions mo = foxOptions();
  CrowdRuntime rt(std::span(&fox, 1), std::span(&mo, 1), smallAtlas(8));
  EXPECT_GT(rt.atlasBytes(), 0u);

  Camera camera = viewCamera(Vec3(0, 0, 1.7f), Vec3(10, 0, 1.0f), 128);
  const impostor::SwitchDistances sw = rt.switchDistances(0, camera);
  // Dobbyn's rule: a texel of the atlas covers one pixel at texel * focal metres.
  const double focal = 128.0 / (2.0 * std::tan(double(camera.fov_y) / 2.0));
  const gpu::AtlasLayout& l = rt.impostor(0).layout;
  EXPECT_NEAR(sw.texel_m, 2.0 * l.half_size.y / l.cell_height * focal, 1e-3);
  const double d = sw.both();
  ASSERT_GT(d, 2.0);

  std::vector<CrowdAgentState> agents(3);
  agents[0].position = Vec3(0.5 * d, 0.0, 0.0);  // near: geometry
  agents[1].position = Vec3(1.5 * d, 0.5, 0.0);  // far: impostor
  agents[2].position = Vec3(-5.0, 0.0, 0.0);     // behind the camera: culled
  for (size_t i = 0; i < 3; ++i) agents[i].object_id = uint32_t(i + 1);
  gpu::RenderTarget target(128, 128);
  gpu::LightSettings light;
  auto drawWith = [&](CrowdPolicy policy) {
    target.bindForOpaquePass();
    target.clear(light.sky_color);
    return rt.draw(camera, agents, policy, light);
  };
  const CrowdFrameStats mixed = drawWith(CrowdPolicy::Mixed);
  EXPECT_EQ(mixed.in_view, 2u);
  EXPECT_EQ(mixed.geometry, 1u);
  EXPECT_EQ(mixed.impostors, 1u);
  EXPECT_EQ(mixed.draw.draw_calls, 2u);
  const image::IdImage ids = target.readIds();
  size_t seen[4] = {0, 0, 0, 0};
  for (uint32_t id : ids.pixels()) seen[std::min<uint32_t>(id, 3)]++;
  EXPECT_GT(seen[1], 5u);  // both visible agents show (a 0.8 m fox, the far one a few pixels)
  EXPECT_GT(seen[2], 0u);
  EXPECT_EQ(seen[3], 0u);
  const CrowdFrameStats all_geometry = drawWith(CrowdPolicy::Geometry);
  EXPECT_EQ(all_geometry.geometry, 2u);
  EXPECT_EQ(all_geometry.draw.triangles, 2u * fox.mesh.triangleCount());
  const CrowdFrameStats all_impostors = drawWith(CrowdPolicy::Impostor);
  EXPECT_EQ(all_impostors.impostors, 2u);
  EXPECT_EQ(all_impostors.draw.triangles, 4u);
}

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

// Mixed's skinned agents at levels of detail: each takes the coarsest level whose measured distance stays within
// geometry_lod_px pixels at its distance (recomputed here from the levels' distances and the agent's box), farther
// agents never take finer levels, the baseline policy draws the mesh, and a coarse level covers the mesh's pixels in
// the mesh's colour regions.
TEST_F(CrowdRuntimeGl, MixedDrawsSkinnedAgentsAtTheCoarsestLevelWithinTheBound) {
  FF_SHARED_FILE_OR_SKIP(man_glb, "models/CesiumMan.glb");
  const scene::SkinnedModel man = scene::importSkinnedModel(man_glb.string());
  const CrowdModelOptions mo = manOptions();
  CrowdRuntimeOptions options = smallAtlas(8);
  options.error_px = 0.001;  // the switch beyond every agent here: all geometry
  options.geometry_lod_px = 0.5;
  options.lod_ratios = {0.5, 0.25, 0.125};
  for (int r = 0; r < scene::kColorRegions; ++r)  // one outfit of distinct region colours
    options.region_tints.push_back(Vec4(float(r % 4) / 3.0f, float(r / 4) / 3.0f, 1.0f - float(r % 3) / 2.0f, 1.0f));
  CrowdRuntime rt(std::span(&man, 1), std::span(&mo, 1), options);
  const std::span<const double> level_m = rt.levelDistances(0);
  const gpu::SkinnedGpuModel& gm = rt.gpuModel(0);
  ASSERT_EQ(level_m.size(), 4u);
  ASSERT_EQ(gm.levelCount(), 4u);
  for (size_t l = 1; l < 4; ++l) EXPECT_LE(gm.triangleCount(l), gm.triangleCount(0) / (size_t(1) << l));

  Camera camera = viewCamera(Vec3(0, 0, 1.7f), Vec3(10, 0, 1.0f), 128);
  const double focal = 128.0 / (2.0 * std::tan(double(camera.fov_y) / 2.0));
  gpu::RenderTarget target(128, 128);
  gpu::LightSettings light;
  auto levelOf = [&](uint64_t triangles) {
    for (size_t l = 0; l < gm.levelCount(); ++l)
      if (gm.triangleCount(l) == triangles) return int(l);
    return -1;
  };
  auto coarsest = [&](double metres) {  // the rule, over the levels' distances
    size_t level = 0;
    for (size_t l = 1; l < level_m.size(); ++l)
      if (level_m[l] <= options.geometry_lod_px * metres / focal) level = l;
    return level;
  };
  int previous = 0;
  for (float x : {2.0f, 6.0f, 15.0f, 40.0f, 100.0f}) {
    std::vector<CrowdAgentState> agent(1);
    agent[0].position = Vec3(x, 0.0f, 0.0f);
    agent[0].object_id = 1;
    target.bindForOpaquePass();
    target.clear(light.sky_color);
    const CrowdFrameStats st = rt.draw(camera, agent, CrowdPolicy::Mixed, light);
    ASSERT_EQ(st.geometry, 1u) << x;
    const int level = levelOf(st.draw.triangles);
    ASSERT_GE(level, 0) << x;
    EXPECT_EQ(st.coarser, level > 0 ? 1u : 0u);
    // The agent's centre lies within its box: the rule's levels at the box's nearest point (at eye height) and at
    // its farthest bracket the level drawn.
    const double near_m = glm::length(camera.eye - Vec3(x, 0.0f, camera.eye.z));
    const double far_m = std::max(glm::length(camera.eye - Vec3(x, 0.0f, 0.0f)),
                                  glm::length(camera.eye - Vec3(x, 0.5f, 1.75f)));
    EXPECT_GE(size_t(level), coarsest(near_m * 0.95)) << x;
    EXPECT_LE(size_t(level), coarsest(far_m * 1.05)) << x;
    EXPECT_GE(level, previous) << x;
    previous = level;
    const CrowdFrameStats base = rt.draw(camera, agent, CrowdPolicy::Geometry, light);
    EXPECT_EQ(base.draw.triangles, gm.triangleCount(0));
    EXPECT_EQ(base.coarser, 0u);
  }
  EXPECT_EQ(previous, 3);  // at 100 m the coarsest level holds

  // At 6 m a coarse level against the mesh: the figure's pixels and their mean colour (the regions' tints).
  std::vector<CrowdAgentState> agent(1);
  agent[0].position = Vec3(6.0f, 0.0f, 0.0f);
  agent[0].object_id = 1;
  CrowdRuntimeOptions coarse = options;
  coarse.geometry_lod_px = 20.0;  // the coarsest level everywhere
  CrowdRuntime coarse_rt(std::span(&man, 1), std::span(&mo, 1), coarse);
  auto render = [&](CrowdRuntime& r, CrowdPolicy policy) {
    target.bindForOpaquePass();
    target.clear(light.sky_color);
    const CrowdFrameStats st = r.draw(camera, agent, policy, light);
    r.finish();
    return std::make_pair(st, std::make_pair(target.readColor(), target.readIds()));
  };
  const auto [mesh_st, mesh] = render(rt, CrowdPolicy::Geometry);
  const auto [level_st, level] = render(coarse_rt, CrowdPolicy::Mixed);
  EXPECT_EQ(level_st.draw.triangles, gm.triangleCount(3));
  size_t both = 0, either = 0;
  double mean_mesh[3] = {0, 0, 0}, mean_level[3] = {0, 0, 0};
  size_t n_mesh = 0, n_level = 0;
  for (size_t p = 0; p < mesh.second.pixels().size(); ++p) {
    const bool a = mesh.second.pixels()[p] == 1, b = level.second.pixels()[p] == 1;
    both += a && b;
    either += a || b;
    if (a) {
      const image::Rgba8 c = mesh.first.pixels()[p];
      mean_mesh[0] += c.r, mean_mesh[1] += c.g, mean_mesh[2] += c.b, ++n_mesh;
    }
    if (b) {
      const image::Rgba8 c = level.first.pixels()[p];
      mean_level[0] += c.r, mean_level[1] += c.g, mean_level[2] += c.b, ++n_level;
    }
  }
  ASSERT_GT(n_mesh, 100u);
  EXPECT_GT(double(both) / double(either), 0.8);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean_level[c] / double(n_level), mean_mesh[c] / double(n_mesh), 12.0) << c;
  EXPECT_FALSE(same(mesh.first, level.first));
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

// cullBehind: agents behind a wall drawn first are left out and the frame is unchanged, pixel for pixel and id for id;
// agents in front of it, or beside it, are drawn; the culling holds for one call only. Brute force: each agent is
// hidden if, drawn alone over the wall, it leaves the wall's frame unchanged.
TEST_F(CrowdRuntimeGl, AgentsBehindTheCityAreLeftOutAndTheFrameIsUnchanged) {
  FF_SHARED_FILE_OR_SKIP(fox_glb, "models/Fox.glb");
  const scene::SkinnedModel fox = scene::importSkinnedModel(fox_glb.string());
  const CrowdModelOptions mo = foxOptions();
  CrowdRuntime rt(std::span(&fox, 1), std::span(&mo, 1), smallAtlas(4));
  // A wall 10 m ahead, 4 m wide, from 2 m below the agents' feet (no ground here: the agents' bounding boxes reach
  // below it) to 3 m above, facing the camera.
  const test::GreyQuad wall({Vec3(10, -2, -2), Vec3(10, -2, 3), Vec3(10, 2, 3), Vec3(10, 2, -2)}, Vec3(-1, 0, 0),
                            0.5f);
  const gpu::DrawItem& item = wall.item;
  gpu::Renderer renderer;
  const gpu::LightSettings light = renderer.light();
  Camera camera = viewCamera(Vec3(0, 0, 1.2f), Vec3(10, 0, 1.0f), 128);
  std::vector<CrowdAgentState> agents;
  for (float x : {6.0f, 14.0f, 20.0f})  // in front of the wall, behind it, far behind it
    for (float y : {-1.0f, 0.5f, 4.5f}) {  // behind the wall's middle, near its edge, beside it
      CrowdAgentState a;
      a.position = Vec3(x, y * x / 10.0f, 0.0f);
      a.heading = 0.3f * float(agents.size());
      a.object_id = uint32_t(agents.size() + 2);
      agents.push_back(a);
    }
  gpu::RenderTarget target(128, 128);
  for (CrowdPolicy policy : {CrowdPolicy::Geometry, CrowdPolicy::Mixed}) {
    auto frame = [&](std::span<const CrowdAgentState> drawn, bool cull, CrowdFrameStats* st) {
      renderer.render(camera, std::span(&item, 1), target);
      target.bindForOpaquePass();
      if (cull) rt.cullBehind(target);
      const CrowdFrameStats s = rt.draw(camera, drawn, policy, light);
      if (st) *st = s;
      rt.finish();
      return std::make_pair(target.readColor(), target.readIds());
    };
    CrowdFrameStats culled, plain;
    const auto with = frame(agents, true, &culled);
    const auto without = frame(agents, false, &plain);
    EXPECT_TRUE(std::equal(with.first.pixels().begin(), with.first.pixels().end(), without.first.pixels().begin(),
                           [](const image::Rgba8& a, const image::Rgba8& b) {
                             return a.r == b.r && a.g == b.g && a.b == b.b;
                           }));
    EXPECT_EQ(with.second.pixels(), without.second.pixels());
    EXPECT_EQ(plain.occluded, 0u);
    EXPECT_EQ(culled.in_view, plain.in_view);
    EXPECT_EQ(culled.geometry + culled.impostors + culled.occluded, plain.geometry + plain.impostors);
    // Brute force: how many agents change the wall's frame when drawn alone.
    const auto wall_only = frame(std::span<const CrowdAgentState>(), false, nullptr);
    size_t showing = 0;
    for (const CrowdAgentState& a : agents) {
      const auto alone = frame(std::span(&a, 1), false, nullptr);
      showing += alone.second.pixels() != wall_only.second.pixels();
    }
    EXPECT_GE(culled.occluded, 2u);                            // the agents behind the wall's middle
    EXPECT_LE(culled.occluded, plain.in_view - showing);       // never one that shows
    // The culling was for that call only.
    target.bindForOpaquePass();
    EXPECT_EQ(rt.draw(camera, agents, policy, light).occluded, 0u);
  }
}

// Agents at any heading and between capture views: the impostor covers nearly the pixels the geometry covers
// (a telephoto camera, so that the agent is large on screen).
TEST_F(CrowdRuntimeGl, ImpostorCoversTheGeometryAtAnyHeading) {
  FF_SHARED_FILE_OR_SKIP(fox_glb, "models/Fox.glb");
  const scene::SkinnedModel fox = scene::importSkinnedModel(fox_glb.string());
  CrowdRuntimeOptions o;
  o.palette_poses = 4;
  o.frames = 4;
  o.texel_m = 0.01f;  // the lecture's 32 x 8 views
  CrowdModelOptions mo;
  mo.height_m = 0.8f;
  CrowdRuntime rt(std::span(&fox, 1), std::span(&mo, 1), o);
  Camera camera = viewCamera(Vec3(0, 0, 1.7f), Vec3(25, 0, 0.4f), 160);
  camera.fov_y = float(degToRad(4.0));
  gpu::RenderTarget target(160, 160);
  gpu::LightSettings light;
  for (float heading : {0.0f, 0.5f, 1.9f, 3.0f, 4.4f}) {
    std::vector<CrowdAgentState> agents(1);
    agents[0].position = Vec3(25, 0, 0);
    agents[0].heading = heading;
    agents[0].phase = 0.25f;
    agents[0].object_id = 1;
    image::IdImage masks[2];
    for (int p = 0; p < 2; ++p) {
      target.bindForOpaquePass();
      target.clear(light.sky_color);
      rt.draw(camera, agents, p == 0 ? CrowdPolicy::Geometry : CrowdPolicy::Impostor, light);
      masks[p] = target.readIds();
    }
    size_t both = 0, either = 0;
    for (size_t i = 0; i < masks[0].pixelCount(); ++i) {
      const bool a = masks[0].pixels()[i] != 0, b = masks[1].pixels()[i] != 0;
      both += a && b;
      either += a || b;
    }
    EXPECT_GT(either, 800u) << heading;
    EXPECT_GT(double(both), 0.7 * double(either)) << "heading " << heading;
  }
}


// With the atlas chosen from the bound, the bake uses the bound's views, texel and frames, and at the bound's
// camera every impostor promise (texel, view, frame) holds from the bound's distance on: the switch is no farther.
TEST_F(CrowdRuntimeGl, AtlasFromTheBoundIsWhatTheBakeUsesAndKeepsTheBound) {
  FF_SHARED_FILE_OR_SKIP(fox_glb, "models/Fox.glb");
  const scene::SkinnedModel fox = scene::importSkinnedModel(fox_glb.string());
  CrowdRuntimeOptions o;
  o.palette_poses = 16;
  o.atlas_from_bound = true;
  o.error_px = 2.0;
  o.bound_switch_m = 12.0;
  o.bound_focal_px = 128.0 / (2.0 * std::tan(double(Camera{}.fov_y) / 2.0));
  o.frames = 5;  // not a divisor of 16: unused with the bound
  CrowdModelOptions mo;
  mo.height_m = 0.8f;
  CrowdRuntime rt(std::span(&fox, 1), std::span(&mo, 1), o);
  const CrowdAtlasChoice& c = rt.atlasChoice(0);
  ASSERT_TRUE(c.from_bound);
  const gpu::AtlasLayout& l = rt.impostor(0).layout;
  EXPECT_EQ(l.azimuths, c.grid.azimuths);
  EXPECT_EQ(l.elevations, c.grid.elevations);
  EXPECT_EQ(l.frames, c.frames);
  EXPECT_EQ(16 % c.frames, 0);
  EXPECT_NEAR(c.texel_m, 12.0 / o.bound_focal_px, 1e-6);
  EXPECT_EQ(l.cell_height, int(std::ceil(2.0f * l.half_size.y / c.texel_m)));
  // The frame error, recomputed from CPU skinning of the palette in agent space, against the bound: the chosen
  // frame count keeps it, the next smaller divisor of 16 does not (when there is one).
  const int a = fox.findAnimation("walk");
  const scene::Animation& anim = fox.animations[size_t(a)];
  std::vector<std::vector<Vec3>> positions(16);
  for (int p = 0; p < 16; ++p)
    for (const Vec3& v :
         scene::skinMesh(fox, scene::jointMatrices(fox, &anim, anim.start + anim.duration * float(p) / 16.0f)).positions)
      positions[size_t(p)].push_back(Vec3(rt.gpuModel(0).modelToAgent() * Vec4(v, 1.0f)));
  auto worst = [&](int frames) {
    double w = 0.0;
    for (int p = 0; p < 16; ++p) {
      const int q = (int(std::lround(double(p) * frames / 16.0)) % frames) * (16 / frames);
      for (size_t v = 0; v < positions[0].size(); ++v)
        w = std::max(w, double(glm::length(positions[size_t(p)][v] - positions[size_t(q)][v])));
    }
    return w;
  };
  const double max_m = o.error_px * o.bound_switch_m / o.bound_focal_px;
  EXPECT_NEAR(c.frame_error_m, worst(c.frames), 1e-5);
  EXPECT_LE(worst(c.frames), max_m);
  if (c.frames > 1) {
    EXPECT_GT(worst(c.frames / 2), max_m);
  }
  Camera camera;
  camera.width = camera.height = 128;
  const impostor::SwitchDistances sw = rt.switchDistances(0, camera);
  EXPECT_LE(sw.texel_m, 12.0 + 1e-6);  // cells rounded up to whole texels: a little finer
  EXPECT_GT(sw.texel_m, 10.0);
  EXPECT_LE(sw.view_m, 12.0 + 1e-6);
  EXPECT_LE(sw.frame_m, 12.0 + 1e-6);
}


// Turning an agent through one azimuth step of the view grid: showing the nearest view, the image jumps once at the
// midpoint; blending the four views around the direction spreads that change over the turn.
TEST_F(CrowdRuntimeGl, BlendedViewsChangeSmoothlyWhereTheNearestViewJumps) {
  FF_SHARED_FILE_OR_SKIP(fox_glb, "models/Fox.glb");
  const scene::SkinnedModel fox = scene::importSkinnedModel(fox_glb.string());
  CrowdRuntimeOptions o;
  o.palette_poses = 4;
  o.frames = 4;
  o.grid = impostor::ViewGrid{12, 3, float(kPi / 4)};
  o.texel_m = 0.01f;
  CrowdModelOptions mo;
  mo.height_m = 0.8f;
  CrowdRuntime nearest(std::span(&fox, 1), std::span(&mo, 1), o);
  o.blend_views = true;
  CrowdRuntime blended(std::span(&fox, 1), std::span(&mo, 1), o);
  Camera camera = viewCamera(Vec3(0, 0, 1.7f), Vec3(25, 0, 0.4f), 160);
  camera.fov_y = float(degToRad(4.0));
  gpu::RenderTarget target(160, 160);
  gpu::LightSettings light;
  auto largestStep = [&](CrowdRuntime& rt) {
    image::ColorImage previous;
    int largest = 0;
    const int steps = 12;
    for (int k = 0; k <= steps; ++k) {
      std::vector<CrowdAgentState> agents(1);
      agents[0].position = Vec3(25, 0, 0);
      agents[0].heading = float(2.0 * kPi / 12.0) * (0.1f + 0.8f * float(k) / float(steps));  // across a midpoint
      agents[0].phase = 0.25f;
      agents[0].object_id = 1;
      target.bindForOpaquePass();
      target.clear(light.sky_color);
      rt.draw(camera, agents, CrowdPolicy::Impostor, light);
      image::ColorImage frame = target.readColor();
      if (k > 0) {
        int changed = 0;
        for (size_t i = 0; i < frame.pixelCount(); ++i)
          for (int c = 0; c < 3; ++c)
            if (std::abs(int(frame.pixels()[i][c]) - int(previous.pixels()[i][c])) > 24) {
              ++changed;
              break;
            }
        largest = std::max(largest, changed);
      }
      previous = std::move(frame);
    }
    return largest;
  };
  const int jump = largestStep(nearest), smooth = largestStep(blended);
  EXPECT_GT(jump, 300) << "the nearest view must jump across the midpoint";
  EXPECT_LT(double(smooth), 0.6 * double(jump)) << smooth << " against " << jump;
}

}  // namespace
}  // namespace farfield::runtime
