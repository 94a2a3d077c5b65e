// The crowd runtime's impostor atlas: it covers the geometry at any heading, an atlas chosen from the bound keeps
// the bound, and blended views change smoothly (GL test: the shared headless context).
#include "farfield/runtime/crowd_runtime.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "farfield/gpu/render_target.h"
#include "farfield/scene/gltf_skin.h"
#include "runtime/crowd_runtime_fixture.h"
#include "support/test_support.h"

namespace farfield::runtime {
namespace {

using crowd_runtime_test::CrowdRuntimeGl;
using crowd_runtime_test::viewCamera;

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
         scene::skinMesh(fox, scene::jointMatrices(fox, &anim, anim.start + anim.duration * float(p) / 16.0f))
             .positions)
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
