// How a walkthrough mode draws its plans' geometry (--mode-option geometry=gpu|cpu, default gpu):
//   gpu: the plan lists its geometry objects (runtime::WalkthroughOptions::geometry_items false) and a GpuCullRun over
//        the run's arena culls and draws their clusters on the GPU, as the culled mode does (gpu_occlusion, gpu_cones,
//        gpu_compact apply; gpu_occlusion is auto by default: region visibility has culled the lists already, and
//        whether the pyramid test still pays is measured on the run's frames); the plan's CPU work is its choice of
//        objects, and only a change of it is uploaded;
//   cpu: the plan's items culled per cluster on the CPU, occlusion-culled against the depth of their nearest ones
//        (the culled-cpu mode's pass) unless occlusion=off.
// Either way the plan's impostors follow in the frame's main pass. occlusion=off turns occlusion off on both paths.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "farfield/eval/gpu_culled_mode.h"
#include "farfield/eval/mode.h"
#include "farfield/eval/occlusion_pass.h"
#include "farfield/runtime/walkthrough.h"

namespace farfield::eval {

class PlanGeometry {
 public:
  // Reads geometry, occlusion and occluder_share (cpu), gpu_* (gpu); throws farfield::Error naming the mode for a bad
  // value.
  PlanGeometry(const ModeContext& context, const std::string& mode_name);
  bool gpuDriven() const { return gpu_; }
  // Sets the walkthrough's options to match (geometry items or objects).
  void configure(runtime::WalkthroughOptions& options) const { options.geometry_items = !gpu_; }
  void prepare(const ModeContext& context);
  // Draws the plan's geometry now and queues its impostors in the frame's main pass.
  void submit(FrameContext& frame, const runtime::FramePlan& plan);
  // Draws these objects (ids, ascending) as geometry now, for a mode that chooses its objects itself: on the GPU
  // the list's difference with the last one goes up (work in the size of the lists), on the CPU their clusters in
  // view are culled (and occlusion-culled) into draw items. An empty list draws nothing.
  void submitObjects(FrameContext& frame, std::span<const uint32_t> ids);
  std::optional<gpu::FrameStats> lateFrameStats(size_t path_frame);
  // Mode::frameMeasured: what gpu_occlusion=auto chooses by.
  void frameMeasured(size_t path_frame, double wall_ms);
  // Mode::gpuCullRun: the GPU path's run, null on the CPU path.
  GpuCullRun* gpuRun() { return run_ ? &*run_ : nullptr; }
  // The GPU run's simplified levels (Mode::setGeometryErrorPx); false on the CPU path.
  bool setGeometryErrorPx(double px) {
    if (!run_) return false;
    run_->culler().setLodErrorPx(float(px));
    return true;
  }
  // The occlusion pass's or the GPU run's numbers, and geometry_gpu (1 or 0), geometry_uploads (plan changes sent).
  std::map<std::string, double> info() const;

 private:
  bool gpu_ = true;
  GpuRunOptions gpu_options_;
  std::optional<GpuCullRun> run_;
  std::optional<OcclusionPass> occlusion_;
  const gpu::GpuScene* gpu_scene_ = nullptr;
  std::vector<gpu::DrawItem> candidates_;
  std::vector<Box3> bounds_;
  uint64_t version_ = ~uint64_t(0);
  size_t uploads_ = 0;
};

}  // namespace farfield::eval
