// The GPU-driven frame (DESIGN.md): a scene arena's clusters culled by compute shaders and drawn with one multi-draw
// per material group, with no CPU-GPU round trip inside the frame.
//
// Per frame, two phases (two-phase hierarchical-Z occlusion culling):
//   1. early: the clusters visible in the last frame that are in view now (their object in the plan, their sphere in
//      the frustum, their normal cone not turned away) are drawn;
//   2. a depth pyramid is built on the GPU from the target's depth, and every cluster in view is tested against it
//      (gpu/occlusion_culler.h's conservative test: hidden only when all of its box lies behind the depth over every
//      pixel it may cover); those not hidden that the early phase did not draw are drawn, and the result is what the
//      next frame's early phase draws (refined by the frame's final depth: GpuCullOptions::refine_history).
// The frame is the one that drawing every cluster in view would give: a cluster left out is out of view, turned away
// or behind depth that was already drawn, and later draws only bring depth nearer. Nothing is read back; statistics
// (clusters and triangles drawn, culled by each test) are copied on the GPU and read frames later (finishedStats).
//
// Contract: a current context; the arena outlives the culler; the target's depth in the frame only comes nearer
// after draw() (no depth clear, no depth test other than GL_GREATER): the next frame's early phase relies on it.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/gpu/scene_arena.h"

namespace farfield::gpu {

struct GpuCullOptions {
  bool occlusion = true;  // two phases with the depth pyramid; false: one phase, frustum and cones only
  bool cone = true;       // normal-cone (back-face) culling of clusters
  // Compacted command lists drawn with glMultiDrawElementsIndirectCount where the driver has it (GL 4.6 or
  // ARB_indirect_parameters); false, or without it: glMultiDrawElementsIndirect over every slot, culled ones empty.
  bool compact = true;
  // After both phases: a pyramid of the frame's final depth decides which clusters the next frame draws first (those
  // it does not hide), at the cost of a second pyramid and test; false: those the second phase found visible.
  bool refine_history = true;
  // Relative depth margin of the occlusion test (DepthPyramid::hides). A negative one hides boxes that are in front
  // of the stored depth: the tests break the test with it and check that frames then differ.
  float occlusion_margin = 1e-5f;
  // The simplified levels (ArenaOptions::lod_ratio): a part whose level's error projects to at most this many pixels
  // of the target (partLodErrorPx) is drawn with it; 0: always the full level. GpuCuller::setLodErrorPx changes it.
  float lod_error_px = 0.0f;
  // GPU time per stage of each frame, read frames later (GpuCuller::finishedStageTimes; gpu/stage_clock.h): timestamp
  // queries on a GPU; on a software rasterizer a wait after each stage, which changes the frame it measures.
  bool stage_times = false;
};

// The stages a frame's GPU time is split into (GpuCullOptions::stage_times). With occlusion culling: the first
// phase's culling (its parts, clusters and commands) and its multi-draws, the depth pyramid, the second phase's
// culling and multi-draws, and the history (the second pyramid and the test that chooses the next frame's first
// phase). Without: the one phase in the first two, 0 in the others.
constexpr std::array<const char*, 6> kGpuCullStages{"cull_early", "draw_early", "pyramid",
                                                    "cull_late",  "draw_late",  "history"};
struct GpuStageTimes {
  uint64_t frame = 0;  // GpuCuller::frames() before the draw() that made it
  std::array<double, kGpuCullStages.size()> ms{};
};

// One frame's statistics, read when the GPU has finished it.
struct GpuCullStats {
  uint64_t frame = 0;              // GpuCuller::frames() before the draw() that made it
  uint32_t instances_in_plan = 0;  // cluster instances of the plan's objects
  uint32_t drawn_early = 0;        // clusters drawn in the first phase
  uint32_t drawn_late = 0;         // in the second (or only) phase
  uint64_t triangles = 0;          // drawn in both
  uint32_t objects = 0;            // distinct objects drawn
  uint32_t commands = 0;           // indirect draws (runs of consecutive clusters of a part) in both phases
  uint32_t frustum_culled = 0, cone_culled = 0, occlusion_culled = 0;
};

class GpuCuller {
 public:
  explicit GpuCuller(const SceneArena& arena, const GpuCullOptions& options = {});
  ~GpuCuller();
  GpuCuller(const GpuCuller&) = delete;
  GpuCuller& operator=(const GpuCuller&) = delete;

  const GpuCullOptions& options() const { return options_; }
  bool indirectCount() const { return indirect_count_; }
  const SceneArena& arena() const { return arena_; }

  // The plan's geometry: the objects (ids, 1-based) whose clusters draw() considers; all of them at first. Uploads
  // only the objects that changed since the last call (work in the size of the lists, not of the scene). Throws
  // farfield::Error for an id out of range.
  void setObjects(std::span<const uint32_t> ids);
  void setAllObjects();
  // The simplified levels' error bound in pixels (GpuCullOptions::lod_error_px) from the next frame on; >= 0.
  void setLodErrorPx(float px);
  // Forgets the last frame's visibility (a camera cut): the next frame draws in its second phase only.
  void resetHistory();
  // Occlusion culling (GpuCullOptions::occlusion) on or off from the next frame on: the frame drawn is the same
  // either way, only its cost differs (runtime/faster_variant.h chooses). Turning it on forgets the history, which
  // frames without it do not keep: the first frame with it draws in its second phase only.
  void setOcclusion(bool on);

  // Draws the frame's clusters into target (bound for an opaque pass here; not cleared; what it holds counts as drawn
  // geometry for the occlusion test). Returns the draw calls issued (triangles are known frames later).
  FrameStats draw(const Camera& camera, RenderTarget& target, RenderMode mode, const LightSettings& light);
  uint64_t frames() const { return frames_; }

  // Statistics of earlier frames that the GPU has finished, oldest first, each returned once. Never waits. A frame
  // whose statistics found the ring full (more than 8 frames unfinished) has none.
  std::vector<GpuCullStats> finishedStats();
  // With GpuCullOptions::stage_times: the stage times of earlier frames the GPU has finished, oldest first, each
  // returned once, never waiting; empty without it.
  std::vector<GpuStageTimes> finishedStageTimes();

 private:
  struct Impl;
  const SceneArena& arena_;
  GpuCullOptions options_;
  bool indirect_count_ = false;
  bool core_count_ = false;  // GL 4.6: the core entry point, else ARB_indirect_parameters
  uint64_t frames_ = 0;
  std::unique_ptr<Impl> impl_;
};

}  // namespace farfield::gpu
