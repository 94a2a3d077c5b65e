// The GPU crowd's compute passes (gpu/gpu_crowd.h; issue 45) against CPU brute force on generated crowds: every
// agent's pose and phase against gen::agentPose, the culled, classified lists and the geometry budget against the
// same rules evaluated on the CPU for random cameras, and bad input. Needs a GL context (llvmpipe is enough).
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <random>
#include <set>
#include <span>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/core/error.h"
#include "farfield/core/math.h"
#include "farfield/eval/gpu_crowd_input.h"
#include "farfield/gen/street_network.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/gl_barrier_check.h"
#include "farfield/gpu/gl_counters.h"

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
        const float expected =
            std::fmod(crowd.agents[i].phase + p.walked / models[crowd.agents[i].model].stride_m, 1.0f);
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

// Every pass's writes are followed by the barrier their readers need (gpu/gl_barrier_check.h): the classification's
// storage reads of the simulation, the draws' indirect commands, the next frame's reset copy and clear, the late
// readback of the commands and the counts read after a frame; under a budget, with levels of detail and shadow
// casters, frame after frame. (llvmpipe finishes all work at any barrier: a missing bit changes nothing here.)
TEST(GpuCrowdGL, EveryPassWriteIsFollowedByTheBarrierItsReadersNeed) {
  gpu::sharedHeadlessContext().makeCurrent();
  if (!gpu::installGlCounters() || !gpu::setGlBarrierCheck(true))
    GTEST_SKIP() << "GL counters unavailable (FF_GL_COUNTERS=0 or no EGL context)";
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  gpu::clearGlBarrierHazards();
  const gen::Crowd crowd = testCrowd(3000, false);
  const std::vector<gpu::GpuCrowdModel> models = testModels();
  gpu::GpuCrowd gc(gpuCrowdRoutes(crowd), gpuCrowdAgents(crowd), models);  // compiled with the check on
  gc.setGeometryBudget(12000);
  gc.setLevelScale(0.002f);
  const std::vector<float> switches{45.0f, 35.0f};
  gc.simulate(0.0f);
  const std::vector<Vec4> start = gc.readPoses();
  size_t listed = 0;
  for (uint64_t frame = 0; frame < 4; ++frame) {
    const Vec4 p = start[frame * 700];
    const Vec3 eye = Vec3(p) + Vec3(0.0f, 0.0f, 1.7f + 10.0f * float(frame % 2));
    const Camera c = crowdCamera(eye, eye + Vec3(std::cos(p.w), std::sin(p.w), -0.2f));
    gc.simulate(0.5f * float(frame));
    gc.castShadows(c, switches, c.viewProjection(), 120.0f, 60.0f, Vec3(0.3f, 0.2f, 1.0f));
    gc.cullAndClassify(c, switches);
    gc.captureCommands(frame);
    const gpu::GpuCrowd::Counts counts = gc.readCounts();
    listed += counts.in_view;
  }
  glFinish();
  size_t captured = 0;
  gc.finishedCommands([&](uint64_t, std::span<const gpu::GpuCrowdCommand> commands) { captured += !commands.empty(); });
  EXPECT_GT(listed, 0u);
  EXPECT_GT(captured, 0u);
  EXPECT_GE(gpu::glBarrierCheckCounts().checked, 4u * 5u);
  EXPECT_EQ(gpu::glBarrierCheckCounts().unknown_program, 0u);
  for (const gpu::GlBarrierHazard& h : gpu::glBarrierHazards())
    ADD_FAILURE() << h.message << " (" << h.count << " calls)";
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
