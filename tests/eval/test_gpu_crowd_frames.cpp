// The frames the crowd runtime draws from the GPU crowd (gpu/gpu_crowd.h; issue 45) against the CPU path's frames on
// a crowd of the built-in figures: policies, blended views, occlusion, shadows, budgets and levels of detail. Needs a
// GL context (llvmpipe is enough).
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <set>
#include <span>
#include <utility>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/eval/crowd_metrics.h"
#include "farfield/eval/crowd_walk.h"
#include "farfield/eval/gpu_crowd_input.h"
#include "farfield/gen/street_network.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/gl_barrier_check.h"
#include "farfield/gpu/gl_counters.h"
#include "farfield/gpu/render_target.h"
#include "farfield/image/metrics.h"
#include "farfield/runtime/crowd_runtime.h"
#include "runtime/grey_quad.h"

namespace farfield::eval {
namespace {

// The built-in figures' runtime, a crowd of 3,000 on a small street network, its GPU crowd and CPU states at one
// time, and a camera among the agents: what the frame tests draw both ways.
struct CrowdScene {
  CrowdModels models = (gpu::sharedHeadlessContext().makeCurrent(), builtinCrowdModels());
  runtime::CrowdRuntime rt{models.models, models.options, runtime::CrowdRuntimeOptions{}};
  gen::Crowd crowd = makeCrowd(models.shares);
  gpu::GpuCrowd gc{gpuCrowdRoutes(crowd), gpuCrowdAgents(crowd, kCrowdIdBit), rt.gpuCrowdModels(kCrowdNominalSpeed)};
  float t = 7.5f;
  std::vector<runtime::CrowdAgentState> states = crowdAgentStates(crowd, rt, t);
  Camera camera = cameraAmong();

  CrowdScene() { gc.simulate(t); }
  static gen::Crowd makeCrowd(const std::vector<float>& shares) {
    gen::StreetNetworkOptions so;
    so.blocks = 12;
    so.seed = 3;
    gen::CrowdOptions co;
    co.agents = 3000;
    co.seed = 21;
    co.model_shares = shares;
    return gen::generateCrowd(gen::generateStreetNetwork(so), co);
  }
  Camera cameraAmong() const {
    const gen::AgentPose some = gen::agentPose(crowd, 0, t);
    Camera c;
    c.eye = some.position + Vec3(-7.0f, -5.0f, 2.5f);
    c.at = some.position + Vec3(10.0f, 8.0f, 0.5f);
    c.width = 320;
    c.height = 200;
    c.near_plane = 0.3f;
    c.far_plane = 3000.0f;
    return c;
  }
};

// The frame drawn from the GPU crowd (simulated, culled and classified on the GPU, indirect draws) against the CPU
// path's frame (gen::agentPose per agent, runtime::CrowdRuntime::draw) on the same camera, for each policy.
TEST(GpuCrowdGL, FramesEqualTheCpuPathsOnTheCrowdsPixels) {
  CrowdScene scene;
  runtime::CrowdRuntime& rt = scene.rt;
  gpu::GpuCrowd& gc = scene.gc;
  const std::vector<runtime::CrowdAgentState>& states = scene.states;
  const Camera& camera = scene.camera;
  const gpu::LightSettings light;
  for (runtime::CrowdPolicy policy :
       {runtime::CrowdPolicy::Impostor, runtime::CrowdPolicy::Geometry, runtime::CrowdPolicy::Mixed}) {
    gpu::RenderTarget cpu(camera.width, camera.height), gpu_path(camera.width, camera.height);
    cpu.clear(Vec4(0.5f, 0.6f, 0.7f, 1.0f));
    cpu.bindForOpaquePass();
    const runtime::CrowdFrameStats cs = rt.draw(camera, states, policy, light);
    gpu_path.clear(Vec4(0.5f, 0.6f, 0.7f, 1.0f));
    gpu_path.bindForOpaquePass();
    const runtime::CrowdFrameStats gs = rt.drawGpu(camera, gc, policy, light);
    EXPECT_EQ(gs.draw.draw_calls, 2u * rt.modelCount());
    const image::IdImage a = cpu.readIds(), b = gpu_path.readIds();
    const image::ColorImage ca = cpu.readColor(), cb = gpu_path.readColor();
    size_t crowd_px = 0, same_id = 0, same_colour = 0;
    for (int y = 0; y < camera.height; ++y)
      for (int x = 0; x < camera.width; ++x) {
        if (!(a.at(x, y) & kCrowdIdBit) && !(b.at(x, y) & kCrowdIdBit)) continue;
        ++crowd_px;
        same_id += a.at(x, y) == b.at(x, y) ? 1 : 0;
        same_colour += glm::all(glm::lessThanEqual(glm::abs(glm::ivec4(ca.at(x, y)) - glm::ivec4(cb.at(x, y))),
                                                   glm::ivec4(2)))
                           ? 1
                           : 0;
      }
    std::printf("policy %d: %zu crowd pixels, %zu same agent, %zu same colour; CPU drew %zu geometry, %zu impostors\n",
                int(policy), crowd_px, same_id, same_colour, cs.geometry, cs.impostors);
    EXPECT_GT(crowd_px, 500u);
    if (policy == runtime::CrowdPolicy::Mixed) {  // the camera sees agents of both kinds
      EXPECT_GT(cs.geometry, 0u);
      EXPECT_GT(cs.impostors, 0u);
    }
    EXPECT_GE(double(same_id), 0.995 * double(crowd_px));
    EXPECT_GE(double(same_colour), 0.99 * double(crowd_px));
  }
  // Blended views (the four around each impostor's direction): the same on both paths too, and not the nearest
  // view's frame.
  runtime::CrowdRuntimeOptions blend;
  blend.blend_views = true;
  runtime::CrowdRuntime blended(scene.models.models, scene.models.options, blend);
  gpu::RenderTarget cpu(camera.width, camera.height), gpu_path(camera.width, camera.height),
      nearest(camera.width, camera.height);
  for (gpu::RenderTarget* t : {&cpu, &gpu_path, &nearest}) t->clear(Vec4(0.5f, 0.6f, 0.7f, 1.0f));
  cpu.bindForOpaquePass();
  blended.draw(camera, states, runtime::CrowdPolicy::Impostor, light);
  gpu_path.bindForOpaquePass();
  blended.drawGpu(camera, gc, runtime::CrowdPolicy::Impostor, light);
  nearest.bindForOpaquePass();
  rt.drawGpu(camera, gc, runtime::CrowdPolicy::Impostor, light);
  const double same = image::psnr(cpu.readColor(), gpu_path.readColor());
  const double other = image::psnr(nearest.readColor(), gpu_path.readColor());
  std::printf("blended views: GPU path against the CPU path %.1f dB, against the nearest view's frame %.1f dB\n", same,
              other);
  EXPECT_GT(same, 50.0);
  EXPECT_LT(other, same - 10.0);
}

// Occlusion on the GPU (GpuCrowd::occludeBehind): behind a wall drawn first, the agents the CPU runtime's exact
// test (cullBehind: the depth read back) leaves out are left out, and the frame is unchanged, pixel for pixel and
// id for id.
TEST(GpuCrowdGL, AgentsBehindAWallAreLeftOutAsTheCpuTestLeavesThemOut) {
  CrowdScene scene;
  runtime::CrowdRuntime& rt = scene.rt;
  gpu::GpuCrowd& gc = scene.gc;
  const std::vector<runtime::CrowdAgentState>& states = scene.states;
  const Camera& camera = scene.camera;
  const gen::AgentPose some = gen::agentPose(scene.crowd, 0, scene.t);
  // A wall 14 m along the view, 16 m wide and 6 m tall, facing the camera, hiding the agents behind its middle.
  const Vec3 f = glm::normalize(Vec3(camera.at.x - camera.eye.x, camera.at.y - camera.eye.y, 0.0f));
  const Vec3 side(-f.y, f.x, 0.0f);
  const Vec3 mid = Vec3(camera.eye.x, camera.eye.y, some.position.z) + 14.0f * f;
  const test::GreyQuad wall({mid + 8.0f * side - Vec3(0, 0, 1), mid - 8.0f * side - Vec3(0, 0, 1),
                             mid - 8.0f * side + Vec3(0, 0, 5), mid + 8.0f * side + Vec3(0, 0, 5)},
                            -f, 0.5f);
  gpu::Renderer renderer;
  const gpu::LightSettings light = renderer.light();
  gpu::RenderTarget target(camera.width, camera.height);
  for (runtime::CrowdPolicy policy : {runtime::CrowdPolicy::Impostor, runtime::CrowdPolicy::Mixed}) {
    auto gpuFrame = [&](bool occlude) {
      renderer.render(camera, std::span(&wall.item, 1), target);
      target.bindForOpaquePass();
      rt.drawGpu(camera, gc, policy, light, occlude ? &target : nullptr);
      rt.finish();
      return std::make_pair(target.readColor(), target.readIds());
    };
    const auto with = gpuFrame(true);
    const gpu::GpuCrowd::Counts culled = gc.readCounts();
    const auto without = gpuFrame(false);
    const gpu::GpuCrowd::Counts plain = gc.readCounts();
    EXPECT_EQ(with.first.pixels(), without.first.pixels());
    EXPECT_EQ(with.second.pixels(), without.second.pixels());
    EXPECT_EQ(plain.occluded, 0u);
    EXPECT_EQ(culled.in_view, plain.in_view);
    // The CPU runtime's test on the same frame: the depth read back.
    renderer.render(camera, std::span(&wall.item, 1), target);
    target.bindForOpaquePass();
    rt.cullBehind(target);
    const runtime::CrowdFrameStats cpu = rt.draw(camera, states, policy, light);
    rt.finish();
    std::printf("policy %d: %u in view, %u left out on the GPU, %zu on the CPU\n", int(policy), culled.in_view,
                culled.occluded, cpu.occluded);
    EXPECT_GT(culled.occluded, 20u);
    EXPECT_EQ(culled.in_view, uint32_t(cpu.in_view));
    EXPECT_NEAR(double(culled.occluded), double(cpu.occluded), 0.01 * double(cpu.occluded) + 1.0);
  }
}

// Shadows on the GPU path (drawGpuShadowed): the agents darken the ground, where the CPU path's shadows fall (its
// map is fitted to the casters it knows, the GPU path's to the receivers: their texels differ, so edges do).
TEST(GpuCrowdGL, ShadowsFallWhereTheCpuPathsFall) {
  CrowdScene scene;
  const Vec3 c = scene.camera.eye;
  const float z = gen::agentPose(scene.crowd, 0, scene.t).position.z;
  const test::GreyQuad ground({Vec3(c.x - 300, c.y - 300, z), Vec3(c.x + 300, c.y - 300, z),
                               Vec3(c.x + 300, c.y + 300, z), Vec3(c.x - 300, c.y + 300, z)},
                              Vec3(0, 0, 1), 0.7f);
  gpu::Renderer renderer;
  gpu::LightSettings light = renderer.light();
  gpu::RenderTarget target(scene.camera.width, scene.camera.height);
  const runtime::CrowdShadowOptions shadows;
  auto frame = [&](int kind) {  // 0: GPU, no shadows; 1: GPU shadowed; 2: CPU shadowed
    renderer.render(scene.camera, std::span(&ground.item, 1), target);
    target.bindForOpaquePass();
    if (kind == 0) scene.rt.drawGpu(scene.camera, scene.gc, runtime::CrowdPolicy::Mixed, light);
    if (kind == 1)
      scene.rt.drawGpuShadowed(scene.camera, scene.gc, runtime::CrowdPolicy::Mixed, light, target, shadows);
    if (kind == 2)
      scene.rt.drawShadowed(scene.camera, scene.states, runtime::CrowdPolicy::Mixed, light, target, shadows);
    scene.rt.finish();
    return std::make_pair(target.readColor(), target.readIds());
  };
  const auto plain = frame(0), gpu_shadowed = frame(1);
  const std::vector<gpu::GpuCrowdCommand> commands = scene.gc.readCommands();
  uint32_t casters = 0;
  for (size_t m = 0; m < scene.gc.modelCount(); ++m)
    casters += commands[scene.gc.casterList(m, false)].instance_count +
               commands[scene.gc.casterList(m, true)].instance_count;
  const auto cpu_shadowed = frame(2);
  size_t ground_px = 0, gpu_dark = 0, cpu_dark = 0, both_dark = 0;
  for (int y = 0; y < scene.camera.height; ++y)
    for (int x = 0; x < scene.camera.width; ++x) {
      if ((plain.second.at(x, y) & kCrowdIdBit) || (cpu_shadowed.second.at(x, y) & kCrowdIdBit) ||
          plain.second.at(x, y) == 0)
        continue;
      ++ground_px;
      const int base = plain.first.at(x, y).g;
      const bool g = gpu_shadowed.first.at(x, y).g + 8 < base, k = cpu_shadowed.first.at(x, y).g + 8 < base;
      gpu_dark += g, cpu_dark += k, both_dark += g && k;
    }
  std::printf("shadows: %u casters on the GPU, %zu ground pixels, %zu darkened by the GPU path, %zu by the CPU's, "
              "%zu by both\n", casters, ground_px, gpu_dark, cpu_dark, both_dark);
  EXPECT_GT(casters, 0u);
  EXPECT_GT(cpu_dark, 50u);
  EXPECT_GE(double(both_dark), 0.95 * double(cpu_dark));  // nearly every CPU shadow pixel is a GPU one
  // The GPU path's map spans every receiver, so its texels are coarser (2.5x here) and its shadows a little wider.
  EXPECT_GE(double(both_dark), 0.7 * double(gpu_dark));
}

// The viewer's loop, frame after frame: the crowd simulated, then classified and drawn. The simulation follows the
// last frame's draws of the lists with no barrier before it, which is right because it writes the poses and phases
// alone. The barrier check follows what a shader declares it may write (gpu/gl_barrier_check.h), and until the check
// reached the viewer's window the simulation declared the lists writable too (unused there: no frame was wrong, but
// the check saw a write after the draws' reads and could not tell).
TEST(GpuCrowdGL, TheNextFramesSimulationFollowsTheLastFramesDrawsWithoutAHazard) {
  gpu::sharedHeadlessContext().makeCurrent();
  if (!gpu::installGlCounters() || !gpu::setGlBarrierCheck(true))
    GTEST_SKIP() << "GL counters unavailable (FF_GL_COUNTERS=0 or no EGL context)";
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  gpu::clearGlBarrierHazards();
  CrowdScene scene;  // its programs compiled with the check on
  const gpu::LightSettings light;
  gpu::RenderTarget target(scene.camera.width, scene.camera.height);
  for (int f = 0; f < 3; ++f) {
    scene.gc.simulate(scene.t + 0.1f * float(f));
    target.bindForOpaquePass();
    scene.rt.drawGpu(scene.camera, scene.gc, runtime::CrowdPolicy::Mixed, light);
  }
  EXPECT_EQ(gpu::glBarrierCheckCounts().unknown_program, 0u);
  EXPECT_GE(gpu::glBarrierCheckCounts().checked, 3u * 3u);
  for (const gpu::GlBarrierHazard& h : gpu::glBarrierHazards())
    ADD_FAILURE() << h.message << " (" << h.count << " calls)";
}

// Mixed's budget in milliseconds on the GPU path: the skinned draws are timed and their triangles copied, both read
// frames later, with no wait counted in the frame; the budget in triangles follows the measured cost. A budget of a
// millionth of a millisecond turns every skinned agent into an impostor once a frame has been measured (10,000
// triangles before, TriangleRate's start); a budget of a thousand seconds keeps the agents the unbudgeted frame draws.
TEST(GpuCrowdGL, TheBudgetInMillisecondsFollowsTheMeasuredSkinnedDraws) {
  CrowdScene scene;
  gpu::installGlCounters();
  const gpu::LightSettings light;
  gpu::RenderTarget target(scene.camera.width, scene.camera.height);
  auto geometryAgents = [&] {
    uint64_t n = 0;
    const std::vector<gpu::GpuCrowdCommand> commands = scene.gc.readCommands();
    for (size_t m = 0; m < scene.rt.modelCount(); ++m) n += commands[2 * m].instance_count;
    return n;
  };
  target.bindForOpaquePass();
  scene.rt.drawGpu(scene.camera, scene.gc, runtime::CrowdPolicy::Mixed, light);
  const uint64_t unbudgeted = geometryAgents();
  ASSERT_GT(unbudgeted, 0u) << "the camera sees skinned agents";
  for (double ms : {1e-6, 1e6}) {
    runtime::CrowdRuntimeOptions o;
    o.geometry_ms = ms;
    runtime::CrowdRuntime rt(scene.models.models, scene.models.options, o);
    for (int f = 0; f < 5; ++f) {
      target.bindForOpaquePass();
      const gpu::GlCounters before = gpu::glCounters();
      const runtime::CrowdFrameStats stats = rt.drawGpu(scene.camera, scene.gc, runtime::CrowdPolicy::Mixed, light);
      const gpu::GlCounters used = gpu::glCounters() - before;
      if (gpu::glCountersInstalled()) {
        EXPECT_EQ(used.syncs, 0u) << "frame " << f;
      }
      if (f == 0) {
        EXPECT_EQ(stats.budget_triangles, 10000u) << "no measurement yet";
      }
      const uint64_t drawn = geometryAgents();
      std::printf("budget %g ms, frame %d: %llu triangles allowed, %llu skinned agents (unbudgeted %llu), last "
                  "measured %.3f ms\n", ms, f, (unsigned long long)stats.budget_triangles, (unsigned long long)drawn,
                  (unsigned long long)unbudgeted, stats.geometry_ms);
      rt.finish();
      if (f < 2) continue;  // measured frames arrive from the first one on
      EXPECT_GT(rt.msPerSkinnedTriangle(), 0.0) << "frame " << f;
      if (ms < 1.0) {
        EXPECT_EQ(stats.budget_triangles, 1u) << "frame " << f;
        EXPECT_EQ(drawn, 0u) << "frame " << f;
      } else {
        EXPECT_GT(stats.budget_triangles, 1'000'000u) << "frame " << f;
        EXPECT_EQ(drawn, unbudgeted) << "frame " << f;
      }
    }
    EXPECT_GT(rt.collectGpuGeometryMs(scene.gc), 0.0);
  }
}

// Under a geometry budget the casters are cast as the camera draws them (runtime::CrowdRuntime::castsAsImpostor):
// an agent the budget turned into an impostor casts as one, so every agent casting as geometry is drawn as geometry.
TEST(GpuCrowdGL, UnderABudgetAgentsCastAsTheyAreDrawn) {
  CrowdScene scene;
  runtime::CrowdRuntimeOptions o;
  o.max_geometry_triangles = 2000;  // about 4 of the agents inside their switch
  runtime::CrowdRuntime rt(scene.models.models, scene.models.options, o);
  const gpu::LightSettings light;
  gpu::RenderTarget target(scene.camera.width, scene.camera.height);
  target.clear(Vec4(0.5f, 0.6f, 0.7f, 1.0f));
  rt.drawGpuShadowed(scene.camera, scene.gc, runtime::CrowdPolicy::Mixed, light, target);
  rt.finish();
  std::set<uint32_t> drawn_geometry, cast_geometry;
  size_t cast_impostors = 0;
  for (size_t m = 0; m < scene.gc.modelCount(); ++m) {
    for (uint32_t id : scene.gc.readList(2 * m)) drawn_geometry.insert(id);
    for (uint32_t id : scene.gc.readList(scene.gc.casterList(m, false))) cast_geometry.insert(id);
    cast_impostors += scene.gc.readList(scene.gc.casterList(m, true)).size();
  }
  const gpu::GpuCrowd::Counts counts = scene.gc.readCounts();
  std::printf("%zu drawn as geometry, %u over the budget; %zu cast as geometry, %zu as impostors\n",
              drawn_geometry.size(), counts.over_budget, cast_geometry.size(), cast_impostors);
  ASSERT_GT(counts.over_budget, 0u) << "the budget binds";
  EXPECT_GT(cast_geometry.size(), 0u);
  EXPECT_GT(cast_impostors, 0u);
  for (uint32_t id : cast_geometry) EXPECT_TRUE(drawn_geometry.count(id)) << "agent " << id << " casts as geometry";
}

// Levels of detail on the GPU path (GpuCrowd::setLevelScale, from the runtime's geometry_lod_px): each skinned agent
// at the level the CPU path's levelFor gives it, each level drawn by its own command, and the frames equal on the
// crowd's pixels.
TEST(GpuCrowdGL, LevelsOfDetailAreTheCpuPathsLevels) {
  CrowdScene scene;
  runtime::CrowdRuntimeOptions o;
  o.geometry_lod_px = 1.0;
  runtime::CrowdRuntime rt(scene.models.models, scene.models.options, o);
  gpu::GpuCrowd gc(gpuCrowdRoutes(scene.crowd), gpuCrowdAgents(scene.crowd, kCrowdIdBit),
                   rt.gpuCrowdModels(kCrowdNominalSpeed));
  gc.simulate(scene.t);
  const std::vector<runtime::CrowdAgentState> states = crowdAgentStates(scene.crowd, rt, scene.t);
  const Camera& camera = scene.camera;
  const gpu::LightSettings light;
  gpu::RenderTarget cpu(camera.width, camera.height), gpu_path(camera.width, camera.height);
  cpu.clear(Vec4(0.5f, 0.6f, 0.7f, 1.0f));
  cpu.bindForOpaquePass();
  rt.draw(camera, states, runtime::CrowdPolicy::Mixed, light);
  gpu_path.clear(Vec4(0.5f, 0.6f, 0.7f, 1.0f));
  gpu_path.bindForOpaquePass();
  const runtime::CrowdFrameStats gs = rt.drawGpu(camera, gc, runtime::CrowdPolicy::Mixed, light);
  size_t coarser = 0, levels_drawn = 0;
  for (size_t m = 0; m < rt.modelCount(); ++m) {
    ASSERT_EQ(gc.levelCount(m), rt.levelDistances(m).size());
    for (size_t l = 0; l < gc.levelCount(m); ++l) {
      std::set<uint32_t> on_gpu, on_cpu;
      for (uint32_t id : gc.readLevelList(m, l)) on_gpu.insert(id);
      for (size_t i = 0; i < states.size(); ++i)
        if (states[i].model == m && rt.drawnLevel(i) == int(l)) on_cpu.insert(states[i].object_id);
      EXPECT_EQ(on_gpu, on_cpu) << "model " << m << " level " << l;
      coarser += l > 0 ? on_gpu.size() : 0;
      levels_drawn += on_gpu.empty() ? 0 : 1;
    }
  }
  EXPECT_GT(coarser, 0u) << "the view needs agents at coarser levels";
  EXPECT_GE(levels_drawn, 3u);
  EXPECT_EQ(gc.readCounts().level_overflow, 0u);
  size_t draws = 0;
  for (size_t m = 0; m < rt.modelCount(); ++m) draws += gc.levelCount(m) + 1;
  EXPECT_EQ(gs.draw.draw_calls, draws) << "a draw per level and model, one per model for the impostors";
  const image::IdImage a = cpu.readIds(), b = gpu_path.readIds();
  size_t crowd_px = 0, same = 0;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      if (!(a.at(x, y) & kCrowdIdBit) && !(b.at(x, y) & kCrowdIdBit)) continue;
      ++crowd_px;
      same += a.at(x, y) == b.at(x, y) ? 1 : 0;
    }
  std::printf("%zu agents at coarser levels, %zu levels drawn; %zu crowd pixels, %zu the same agent\n", coarser,
              levels_drawn, crowd_px, same);
  EXPECT_GT(crowd_px, 500u);
  EXPECT_GE(double(same), 0.999 * double(crowd_px));

  // With shadows: an agent casting as geometry casts at the level it is drawn at.
  gpu_path.clear(Vec4(0.5f, 0.6f, 0.7f, 1.0f));
  rt.drawGpuShadowed(camera, gc, runtime::CrowdPolicy::Mixed, light, gpu_path);
  std::map<uint32_t, size_t> drawn_level;
  for (size_t m = 0; m < rt.modelCount(); ++m)
    for (size_t l = 0; l < gc.levelCount(m); ++l)
      for (uint32_t id : gc.readLevelList(m, l)) drawn_level[id] = l;
  size_t cast_drawn = 0, cast_coarser = 0;
  for (size_t m = 0; m < rt.modelCount(); ++m)
    for (size_t l = 0; l < gc.levelCount(m); ++l)
      for (uint32_t id : gc.readLevelList(m, l, true)) {
        const auto it = drawn_level.find(id);
        if (it == drawn_level.end()) continue;  // cast, not in view
        ++cast_drawn;
        cast_coarser += l > 0 ? 1 : 0;
        EXPECT_EQ(it->second, l) << "agent " << id << " casts at another level than it is drawn at";
      }
  std::printf("%zu drawn agents cast as geometry, %zu of them at coarser levels\n", cast_drawn, cast_coarser);
  EXPECT_GT(cast_coarser, 0u);

  // Under a budget of half the skinned triangles, the budget counts each agent's level's triangles.
  auto levelTriangles = [&] {
    uint64_t t = 0;
    for (size_t m = 0; m < rt.modelCount(); ++m)
      for (size_t l = 0; l < gc.levelCount(m); ++l)
        t += gc.readLevelList(m, l).size() * rt.gpuModel(m).triangleCount(l);
    return t;
  };
  const uint64_t unbudgeted = levelTriangles();
  runtime::CrowdRuntimeOptions ob = o;
  ob.max_geometry_triangles = unbudgeted / 2;
  runtime::CrowdRuntime budgeted(scene.models.models, scene.models.options, ob);
  gpu_path.bindForOpaquePass();
  budgeted.drawGpu(camera, gc, runtime::CrowdPolicy::Mixed, light);
  const uint64_t kept = levelTriangles();
  const gpu::GpuCrowd::Counts counts = gc.readCounts();
  std::printf("budget %llu of %llu triangles: %llu kept, %u agents over it\n",
              (unsigned long long)ob.max_geometry_triangles, (unsigned long long)unbudgeted, (unsigned long long)kept,
              counts.over_budget);
  EXPECT_GT(counts.over_budget, 0u);
  EXPECT_LE(kept, ob.max_geometry_triangles);
  EXPECT_EQ(uint64_t(counts.budget_triangles_kept), kept);
  EXPECT_EQ(uint64_t(counts.budget_triangles_wanted), unbudgeted);
}

}  // namespace
}  // namespace farfield::eval
