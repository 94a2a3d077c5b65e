// The GPU crowd (gpu/gpu_crowd.h; issue 45) against CPU brute force on generated crowds: every agent's pose and
// phase against gen::agentPose, and the culled, classified lists against the same rule evaluated on the CPU for
// random cameras. Needs a GL context (llvmpipe is enough).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <span>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/eval/crowd_metrics.h"
#include "farfield/eval/crowd_walk.h"
#include "farfield/eval/gpu_crowd_input.h"
#include "farfield/gen/street_network.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/gl_counters.h"
#include "farfield/gpu/render_target.h"
#include "farfield/image/metrics.h"
#include "farfield/runtime/crowd_runtime.h"
#include "runtime/grey_quad.h"

namespace farfield::eval {
namespace {

gen::Crowd testCrowd(size_t agents, bool sloped) {
  gen::StreetNetworkOptions so;
  so.blocks = 40;
  so.seed = 12;
  const urban::StreetGraph streets = gen::generateStreetNetwork(so);
  gen::CrowdOptions o;
  o.agents = agents;
  o.seed = 77;
  // A plane: the GPU interpolates the ground between the loop's points, exactly on a plane.
  if (sloped) o.ground_height = [](float x, float y) { return 0.03f * x - 0.02f * y + 5.0f; };
  return gen::generateCrowd(streets, o);
}

std::vector<gpu::GpuCrowdModel> testModels() {
  gpu::GpuCrowdModel a, b;
  a.centre = Vec3(0.0f, 0.0f, 0.9f);
  a.radius = 1.0f;
  a.stride_m = 1.4f;
  a.geometry_indices = 3000;
  b.centre = Vec3(0.3f, 0.0f, 0.5f);
  b.radius = 0.8f;
  b.stride_m = 0.9f;
  b.geometry_indices = 1500;
  return {a, b};
}

// A 640 x 360 camera over the test crowd.
Camera crowdCamera(const Vec3& eye, const Vec3& at) {
  Camera c;
  c.eye = eye;
  c.at = at;
  c.width = 640;
  c.height = 360;
  c.near_plane = 0.5f;
  c.far_plane = 5000.0f;
  return c;
}

// The runtime's bounding-sphere centre of an agent at a GPU pose: the model's centre turned by the heading, about the
// feet, in double precision.
DVec3 agentCentre(const Vec4& pose, const gpu::GpuCrowdModel& m) {
  const double h = pose.w;
  return DVec3(Vec3(pose)) + DVec3(std::cos(h) * m.centre.x - std::sin(h) * m.centre.y,
                                   std::sin(h) * m.centre.x + std::cos(h) * m.centre.y, m.centre.z);
}

// One frame of the GPU crowd, simulated to t and classified for the camera: the GL work it asked for.
gpu::GlCounters classifyCounted(gpu::GpuCrowd& gc, float t, const Camera& c, std::span<const float> switches) {
  const gpu::GlCounters before = gpu::glCounters();
  gc.simulate(t);
  gc.cullAndClassify(c, switches);
  return gpu::glCounters() - before;
}

float angleDifference(float a, float b) {
  const float d = std::fmod(std::abs(a - b), float(2.0 * kPi));
  return std::min(d, float(2.0 * kPi) - d);
}

TEST(GpuCrowdGL, PosesAndPhasesEqualTheCpuSimulation) {
  gpu::sharedHeadlessContext().makeCurrent();
  for (bool sloped : {false, true}) {
    const gen::Crowd crowd = testCrowd(5000, sloped);
    const std::vector<gpu::GpuCrowdModel> models = testModels();
    gpu::GpuCrowd gc(gpuCrowdRoutes(crowd), gpuCrowdAgents(crowd), models);
    for (float t : {0.0f, 3.7f, 125.25f}) {
      gc.simulate(t);
      const std::vector<Vec4> poses = gc.readPoses();
      const std::vector<float> phases = gc.readPhases();
      double worst_m = 0.0, worst_rad = 0.0, worst_phase = 0.0;
      for (size_t i = 0; i < crowd.agents.size(); ++i) {
        const gen::AgentPose p = gen::agentPose(crowd, i, t);
        worst_m = std::max(worst_m, double(glm::length(Vec3(poses[i]) - p.position)));
        worst_rad = std::max(worst_rad, double(angleDifference(poses[i].w, p.heading)));
        const float expected = std::fmod(crowd.agents[i].phase + p.walked / models[crowd.agents[i].model].stride_m, 1.0f);
        const float dp = std::abs(phases[i] - expected);
        worst_phase = std::max(worst_phase, double(std::min(dp, 1.0f - dp)));
      }
      EXPECT_LT(worst_m, 2e-3) << "t " << t << (sloped ? " sloped" : "");
      EXPECT_LT(worst_rad, 1e-3) << "t " << t;
      EXPECT_LT(worst_phase, 1e-3) << "t " << t;
    }
  }
}

TEST(GpuCrowdGL, CullingAndClassificationEqualACpuBruteForce) {
  gpu::sharedHeadlessContext().makeCurrent();
  gpu::installGlCounters();
  const gen::Crowd crowd = testCrowd(20000, false);
  const std::vector<gpu::GpuCrowdModel> models = testModels();
  gpu::GpuCrowd gc(gpuCrowdRoutes(crowd), gpuCrowdAgents(crowd), models);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Vec2 lo(1e30f), hi(-1e30f);
  for (const gen::SidewalkRoute& r : crowd.routes)
    for (const Vec2& p : r.loop) lo = glm::min(lo, p), hi = glm::max(hi, p);
  size_t geometry = 0, impostors = 0;
  for (int trial = 0; trial < 6; ++trial) {
    const Vec3 eye(lo.x + u(rng) * (hi.x - lo.x), lo.y + u(rng) * (hi.y - lo.y), 1.7f + 60.0f * u(rng));
    const Camera c = crowdCamera(eye, Vec3(lo.x + u(rng) * (hi.x - lo.x), lo.y + u(rng) * (hi.y - lo.y), 0.0f));
    const std::vector<float> switches{20.0f + 30.0f * u(rng), 10.0f + 20.0f * u(rng)};
    const float t = 10.0f * u(rng);
    const gpu::GlCounters frame = classifyCounted(gc, t, c, switches);
    if (gpu::glCountersInstalled()) {
      EXPECT_EQ(frame.syncs, 0u) << "nothing in the frame waits for the GPU";
      EXPECT_LT(frame.upload_bytes, 512u) << "only a few uniforms are sent";
      EXPECT_EQ(frame.dispatches, 2u);
    }
    // The CPU brute force, on the GPU's poses: the same sphere, planes and switch, in double precision.
    const std::vector<Vec4> poses = gc.readPoses();
    Frustum f = Frustum::fromMatrix(c.viewProjection());
    for (Vec4& p : f.planes) p /= glm::length(Vec3(p));
    std::vector<std::set<uint32_t>> expected(2 * models.size()), near_threshold(2 * models.size());
    for (size_t i = 0; i < crowd.agents.size(); ++i) {
      const gpu::GpuCrowdModel& m = models[crowd.agents[i].model];
      const DVec3 centre = agentCentre(poses[i], m);
      const double radius = m.radius;
      bool inside = true, borderline = false;
      for (const Vec4& p : f.planes) {
        const double d = glm::dot(DVec3(Vec3(p)), centre) + double(p.w) + radius;
        if (d < 0.0) inside = false;
        if (std::abs(d) < 1e-3) borderline = true;
      }
      const double dist = glm::length(DVec3(c.eye) - centre);
      const size_t list = 2 * crowd.agents[i].model + (dist < switches[crowd.agents[i].model] ? 0 : 1);
      if (std::abs(dist - switches[crowd.agents[i].model]) < 1e-3) borderline = true;
      if (borderline) {
        near_threshold[list].insert(uint32_t(i));
        near_threshold[list ^ 1].insert(uint32_t(i));
        continue;
      }
      if (inside) expected[list].insert(uint32_t(i));
    }
    const std::vector<gpu::GpuCrowdCommand> commands = gc.readCommands();
    for (size_t list = 0; list < expected.size(); ++list) {
      const std::vector<uint32_t> got = gc.readList(list);
      EXPECT_EQ(commands[list].count, list % 2 ? 4u : models[list / 2].geometry_indices);
      EXPECT_EQ(size_t(commands[list].instance_count), got.size());
      std::set<uint32_t> got_set(got.begin(), got.end());
      EXPECT_EQ(got_set.size(), got.size()) << "an agent listed twice";
      for (uint32_t i : near_threshold[list]) got_set.erase(i);
      EXPECT_EQ(got_set, expected[list]) << "trial " << trial << " list " << list;
      (list % 2 ? impostors : geometry) += got.size();
    }
  }
  EXPECT_GT(geometry, 0u);  // the cameras saw both kinds
  EXPECT_GT(impostors, 0u);
}

// Mixed's geometry budget on the GPU (GpuCrowd::setGeometryBudget) against a CPU brute force on the same poses: the
// skinned triangles stay within the budget, the agents kept as geometry are the nearest of those inside their switch
// (up to the distance bucket at the cut), the others inside their switch become impostors, and the frame still waits
// for nothing.
TEST(GpuCrowdGL, TheGeometryBudgetKeepsTheNearestAgentsAsGeometry) {
  gpu::sharedHeadlessContext().makeCurrent();
  gpu::installGlCounters();
  const gen::Crowd crowd = testCrowd(20000, false);
  const std::vector<gpu::GpuCrowdModel> models = testModels();
  gpu::GpuCrowd gc(gpuCrowdRoutes(crowd), gpuCrowdAgents(crowd), models);
  const float t = 3.0f;
  gc.simulate(t);
  const std::vector<Vec4> start = gc.readPoses();
  const std::vector<float> switches{45.0f, 35.0f};
  const double bucket_m = 45.0 / gpu::GpuCrowd::kBudgetBuckets;
  size_t tried = 0;
  for (size_t k = 0; k < 4; ++k) {
    // A pedestrian's eye among the agents, looking along the street.
    const Vec4 p = start[k * 4999];
    const Vec3 eye = Vec3(p) + Vec3(0.0f, 0.0f, 1.7f);
    const Camera c = crowdCamera(eye, eye + Vec3(std::cos(p.w), std::sin(p.w), -0.05f));
    const uint64_t budget = 20000 + 15000 * k;
    gc.setGeometryBudget(budget);
    const gpu::GlCounters frame = classifyCounted(gc, t, c, switches);
    if (gpu::glCountersInstalled()) {
      EXPECT_EQ(frame.syncs, 0u) << "nothing in the frame waits for the GPU";
      EXPECT_EQ(frame.dispatches, 4u) << "simulate, classify, the budget's scan and assignment";
    }
    const std::vector<Vec4> poses = gc.readPoses();
    auto distanceOf = [&](uint32_t i) {
      return glm::length(DVec3(c.eye) - agentCentre(poses[i], models[crowd.agents[i].model]));
    };
    auto trianglesOf = [&](uint32_t i) { return uint64_t(models[crowd.agents[i].model].geometry_indices / 3); };
    // The GPU's lists (ids are the agents' indices here).
    uint64_t kept = 0;
    double farthest_geometry = 0.0, nearest_over = 1e30;
    size_t over = 0;
    std::vector<std::pair<double, uint32_t>> candidates;  // inside their switch, in view: what the budget ranks
    for (size_t m = 0; m < models.size(); ++m) {
      for (uint32_t i : gc.readList(2 * m)) {
        kept += trianglesOf(i);
        farthest_geometry = std::max(farthest_geometry, distanceOf(i));
        candidates.emplace_back(distanceOf(i), i);
      }
      for (uint32_t i : gc.readList(2 * m + 1))
        if (distanceOf(i) < switches[m] - 1e-3) {
          ++over;
          nearest_over = std::min(nearest_over, distanceOf(i));
          candidates.emplace_back(distanceOf(i), i);
        }
    }
    const gpu::GpuCrowd::Counts counts = gc.readCounts();
    if (over == 0) continue;  // the budget held every candidate: nothing to rank here
    ++tried;
    EXPECT_LE(kept, budget);
    EXPECT_EQ(uint64_t(counts.budget_triangles_kept), kept);
    EXPECT_EQ(size_t(counts.over_budget), over);
    EXPECT_LT(farthest_geometry, nearest_over + bucket_m) << "a farther agent kept its geometry";
    // The CPU's cut: the nearest candidates whose triangles fit. The GPU keeps as much, less the agents within a
    // bucket of the cut (they go together).
    std::sort(candidates.begin(), candidates.end());
    uint64_t cpu_kept = 0;
    double cut = 1e30;
    for (const auto& [d, i] : candidates) {
      if (cpu_kept + trianglesOf(i) > budget) {
        cut = d;
        break;
      }
      cpu_kept += trianglesOf(i);
    }
    uint64_t near_cut = 0;
    for (const auto& [d, i] : candidates)
      if (d >= cut - 2.0 * bucket_m && d < cut) near_cut += trianglesOf(i);
    EXPECT_GE(kept + near_cut, cpu_kept) << "trial " << k;
    std::printf("budget %llu: %llu triangles kept (the CPU's exact cut %llu), %zu agents over it\n",
                (unsigned long long)budget, (unsigned long long)kept, (unsigned long long)cpu_kept, over);
  }
  EXPECT_GE(tried, 2u) << "the test needs views where the budget binds";
}


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
    casters += commands[scene.gc.casterList(m, false)].instance_count + commands[scene.gc.casterList(m, true)].instance_count;
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

TEST(GpuCrowdGL, BadInputIsAnError) {
  gpu::sharedHeadlessContext().makeCurrent();
  const gen::Crowd crowd = testCrowd(10, false);
  const std::vector<gpu::GpuCrowdRoute> routes = gpuCrowdRoutes(crowd);
  std::vector<gpu::GpuCrowdAgent> agents = gpuCrowdAgents(crowd);
  const std::vector<gpu::GpuCrowdModel> models = testModels();
  EXPECT_THROW(gpu::GpuCrowd(routes, {}, models), Error);
  EXPECT_THROW(gpu::GpuCrowd(routes, agents, {}), Error);
  agents[3].model = 7;
  EXPECT_THROW(gpu::GpuCrowd(routes, agents, models), Error);
  agents = gpuCrowdAgents(crowd);
  gpu::GpuCrowd gc(routes, agents, models);
  Camera c;
  c.eye = Vec3(0, 0, 10);
  c.at = Vec3(10, 10, 0);
  EXPECT_THROW(gc.cullAndClassify(c, std::vector<float>{1.0f}), Error);  // one switch for two models
}

}  // namespace
}  // namespace farfield::eval
