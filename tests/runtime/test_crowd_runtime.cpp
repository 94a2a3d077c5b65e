// The crowd runtime's choice of representation per agent under Mixed: geometry near, impostors far, culled behind
// the camera or the city, skinned levels of detail (GL test: the shared headless context).
#include "farfield/runtime/crowd_runtime.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/scene/gltf_skin.h"
#include "grey_quad.h"
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
  // A level's error for the rule: the larger of its distance to the mesh and how far it moves a texel.
  const std::span<const double> surface_m = rt.levelSurfaceDistances(0), texture_m = rt.levelTextureDeviations(0);
  ASSERT_EQ(surface_m.size(), 4u);
  ASSERT_EQ(texture_m.size(), 4u);
  for (size_t l = 1; l < 4; ++l) {
    EXPECT_GT(texture_m[l], 0.0);
    EXPECT_EQ(level_m[l], std::max(surface_m[l], texture_m[l]));
  }

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

}  // namespace
}  // namespace farfield::runtime
