// "culled": the GPU-driven frame (DESIGN.md; gpu/gpu_culler.h). The scene's arena culled by compute shaders
// (frustum, normal cones, two-phase hierarchical-Z occlusion against its own depth) and drawn with one multi-draw per
// material group and phase; nothing waits for the GPU inside the frame. Its frame is the frame of "frustum" (every
// cluster in view), up to pixels whose content depends on draw order (coplanar surfaces of different objects).
// Triangles and objects drawn are counted on the GPU and read after the frame (Mode::lateFrameStats).
//
// Options (--mode-option), shared by every mode that draws through the arena: gpu_occlusion=on|off|auto (the pyramid
// test; off: frustum and cones only; auto: on or off, whichever the run's measured frames find faster, by
// runtime::FasterVariant; the default of the walkthrough modes, whose lists region visibility has already culled;
// culled's is on), gpu_cones=on|off, gpu_compact=on|off (compacted command lists with
// glMultiDrawElementsIndirectCount where the driver has it), gpu_refine_history=on|off (GpuCullOptions::
// refine_history: the next frame's early list from a pyramid of this frame's final depth), gpu_stage_times=on|off
// (off by default: the GPU time of each stage, gpu_stage_<stage>_ms in info(); timestamp queries on a GPU, a wait
// after each stage on a software rasterizer, which slows the frame).
#pragma once

#include <array>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "farfield/eval/mode.h"
#include "farfield/gpu/gpu_culler.h"
#include "farfield/runtime/faster_variant.h"

namespace farfield::eval {

struct GpuRunOptions {
  gpu::GpuCullOptions cull;
  bool occlusion_auto = false;  // gpu_occlusion=auto: cull.occlusion chosen per frame (runtime::FasterVariant)
};
// The GpuCuller options of a run's --mode-option keys (gpu_occlusion: on, off or auto; gpu_cones, gpu_compact,
// gpu_refine_history, gpu_stage_times: on or off); throws farfield::Error naming the key for another value.
// `occlusion_default`: gpu_occlusion's value where the run does not set it.
GpuRunOptions gpuRunOptions(const ModeContext& context, const std::string& mode_name,
                            const std::string& occlusion_default = "on");

// A GpuCuller over the run's arena drawing into bench frames, its statistics read late and kept per path frame.
class GpuCullRun {
 public:
  // Needs the context current (makes the run's arena on first use).
  GpuCullRun(const ModeContext& context, const GpuRunOptions& options);
  gpu::GpuCuller& culler() { return *culler_; }
  // Draws the culler's frame as a pass of `frame` (FrameContext::beginOwnPass); with occlusion_auto, with or without
  // occlusion culling as the chooser decides.
  void draw(FrameContext& frame);
  // Triangles and objects of the last frame drawn for this path frame, once the GPU has finished it.
  std::optional<gpu::FrameStats> lateFrameStats(size_t path_frame);
  // The measured time of the last frame drawn for this path frame (Mode::frameMeasured): what occlusion_auto
  // chooses by.
  void frameMeasured(size_t path_frame, double wall_ms);
  // For a host's timed calibration (the governor's): with occlusion_auto, the next frames are drawn with the test on
  // or off whatever the chooser says (nullopt: the chooser again), and the chooser of the last frame's kind (target
  // size, simplified levels) starts from both variants' times (runtime::FasterVariant::startFrom); returns whether it
  // keeps the test on.
  bool occlusionAuto() const { return occlusion_auto_; }
  void forceOcclusion(std::optional<bool> on) { forced_occlusion_ = on; }
  // Whether the frames drawn next have room for a probe of the other variant (runtime::FasterVariant::decide's
  // `room`; a governor near its budget says no). True unless set.
  void setProbeRoom(bool room) { probe_room_ = room; }
  bool startOcclusionFrom(double on_ms, double off_ms);
  // arena_clusters, arena_instances, arena_material_groups, arena_gpu_bytes, arena_build_s (making the arena, once a
  // run), indirect_count (1 or 0), and per frame
  // (means over the frames whose statistics came back): gpu_clusters_drawn_early, gpu_clusters_drawn_late,
  // gpu_frustum_culled, gpu_cone_culled, gpu_occlusion_culled, gpu_draw_commands (indirect draws after merging runs
  // of clusters), gpu_triangles; with gpu_stage_times, gpu_stage_<stage>_ms (gpu::kGpuCullStages) and
  // gpu_stage_frames; with occlusion_auto, gpu_occlusion_auto (1), gpu_occlusion_frames (the share of frames drawn
  // with occlusion culling), gpu_occlusion_kinds (the kinds of frame chosen for apart: target sizes and simplified
  // levels, a governor's levels), gpu_occlusion_kept (1 or 0: the choice at the end for the kind drawn most),
  // gpu_occlusion_probes, gpu_occlusion_switches, gpu_occlusion_early_probes (those a change of the frame time
  // started), gpu_occlusion_held (given up for want of room: setProbeRoom), gpu_occlusion_started (kinds started from
  // a host's timing of both; summed over the kinds).
  std::map<std::string, double> info() const;

 private:
  void collect();

  std::unique_ptr<gpu::GpuCuller> culler_;
  bool occlusion_auto_ = false;
  std::optional<bool> forced_occlusion_;
  bool probe_room_ = true;
  std::tuple<int, int, float> last_kind_{0, 0, 0.0f};
  // Per kind of frame (the target's width and height, the simplified levels' bound): variant 0 occlusion on, 1 off.
  std::map<std::tuple<int, int, float>, runtime::FasterVariant> occlusion_choices_;
  std::vector<runtime::FasterVariant*> chooser_of_;  // per culler frame, with occlusion_auto (null: forced)
  std::vector<size_t> path_frame_of_;           // per culler frame
  std::map<size_t, gpu::GpuCullStats> latest_;  // per path frame, the last statistics that came back
  double frames_ = 0.0, early_ = 0.0, late_ = 0.0, frustum_ = 0.0, cone_ = 0.0, occluded_ = 0.0, commands_ = 0.0;
  double triangles_ = 0.0;
  std::array<double, gpu::kGpuCullStages.size()> stage_ms_{};
  double stage_frames_ = 0.0;
  double arena_build_s_ = 0.0;
  double occlusion_frames_ = 0.0;  // frames drawn with occlusion culling (occlusion_auto)
};

class GpuCulledMode final : public Mode {
 public:
  explicit GpuCulledMode(const ModeContext& context);
  std::string name() const override { return "culled"; }
  void prepare(const ModeContext& context) override;
  void frame(FrameContext& frame) override { run_->draw(frame); }
  std::optional<gpu::FrameStats> lateFrameStats(size_t path_frame) override { return run_->lateFrameStats(path_frame); }
  void frameMeasured(size_t path_frame, double wall_ms) override { run_->frameMeasured(path_frame, wall_ms); }
  GpuCullRun* gpuCullRun() override { return run_ ? &*run_ : nullptr; }
  std::map<std::string, double> info() const override { return run_ ? run_->info() : std::map<std::string, double>{}; }
  bool setGeometryErrorPx(double px) override {
    if (!run_) return false;
    run_->culler().setLodErrorPx(float(px));
    return true;
  }

 private:
  GpuRunOptions options_;
  std::optional<GpuCullRun> run_;
};

}  // namespace farfield::eval
