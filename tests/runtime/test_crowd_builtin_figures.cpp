// The crowd runtime on the built-in figures (gen/walker_figure.h, gen/quadruped_figure.h), which need no file: both
// are baked into impostors, drawn skinned near and as impostors far, at levels of detail, and cast shadows; an
// impostor shows its figure (the same pixels and colours as the skinned geometry from a captured view). GL tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "farfield/gen/quadruped_figure.h"
#include "farfield/gen/walker_figure.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/runtime/crowd_runtime.h"
#include "grey_quad.h"

namespace farfield::runtime {
namespace {

class CrowdBuiltinFiguresGl : public ::testing::Test {
 protected:
  void SetUp() override { gpu::sharedHeadlessContext(); }

  // The walker (1.77 m) and the four-legged figure (0.7 m), both made facing +x.
  static std::vector<CrowdModelOptions> figureOptions() {
    std::vector<CrowdModelOptions> o(2);
    o[0].height_m = 1.77f;
    o[1].height_m = 0.7f;
    for (CrowdModelOptions& m : o) m.facing_deg = 0.0f;
    return o;
  }

  std::vector<scene::SkinnedModel> figures_{gen::makeWalkerFigure(), gen::makeQuadrupedFigure()};
};

// A small atlas: 16 azimuths x 3 elevations up to 45 degrees, 4 frames of a 16-pose palette, 1.5 cm texels.
CrowdRuntimeOptions smallAtlas() {
  CrowdRuntimeOptions o;
  o.palette_poses = 16;
  o.frames = 4;
  o.grid = impostor::ViewGrid{16, 3, float(kPi / 4)};
  o.texel_m = 0.015f;
  return o;
}

Camera viewCamera(Vec3 eye, Vec3 at, int size) {
  Camera camera;
  camera.eye = eye;
  camera.at = at;
  camera.width = camera.height = size;
  return camera;
}

TEST_F(CrowdBuiltinFiguresGl, BothFiguresAreDrawnSkinnedNearAndAsImpostorsFar) {
  const std::vector<CrowdModelOptions> mo = figureOptions();
  CrowdRuntimeOptions options = smallAtlas();
  options.geometry_lod_px = 0.5;
  options.lod_ratios = {0.5, 0.25};
  CrowdRuntime rt(figures_, mo, options);
  ASSERT_EQ(rt.modelCount(), 2u);
  EXPECT_GT(rt.atlasBytes(), 0u);
  for (size_t m = 0; m < 2; ++m) {
    EXPECT_EQ(rt.modelTriangles(m), figures_[m].mesh.triangleCount());
    EXPECT_FALSE(rt.gpuModel(m).cutout());
    // Levels of detail over the walk's poses: fewer triangles at each level, a finite distance to the mesh.
    const gpu::SkinnedGpuModel& gm = rt.gpuModel(m);
    ASSERT_EQ(gm.levelCount(), 3u);
    EXPECT_LT(gm.triangleCount(1), gm.triangleCount(0));
    EXPECT_LT(gm.triangleCount(2), gm.triangleCount(1));
    const std::span<const double> level_m = rt.levelDistances(m);
    ASSERT_EQ(level_m.size(), 3u);
    EXPECT_TRUE(std::isfinite(level_m[2]) && level_m[2] > 0.0 && level_m[2] < 0.1) << level_m[2];
  }

  Camera camera = viewCamera(Vec3(0, 0, 1.6f), Vec3(10, 0, 0.8f), 160);
  std::vector<CrowdAgentState> agents;
  for (uint32_t m = 0; m < 2; ++m) {
    const double d = rt.switchDistances(m, camera).both();
    ASSERT_GT(d, 3.0);
    for (double x : {0.3 * d, 1.3 * d}) {
      CrowdAgentState a;
      a.model = m;
      a.position = Vec3(float(x), m == 0 ? 0.6f : -0.6f, 0.0f);
      a.object_id = uint32_t(agents.size() + 1);
      agents.push_back(a);
    }
  }
  gpu::RenderTarget target(160, 160);
  gpu::LightSettings light;
  target.bindForOpaquePass();
  target.clear(light.sky_color);
  const CrowdFrameStats st = rt.draw(camera, agents, CrowdPolicy::Mixed, light);
  rt.finish();
  EXPECT_EQ(st.in_view, 4u);
  EXPECT_EQ(st.geometry, 2u);
  EXPECT_EQ(st.impostors, 2u);
  std::vector<size_t> seen(agents.size() + 1, 0);
  const image::IdImage ids = target.readIds();
  for (uint32_t id : ids.pixels()) ++seen[std::min<size_t>(id, agents.size())];
  for (size_t i = 1; i <= agents.size(); ++i) EXPECT_GT(seen[i], 0u) << "agent " << i << " covers no pixel";
  EXPECT_GT(seen[1], seen[2]) << "the near walker is larger than the far one";
}

// From a view the atlas captured (the agent straight ahead at the ring's elevation, a frame's phase), the impostor
// covers the skinned figure's pixels and shows its colours: the figure's regions, not a blob.
TEST_F(CrowdBuiltinFiguresGl, AnImpostorShowsItsFigure) {
  const std::vector<CrowdModelOptions> mo = figureOptions();
  CrowdRuntime rt(figures_, mo, smallAtlas());
  gpu::LightSettings light;
  for (uint32_t m = 0; m < 2; ++m) {
    const float h = mo[m].height_m;
    const float distance = 4.0f * h;
    // The agent at the origin seen level from its side (azimuth 90 degrees, elevation 0: a captured view).
    const float cz = 0.5f * h;
    Camera camera = viewCamera(Vec3(0, -distance, cz), Vec3(0, 0, cz), 128);
    camera.fov_y = 2.0f * std::atan(0.75f * h / distance);
    std::vector<CrowdAgentState> agent(1);
    agent[0].model = m;
    agent[0].phase = 0.25f;  // frame 1 of 4
    agent[0].object_id = 1;
    gpu::RenderTarget target(128, 128);
    auto render = [&](CrowdPolicy policy) {
      target.bindForOpaquePass();
      target.clear(light.sky_color);
      rt.draw(camera, agent, policy, light);
      rt.finish();
      return std::make_pair(target.readColor(), target.readIds());
    };
    const auto geometry = render(CrowdPolicy::Geometry);
    const auto impostor = render(CrowdPolicy::Impostor);
    size_t both = 0, either = 0, close = 0;
    for (size_t p = 0; p < geometry.second.pixels().size(); ++p) {
      const bool a = geometry.second.pixels()[p] == 1, b = impostor.second.pixels()[p] == 1;
      both += a && b;
      either += a || b;
      if (a && b) {
        const image::Rgba8 x = geometry.first.pixels()[p], y = impostor.first.pixels()[p];
        const int diff = std::max({std::abs(int(x.r) - int(y.r)), std::abs(int(x.g) - int(y.g)),
                                   std::abs(int(x.b) - int(y.b))});
        if (diff <= 40) ++close;
      }
    }
    ASSERT_GT(either, 500u) << figures_[m].name;
    EXPECT_GT(double(both) / double(either), 0.8) << figures_[m].name;
    EXPECT_GT(double(close) / double(both), 0.8) << figures_[m].name;
    // Colours vary over the figure (its material regions): the skinned pixels span a range of colours.
    int lo = 255, hi = 0;
    for (size_t p = 0; p < geometry.second.pixels().size(); ++p)
      if (geometry.second.pixels()[p] == 1) {
        const image::Rgba8 c = geometry.first.pixels()[p];
        lo = std::min(lo, int(c.r) + int(c.g) + int(c.b));
        hi = std::max(hi, int(c.r) + int(c.g) + int(c.b));
      }
    EXPECT_GT(hi - lo, 150) << figures_[m].name;
  }
}

// The figures cast shadows: the ground under the sun darkens beside them, as geometry and as impostors.
TEST_F(CrowdBuiltinFiguresGl, FiguresCastShadowsOnTheGround) {
  const std::vector<CrowdModelOptions> mo = figureOptions();
  CrowdRuntime rt(figures_, mo, smallAtlas());
  const test::GreyQuad ground({Vec3(-10, -10, 0), Vec3(10, -10, 0), Vec3(10, 10, 0), Vec3(-10, 10, 0)},
                              Vec3(0, 0, 1), 0.6f);
  gpu::Renderer renderer;
  const gpu::LightSettings light = renderer.light();
  Camera camera = viewCamera(Vec3(-4.0f, -4.0f, 5.0f), Vec3(0, 0, 0.3f), 160);
  std::vector<CrowdAgentState> agents(2);
  agents[0].position = Vec3(-0.6f, 0.0f, 0.0f);
  agents[1].model = 1;
  agents[1].position = Vec3(0.8f, 0.5f, 0.0f);
  agents[0].object_id = kAgentIdBit | 1u;
  agents[1].object_id = kAgentIdBit | 2u;
  auto ground_pixels = [&](CrowdPolicy policy, bool shadows) {
    gpu::RenderTarget t(160, 160);
    renderer.render(camera, std::span(&ground.item, 1), t);
    if (shadows) {
      const CrowdFrameStats st = rt.drawShadowed(camera, agents, policy, light, t, CrowdShadowOptions{});
      EXPECT_EQ(st.shadow_casters, 2u);
    } else {
      t.bindForOpaquePass();
      rt.draw(camera, agents, policy, light);
    }
    rt.finish();
    return std::make_pair(t.readColor(), t.readIds());
  };
  for (CrowdPolicy policy : {CrowdPolicy::Geometry, CrowdPolicy::Impostor}) {
    const auto plain = ground_pixels(policy, false);
    const auto shadowed = ground_pixels(policy, true);
    size_t darker = 0;
    for (size_t p = 0; p < plain.second.pixels().size(); ++p)
      if (plain.second.pixels()[p] == 1 && shadowed.second.pixels()[p] == 1 &&
          int(shadowed.first.pixels()[p].g) + 20 < int(plain.first.pixels()[p].g))
        ++darker;
    EXPECT_GT(darker, 30u) << (policy == CrowdPolicy::Geometry ? "geometry" : "impostor");
  }
}

}  // namespace
}  // namespace farfield::runtime
