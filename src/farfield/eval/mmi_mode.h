// Walkthrough modes over a pipeline store (Decoret et al. 1999, section 6.1, Table 1): `farfield bake --pipeline
// pvs,near-far,mmi` writes per cell the PVS, the near/far split, the multi-mesh impostor (MMI) layers and the single
// mesh (SMI) of the same far objects; these bench modes draw them through runtime::Walkthrough
// (runtime/walkthrough.h), of
// which they are thin adapters:
//
//   local        the cell's near geometry only (frustum-culled): the upper bound of the frame rate
//   visible      the cell's PVS (frustum-culled): what any image-based method must beat
//   smi          near geometry + the single-mesh impostor of the far objects
//   mmi          near geometry + one meshed impostor per layer
//   mmi-dynamic  mmi, with the front-most layers turned into dynamically updated impostors while the frame budget
//                allows (section 5.5)
//
// Mode options (--mode-option key=value; `farfield bench --impostors DIR` sets impostor_dir):
//   impostor_dir=DIR        the pipeline store (mmi_dir=DIR overrides it for these modes)
//   gpu_budget_mb=MB        GPU bytes of resident impostors, least recently used cells evicted (default 512)
//   read_ahead=on|off       read the cells (placed: the impostors of the problem views ahead along the eye's motion)
//                           ahead of the viewer on a background thread (default on)
//   memory_budget_mb=MB     one budget for the database in memory (resident impostors and cells read ahead;
//                           replaces gpu_budget_mb; `--memory-budget` of walk and bench)
//   streaming_csv=FILE      per-frame streaming log: cell entered, stall, resident bytes (runtime/streaming.h)
//   impostor_ids=object|layer  item buffers show, per impostor pixel, the object captured there (default: the
//                           views' per-texel ids as an id texture) or one id per layer
//   cell_lookup=street|nearest  as for the depth-mesh mode
//   error_px=PX             the error bound in pixels of this walk's frames (default: the bake's --error-px); the
//                           bound's angle follows from the frame size and field of view (core/error_bound.h)
//   coarser_impostors=on|off  placed: impostors placed under a coarser bound (place --fallback-bounds) drawn, held
//                           to their own bound (default on), or their objects drawn as geometry (off: every frame
//                           keeps error_px; the governed mode's impostor levels raise it to take them)
//   read_ahead_ms=MS        each frame loads what it will soon need within MS after it is drawn: the placed
//                           impostors of the problem view ahead, or the views of the cells read ahead (smi, mmi,
//                           mmi-dynamic) (runtime::Walkthrough::loadAhead; default 0: loaded by the frame that needs
//                           them; the governed mode gives its slack instead, governor_read_ahead)
//   read_ahead_frames=N     placed: how far ahead along the eye's motion it looks (default 15 frames; 0: never)
//   geometry=gpu|cpu        the plan's geometry culled and drawn on the GPU through the run's arena (default; as
//                           the culled mode, gpu_occlusion, gpu_cones, gpu_compact apply) or culled per cluster on
//                           the CPU (eval/plan_geometry.h)
//   occlusion=on|off        the plan's geometry occlusion-culled (exact: the same frame; default on); on the CPU
//                           path against the depth of its nearest items, occluder_share=S the triangle share drawn
//                           first (0.1)
//
// info() adds to the walkthrough's statistics the path frames that drew an impostor (eval::addImpostorFrames).
//   mmi-dynamic only:
//   frame_budget_ms=MS      the desired frame time (default 33.3: 30 Hz)
//   dynamic_error_px=PX     a layer is refreshed when its error angle exceeds PX pixels (default 2)
//   dynamic_resolution=PX   dynamic impostor image size (default: frame width x fov margin)
//   dynamic_grid_px=PX      grid spacing of the dynamic meshes (default 8)
//   dynamic_max_updates=N   layer updates per frame at most (default 1: updates are spread over frames)
//   dynamic_min_lifetime=F  fast motion: when the nearest layer's error would outgrow dynamic_error_px within F
//                           frames at the current speed, every layer falls back to its MMI (default 3)
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>

#include "farfield/eval/mode.h"
#include "farfield/eval/plan_geometry.h"
#include "farfield/runtime/walkthrough.h"

namespace farfield::eval {

// Registers local, visible, smi, mmi and mmi-dynamic (called by registerImpostorModes()).
void registerMmiModes();

class MmiMode final : public Mode {
 public:
  MmiMode(runtime::Representation representation, const ModeContext& context);
  ~MmiMode() override;

  std::string name() const override { return runtime::representationName(options_.representation); }
  void prepare(const ModeContext& context) override;
  void frame(FrameContext& frame) override;
  std::optional<gpu::FrameStats> lateFrameStats(size_t path_frame) override {
    return geometry_->lateFrameStats(path_frame);
  }
  void frameMeasured(size_t path_frame, double wall_ms) override { geometry_->frameMeasured(path_frame, wall_ms); }
  GpuCullRun* gpuCullRun() override { return geometry_ ? geometry_->gpuRun() : nullptr; }
  bool setGeometryErrorPx(double px) override { return geometry_ && geometry_->setGeometryErrorPx(px); }
  double readAhead(const Camera& camera, double budget_ms) override {
    return walkthrough_ ? walkthrough_->loadAhead(camera, budget_ms) : 0.0;
  }
  double planWorkload(const Camera& camera) const override {
    return walkthrough_ ? walkthrough_->expectedTriangles(camera.eye) : 0.0;
  }
  std::map<std::string, double> info() const override;
  // None for local and visible, which draw geometry only.
  std::optional<bool> drewImpostors() const override {
    return drawsImpostors() ? std::optional<bool>(last_drew_impostors_) : std::nullopt;
  }

 private:
  bool drawsImpostors() const {
    return options_.representation != runtime::Representation::Local &&
           options_.representation != runtime::Representation::Visible;
  }
  runtime::WalkthroughOptions options_;
  std::unique_ptr<runtime::Walkthrough> walkthrough_;
  std::optional<PlanGeometry> geometry_;  // how the plans' geometry is drawn (--mode-option geometry, occlusion)
  std::map<size_t, bool> impostor_frames_;  // per path frame: an impostor drawn (addImpostorFrames)
  bool last_drew_impostors_ = false;
  double read_ahead_ms_ = 0.0;  // placed: each frame's own read-ahead budget (--mode-option read_ahead_ms)
};

}  // namespace farfield::eval
