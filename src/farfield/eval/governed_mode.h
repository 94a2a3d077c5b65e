// "governed": another mode's frame under a frame governor (runtime/frame_governor.h) that keeps the run's t_max
// (`--tmax`) in a closed loop, every coarsened frame reported with the error bound it kept.
//
// The coarser levels, in order: impostors accepted under larger bounds (governor_impostor_px=4,8: the governed mode
// again with its walkthrough's bound, --mode-option error_px, set to each, so that more of its database's impostors
// hold the eye; for modes over an impostor database; not a placement made for that bound), the arena's simplified
// geometry (gpu/scene_arena.h: meshopt_simplify per mesh, drawn for a part whose error projects under the level's
// pixels; for modes that draw through the arena), then lower render resolutions (scale s per side: the frame rendered
// at s x the size and scaled up, colour bilinear, ids and depth nearest) with the coarsest of both, the last resort.
// A level keeps the bound max(promised, impostors' px, simplified px) / s: a mode that checks its bound in pixels of
// its camera (the walkthrough) does so at the smaller size, and a pixel there is 1 / s pixels of the frame.
//
// The prediction and the loop are runtime::GovernorLoop's (runtime/governor_loop.h); this mode draws, times and
// reports. The prediction: a cost model (gpu/cost_model.h: base, per million triangles, per million pixels) fitted on
// the governed mode's own frames. On its first frame (the bench's untimed warm-up; an engine's first frame) the mode draws
// that view at every level a few times, each waited for and timed: the calibration, and the one frame with waits.
// Then every measured frame is a sample (its triangles, read late, and its pixels), and the model is refitted over
// the calibration and the last samples every 16 frames. A frame is predicted at each level from the triangles of the
// last frame whose statistics came back, moved to that level by the share of triangles each level drew at the
// calibration's view, and the level's pixels. Measured times reach the governor `governor_lag` frames
// late (as a timer query read late would).
//
// Options (--mode-option): governed=MODE (the mode governed; default culled), governor_impostor_px (none by default),
// governor_lod_px=0,1,2,4 (the simplified
// levels' bounds, 0 first, increasing; 0 alone over an arena a mode of the run made before without them), governor_error_px (the promised bound, default 1 px: bound scales are relative
// to it), governor_scales=1,0.84,... (the resolution scales, 1 first, decreasing, each in [0.25, 1]; default down to 0.25), governor_lag
// (frames, default 2),
// governor_aim, governor_refine_below, governor_refine_after, governor_window, governor_cold_ratio (default 1.5:
// the model, fitted on the calibration's quiet frames, is taken 1.5x larger until the first frame is measured)
// (runtime::GovernorOptions),
// governor_calibration_repeats (default 3), governor_t_max_ms (the budget where the command has no --tmax, e.g. walk;
// it wins over --tmax). Needs one of them. governor_read_ahead=on|off (default on): after each frame, what the
// governor expects it to leave of aim x t_max goes to Mode::readAhead (the placed walkthrough loads the impostors it
// will soon need), and that time is left out of the measurement the loop is given. governor_upscale_depth=on|off
// (default off): a lower resolution's depth scaled up with its colour and ids (for a pass drawn over the frame
// afterwards; 0.45 ms a frame on llvmpipe at 640 x 360), else the frame's depth is the far plane at those levels.
// Ids are scaled up only where the harness reads them (ModeContext::ids_read: the bench; a walk does not, and its
// lower resolutions' ids are 0): on llvmpipe the upscale is 1.3 ms of a 1.7 ms frame at the coarsest level, 0.3 of it
// the ids.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/eval/mode.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/target_upscaler.h"
#include "farfield/runtime/governor_loop.h"

namespace farfield::eval {

class GovernedMode final : public Mode {
 public:
  explicit GovernedMode(const ModeContext& context);
  std::string name() const override { return "governed"; }
  void prepare(const ModeContext& context) override;
  void frame(FrameContext& frame) override;
  std::optional<gpu::FrameStats> lateFrameStats(size_t path_frame) override;
  void frameMeasured(size_t path_frame, double wall_ms) override;
  std::optional<FrameGovernance> governance(size_t path_frame) const override;
  // Whether the level that drew the frame just drawn drew an impostor (its inner mode's answer).
  std::optional<bool> drewImpostors() const override { return inners_.at(last_inner_)->drewImpostors(); }
  // The governed mode's info, and governor_*: levels, frames per level, relaxed frames, coarsenings, refinements,
  // measured frames over t_max, the model's coefficients, calibration time, and the quantiles (p50, p95) of
  // measured / predicted and measured / corrected over the measured frames.
  std::map<std::string, double> info() const override;

 private:
  struct Level {
    size_t inner = 0;          // inners_[inner] draws it
    double scale = 1.0;
    double lod_px = 0.0;       // the simplified geometry's bound (Mode::setGeometryErrorPx), 0: full detail
    int width = 0, height = 0;
    gpu::RenderTarget target;  // scale < 1: where it is drawn before being scaled up
  };
  Camera levelCamera(const Camera& camera, size_t level) const;
  // Draws the governed mode's frame at `level` into that level's own target (or the calibration's full-size one).
  gpu::FrameStats drawLevel(const Camera& camera, size_t path_frame, size_t level);
  void calibrate(const Camera& camera, size_t path_frame);

  // The governed mode, and again under each of impostor_px_ (their contexts in contexts_, kept for their lifetime).
  std::vector<std::unique_ptr<Mode>> inners_;
  std::vector<ModeContext> contexts_;
  std::vector<double> impostor_px_;
  size_t last_inner_ = 0;
  std::map<size_t, bool> impostor_frames_;  // per path frame: the governed frame drew an impostor
  std::string inner_name_;
  std::vector<double> scales_;
  std::vector<double> lod_px_;
  double error_px_ = 1.0;  // the promised bound the levels' bound scales are relative to
  std::vector<Level> levels_;
  runtime::GovernorLoopOptions loop_options_;
  std::unique_ptr<runtime::GovernorLoop> loop_;
  int calibration_repeats_ = 3;
  double calibration_s_ = 0.0;
  gpu::Renderer* renderer_ = nullptr;
  gpu::RenderTarget finish_target_;  // 1 x 1: the calibration's waits (Renderer::render's glFinish)
  gpu::RenderTarget full_target_;    // the calibration's full-size frames
  std::unique_ptr<gpu::TargetUpscaler> upscaler_;  // a lower resolution's frame shown at the full one
  gpu::TargetUpscaler::Channels upscale_channels_ = gpu::TargetUpscaler::Channels::ColorAndIds;
  std::vector<gpu::DrawItem> items_;
  uint64_t next_frame_ = 0;
  std::optional<uint64_t> last_frame_;  // the loop's number of the last frame drawn (none: it calibrated)
  size_t last_path_frame_ = 0;
  std::optional<FrameGovernance> last_;
  bool read_ahead_ = true;           // governor_read_ahead: the slack goes to Mode::readAhead
  double last_read_ahead_ms_ = 0.0;  // the last frame's read-ahead, left out of its measurement
  double read_ahead_ms_total_ = 0.0;
};

}  // namespace farfield::eval
