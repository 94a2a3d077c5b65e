// A crowd simulated, culled and classified on the GPU (issue 45, first part): the agents, their sidewalk loops and
// their models live in GPU buffers, uploaded once. Per frame, two compute dispatches and no upload but a few
// uniforms: the first advances every agent to time t along its loop (gen::agentPose's arithmetic, in
// crowd_sim.comp.glsl) and its walk-cycle phase; the second culls each agent against the camera's frustum and
// classifies it by its model's switch distance (geometry nearer, impostor farther: the switch the CPU runtime takes
// from Dobbyn's texel rule and the view error bound, runtime::CrowdRuntime::switchDistances), appending its index to
// one of two lists per model. Each list has an indirect draw command whose instance count the pass increments, so the
// lists are drawn with glMultiDrawElementsIndirect and nothing is read back.
//
// Plain data in (no gen or runtime types): eval converts a gen::Crowd (eval/gpu_crowd_input.h).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/core/math.h"
#include "farfield/gpu/gpu_depth_pyramid.h"
#include "farfield/gpu/late_readback.h"
#include "farfield/gpu/program.h"
#include "farfield/gpu/render_target.h"

namespace farfield::gpu {

struct GpuCrowdRoute {
  std::vector<Vec2> loop;       // the sidewalk loop's points, counter-clockwise
  std::vector<float> distance;  // arc length at each point (distance[0] = 0)
  std::vector<float> ground;    // ground height at each point (empty: 0)
  float length = 0.0f;
};

struct GpuCrowdAgent {
  uint32_t route = 0, model = 0, outfit = 0;
  uint32_t id = 0;         // its object id (the id buffer's)
  float start = 0.0f, speed = 1.2f;
  float direction = 1.0f;  // +1 counter-clockwise, -1 clockwise
  float phase = 0.0f;      // animation phase at t = 0
  Vec4 tint{1.0f};
};

struct GpuCrowdModel {
  Vec3 centre{0.0f, 0.0f, 0.9f};  // bounding sphere in agent space (feet at the origin, facing +x, z up), turned
  float radius = 1.0f;            // with the agent's heading (runtime::CrowdRuntime's)
  float stride_m = 1.3f;          // metres walked over one animation cycle
  uint32_t palette_poses = 64;    // geometry records: the palette pose nearest the phase
  uint32_t frames = 16;           // impostor records: the atlas frame nearest the phase, and the view nearest the
  uint32_t azimuths = 32;         // eye's direction on an azimuths x elevations grid up to max_elevation (not
  uint32_t elevations = 8;        // octahedral: impostor::nearestView)
  float max_elevation = 1.5707964f;
  // The lists' draw commands: the geometry's indexed draw (index count and first index of the mesh), the
  // impostors' 4-vertex strip (a DrawArraysIndirectCommand in the same 20-byte slot).
  uint32_t geometry_indices = 0, geometry_first_index = 0;
  // Levels of detail after the mesh (level 0), at most GpuCrowd::kMaxLevels - 1: each one's index range in the same
  // index buffer and its error (agent metres, increasing: runtime::CrowdRuntime::levelDistances, its distance to
  // the mesh or the larger of that and its texture deviation), as runtime::CrowdRuntime's levels.
  struct Level {
    uint32_t indices = 0, first_index = 0;
    float distance_m = 0.0f;
  };
  std::vector<Level> levels;
};

// The indirect draw command of a list (GL's DrawElementsIndirectCommand).
struct GpuCrowdCommand {
  uint32_t count = 0, instance_count = 0, first_index = 0;
  int32_t base_vertex = 0;
  uint32_t base_instance = 0;
};

class GpuCrowd {
 public:
  static constexpr int kMaxModels = 16;
  static constexpr int kMaxLevels = 8;  // levels of detail per model, the mesh included
  // Needs a current context. Throws farfield::Error for no agents, an agent naming a missing route or model, a route
  // of fewer than 2 points or mismatched arrays, more than kMaxModels models.
  GpuCrowd(std::span<const GpuCrowdRoute> routes, std::span<const GpuCrowdAgent> agents,
           std::span<const GpuCrowdModel> models);
  ~GpuCrowd();
  GpuCrowd(const GpuCrowd&) = delete;
  GpuCrowd& operator=(const GpuCrowd&) = delete;

  // Every agent's pose and phase at time t (seconds): one dispatch.
  void simulate(float t);
  // The agents in the camera's frustum into the lists, by switch distance per model (metres; one per model): the
  // commands' instance counts reset (a copy between GPU buffers) and one dispatch. Call after simulate.
  void cullAndClassify(const Camera& camera, std::span<const float> switch_m);

  // The shadow casters of a map (after simulate and cullAndClassify): every agent whose sphere reaches into the map's
  // box (light_view_proj: orthographic, x and y to [-1, 1] over side_m metres, z to [0, 1] over depth_range_m), in
  // the representation the switch distances give it (as cullAndClassify; under a geometry budget, as that call drew
  // it: geometry only where the budget kept it, an agent not drawn as an impostor), impostors with their view towards
  // the light (to_light: unit, towards it); into the caster lists, whose counts alone are reset. One dispatch.
  void castShadows(const Camera& camera, std::span<const float> switch_m, const Mat4& light_view_proj, float side_m,
                   float depth_range_m, const Vec3& to_light);
  // Lists: the camera's, 2m (geometry) and 2m + 1 (impostors); the casters', casterList(m, impostor).
  size_t casterList(size_t m, bool impostor) const { return 2 * models_ + 2 * m + (impostor ? 1 : 0); }

  // A budget of skinned triangles for the cullAndClassify calls that follow (0: none, the default): of the agents in
  // view inside their switch distance, the nearest whose models' triangles fit in it stay geometry and the others
  // become impostors (runtime::CrowdRuntimeOptions::max_geometry_triangles' rule, impostors of the farthest), by
  // distance buckets of 1/1024 of the largest switch distance (agents of one bucket go together, so a few triangles
  // of the budget may stay unused): two more dispatches, no readback.
  static constexpr uint32_t kBudgetBuckets = 1024;
  void setGeometryBudget(uint64_t triangles) { budget_ = triangles; }
  uint64_t geometryBudget() const { return budget_; }

  // Levels of detail for the cullAndClassify calls that follow (0: the mesh alone, the default): a skinned agent at
  // distance d takes the coarsest level whose distance to the mesh is at most lod_m_per_m * d (the runtime's levelFor:
  // geometry_lod_px over the focal length); the budget counts its level's triangles. Level l of model m is drawn by
  // command levelCommand(m, l) over levelCapacity() records at listOffset(2m) + levelOffset(l); an agent past its
  // level's capacity is drawn as an impostor (Counts::level_overflow). One more dispatch. Shadow casters drawn as
  // geometry take the level the camera gives them, in their lists' parts alike (caster: levelCommand(m, l, true),
  // at listOffset(casterList(m, false)) + levelOffset(l)).
  void setLevelScale(float lod_m_per_m) { lod_m_per_m_ = lod_m_per_m; }
  float levelScale() const { return lod_m_per_m_; }
  size_t levelCount(size_t m) const { return level_counts_[m]; }
  size_t levelCommand(size_t m, size_t level, bool caster = false) const {
    if (level == 0) return caster ? casterList(m, false) : 2 * m;
    return 4 * models_ + (caster ? models_ : 0) * (kMaxLevels - 1) + m * (kMaxLevels - 1) + level - 1;
  }
  size_t levelCapacity() const { return level_capacity_; }
  size_t levelOffset(size_t level) const { return level * level_capacity_ * 48; }
  // Where model m's level l of the camera's (or the casters') geometry list starts in the list buffer, bytes.
  size_t levelListOffset(size_t m, size_t level, bool caster = false) const {
    return listOffset(caster ? casterList(m, false) : 2 * m) + levelOffset(level);
  }

  // Occlusion culling of the next cullAndClassify (that call only): agents whose bounding box lies behind `target`'s
  // current depth (the city, drawn first) over the box's whole footprint are left out, by the test of the CPU runtime's
  // cullBehind (gpu::projectBox, DepthPyramid::hides) on a depth pyramid built on the GPU: no readback. The target
  // must be the next camera's size.
  void occludeBehind(const RenderTarget& target);
  // After cullAndClassify (waits for the GPU; tests and counts, never inside a frame): agents in view, and of them
  // left out by occlusion.
  // Under a budget: the agents inside their switch drawn as impostors for it, the skinned triangles kept, and those
  // the agents inside their switch would have drawn.
  struct Counts {
    uint32_t in_view = 0, occluded = 0;
    uint32_t over_budget = 0, budget_triangles_kept = 0, budget_triangles_wanted = 0;
    uint32_t level_overflow = 0;  // with levels of detail: skinned agents past their level's part of the list
  };
  Counts readCounts() const;
  // Every command (as readCommands: the camera's lists, the casters', the levels') copied for reading frames later,
  // tagged `frame`: after cullAndClassify, no wait (gpu/late_readback.h; skipped while 8 copies are in flight).
  // finishedCommands calls `use` with each copy the GPU has completed, oldest first, and never waits.
  void captureCommands(uint64_t frame);
  size_t finishedCommands(const std::function<void(uint64_t frame, std::span<const GpuCrowdCommand> commands)>& use);

  size_t agentCount() const { return agents_; }
  size_t modelCount() const { return models_; }
  // List of model m: 2m (geometry) and 2m + 1 (impostors); its records (gpu::CrowdAgentGpu, crowd_renderer.h) start
  // at listOffset(list) bytes of the list buffer; its command at list * sizeof(GpuCrowdCommand) of the command buffer.
  size_t listOffset(size_t list) const { return list * capacity_ * 48; }
  size_t listBytes() const { return capacity_ * 48; }
  uint32_t poseBuffer() const { return poses_; }    // vec4 per agent: feet x, y, z, heading
  uint32_t phaseBuffer() const { return phases_; }  // float per agent
  uint32_t listBuffer() const { return lists_; }
  uint32_t commandBuffer() const { return commands_; }

  // Reads back (waits for the GPU; tests and checks, never a frame): poses, phases, the lists' agents, commands.
  std::vector<Vec4> readPoses() const;
  std::vector<float> readPhases() const;
  std::vector<GpuCrowdCommand> readCommands() const;
  // The object ids of a list's agents, in list order; readLevelList: those of model m's level l (with levels; the
  // camera's, or the casters').
  std::vector<uint32_t> readList(size_t list) const;
  std::vector<uint32_t> readLevelList(size_t m, size_t level, bool caster = false) const;
  size_t gpuBytes() const;

 private:
  // Every buffer at its binding (crowd_sim.comp.glsl's layout); a classifying pass's program, uniforms and buffers.
  void bindBuffers() const;
  void usePass(const Program& pass, const Camera& camera, std::span<const float> switch_m) const;

  size_t agents_ = 0, models_ = 0, capacity_ = 0;  // capacity: records a list holds (agents, rounded up to 64)
  uint32_t agent_buf_ = 0, routes_ = 0, points_ = 0, poses_ = 0, phases_ = 0, model_buf_ = 0, commands_ = 0,
           initial_ = 0, lists_ = 0, counts_ = 0, candidates_ = 0, buckets_ = 0;
  uint64_t budget_ = 0;
  float lod_m_per_m_ = 0.0f;
  size_t level_capacity_ = 0;
  std::vector<size_t> level_counts_;  // per model
  uint32_t level_count_buf_ = 0;
  Program level_counts_pass_;
  void countLevels(const Camera& camera, std::span<const float> switch_m, bool casters);  // FF_LEVEL_COUNTS
  // The object ids of the records at `offset` of the list buffer, as many as command `command` counts.
  std::vector<uint32_t> readIds(size_t offset, size_t command) const;
  bool budgeted_ = false;  // the last cullAndClassify ran under the budget (its candidates and cut are valid)
  std::unique_ptr<LateReadback> late_commands_;  // captureCommands' copies
  std::unique_ptr<GpuDepthPyramid> pyramid_;  // made by the first occludeBehind
  bool occlude_next_ = false;
  size_t bytes_ = 0;
  std::vector<GpuCrowdCommand> initial_commands_;
  Program simulate_, classify_, casters_, budget_scan_, budget_assign_;
};

}  // namespace farfield::gpu
