#include "farfield/eval/governed_mode.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/core/timer.h"
#include "farfield/eval/frame_stats.h"
#include "farfield/eval/gpu_culled_mode.h"
#include "farfield/eval/mode_options.h"

namespace farfield::eval {
namespace {

// A comma-separated list of numbers in [lo, hi] for --mode-option KEY, the first equal to `first`, each after it
// beyond the one before in the list's direction (`increasing` or decreasing); `what` names an item in errors.
std::vector<double> parseLevelList(const std::string& text, const std::string& key, double lo, double hi,
                                   double first, bool increasing, const std::string& what) {
  const std::string where = "--mode-option " + key;
  std::vector<double> values;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || end == item.c_str() || *end != '\0' || !std::isfinite(v) || v < lo || v > hi)
      throw Error(where, "'" + item + "' is not " + what);
    if (!values.empty() && !(increasing ? v > values.back() : v < values.back()))
      throw Error(where, std::string("the values must ") + (increasing ? "increase" : "decrease"));
    values.push_back(v);
  }
  if (values.empty() || values.front() != first)
    throw Error(where, "the first value must be " + std::to_string(int(first)));
  return values;
}

}  // namespace

GovernedMode::GovernedMode(const ModeContext& context) {
  inner_name_ = context.option("governed", "culled");
  if (inner_name_ == "governed") throw Error("--mode-option governed", "cannot govern itself");
  // The simplified levels are made with the run's arena (in a mode's prepare). An arena some mode made already without
  // them (the viewer's culled, selected first) stays: the simplified levels are then left out.
  const bool simplified = !context.arena_slot->arena || context.arena_slot->simplified_levels;
  if (simplified) context.arena_slot->simplified_levels = true;
  else FF_WARN("mode governed: the run's arena was made without simplified levels: the coarser levels are impostors "
               "and lower resolutions only");
  inners_.push_back(createMode(inner_name_, context));
  // Impostors accepted under larger bounds: the governed mode again, its walkthrough's bound (error_px) set to each.
  const std::string impostor_px = context.option("governor_impostor_px");
  if (!impostor_px.empty()) {
    impostor_px_ = parseLevelList("0," + impostor_px, "governor_impostor_px", 0.0, 64.0, 0.0, true,
                                  "a number of pixels in (0, 64]");
    impostor_px_.erase(impostor_px_.begin());
    for (double px : impostor_px_) {
      ModeContext coarser = context;  // shares the run's arena and the record of options read
      char value[32];
      std::snprintf(value, sizeof(value), "%g", px);
      coarser.options["error_px"] = value;
      contexts_.push_back(coarser);
      inners_.push_back(createMode(inner_name_, coarser));
    }
  }
  // Resolution scales, 1 (the frame itself) first, decreasing; the simplified levels' bounds, 0 (full detail) first.
  // The last resort goes down to a quarter per side: on llvmpipe the levels under half resolution take 15-25 % off
  // the floor (docs/DESIGN-NOTES.md, "The governor's floor").
  scales_ = parseLevelList(context.option("governor_scales", "1,0.84,0.71,0.59,0.5,0.42,0.35,0.3,0.25"),
                           "governor_scales", 0.25, 1.0, 1.0, false, "a scale in [0.25, 1]");
  lod_px_ = parseLevelList(context.option("governor_lod_px", simplified ? "0,1,2,4" : "0"), "governor_lod_px", 0.0,
                           64.0, 0.0, true, "a number of pixels in [0, 64]");
  if (!simplified && lod_px_.size() > 1)
    throw Error("--mode-option governor_lod_px", "the run's arena has no simplified levels to draw");
  error_px_ = positiveOption(context, "governor_error_px", error_px_);
  // The budget: --mode-option governor_t_max_ms (for commands without --tmax: walk), else the run's --tmax.
  const double t_max = numberOption(context, "governor_t_max_ms", context.t_max_ms.value_or(0.0), 0.0);
  if (!(t_max > 0.0)) throw Error("mode 'governed'", "needs a frame budget: --tmax MS (or --mode-option governor_t_max_ms=MS)");
  runtime::GovernorOptions& g = loop_options_.governor;
  g.t_max_ms = t_max;
  g.aim = numberOption(context, "governor_aim", g.aim, 0.05, 1.0);
  read_ahead_ = switchOption(context, "governor_read_ahead", true);
  using Channels = gpu::TargetUpscaler::Channels;
  upscale_channels_ = switchOption(context, "governor_upscale_depth", false) ? Channels::All
                      : context.ids_read                                   ? Channels::ColorAndIds
                                                                           : Channels::Color;
  g.refine_below = numberOption(context, "governor_refine_below", g.refine_below, 0.05, g.aim);
  g.refine_after = countOption(context, "governor_refine_after", g.refine_after);
  g.window = countOption(context, "governor_window", g.window);
  // The bench's interleaved frames were 18-50 % slower on llvmpipe than the quiet frames the model is fitted on.
  g.cold_ratio = numberOption(context, "governor_cold_ratio", 1.5, 1.0, 10.0);
  loop_options_.lag = countOption(context, "governor_lag", loop_options_.lag, 1, 16);
  calibration_repeats_ = intOption(context, "governor_calibration_repeats", calibration_repeats_, 1, 20);
}

void GovernedMode::prepare(const ModeContext& context) {
  inners_[0]->prepare(context);
  for (size_t k = 1; k < inners_.size(); ++k) inners_[k]->prepare(contexts_[k - 1]);
  renderer_ = context.renderer;
  finish_target_ = gpu::RenderTarget(1, 1);
  full_target_ = gpu::RenderTarget(context.width, context.height);
  upscaler_ = std::make_unique<gpu::TargetUpscaler>();
  // The levels, in the order: impostors under larger bounds (governor_impostor_px), then the simplified levels
  // (at full resolution, with the coarsest impostor bound), where the governed mode draws through the arena; then the
  // lower resolutions, with the coarsest of both.
  for (const auto& inner : inners_)
    if (!inner->setGeometryErrorPx(0.0)) lod_px_ = {0.0};
  struct Plan {
    size_t inner;
    double scale, lod_px, impostor_px;
  };
  std::vector<Plan> plan;
  plan.push_back({0, 1.0, 0.0, 0.0});
  for (size_t k = 0; k < impostor_px_.size(); ++k) plan.push_back({k + 1, 1.0, 0.0, impostor_px_[k]});
  const size_t last = inners_.size() - 1;
  const double last_px = impostor_px_.empty() ? 0.0 : impostor_px_.back();
  for (size_t i = 1; i < lod_px_.size(); ++i) plan.push_back({last, 1.0, lod_px_[i], last_px});
  for (size_t i = 1; i < scales_.size(); ++i) plan.push_back({last, scales_[i], lod_px_.back(), last_px});
  std::vector<runtime::LoopLevel> levels;
  for (const auto& [inner, s, px, ipx] : plan) {
    Level level;
    level.inner = inner;
    level.scale = s;
    level.lod_px = px;
    level.width = std::max(1, int(std::lround(context.width * s)));
    level.height = std::max(1, int(std::lround(context.height * s)));
    if (s < 1.0) level.target = gpu::RenderTarget(level.width, level.height);
    char name[96];
    std::snprintf(name, sizeof(name), "%.2fx resolution, simplified to %g px, impostors under %g px", s, px, ipx);
    // The bound kept: the impostors', the simplified geometry's or the promised one, whichever is larger, in pixels
    // of the frame.
    levels.push_back({{name, std::max({1.0, px / error_px_, ipx / error_px_}) / s},
                      double(level.width) * double(level.height)});
    levels_.push_back(std::move(level));
  }
  loop_ = std::make_unique<runtime::GovernorLoop>(std::move(levels), loop_options_);
}

Camera GovernedMode::levelCamera(const Camera& camera, size_t level) const {
  Camera c = camera;
  c.width = levels_[level].width;
  c.height = levels_[level].height;
  return c;
}

gpu::FrameStats GovernedMode::drawLevel(const Camera& camera, size_t path_frame, size_t level) {
  Level& l = levels_[level];
  const Camera c = levelCamera(camera, level);
  gpu::RenderTarget& target = l.scale < 1.0 ? l.target : full_target_;
  Mode& mode = *inners_[l.inner];
  mode.setGeometryErrorPx(l.lod_px);
  FrameContext inner(c, path_frame, *renderer_, target, items_);
  mode.frame(inner);
  return inner.drawMainPass();
}

void GovernedMode::calibrate(const Camera& camera, size_t path_frame) {
  Stopwatch total;
  Camera tiny = camera;
  tiny.width = tiny.height = 1;
  // One draw of a level, waited for: its triangles (read after the wait) and milliseconds.
  struct Timed {
    double triangles = 0.0, ms = 0.0;
  };
  const auto timedDraw = [&](size_t level) {
    Stopwatch clock;
    const gpu::FrameStats drawn = drawLevel(camera, path_frame, level);
    // A lower resolution's frame is scaled up as in a real frame (the first also makes the driver's state).
    if (levels_[level].scale < 1.0) upscaler_->draw(levels_[level].target, full_target_, upscale_channels_);
    renderer_->render(tiny, {}, finish_target_);  // waits for the GPU (Renderer::render's glFinish)
    Timed t;
    t.ms = clock.milliseconds();
    t.triangles = double(drawn.triangles);
    if (const std::optional<gpu::FrameStats> late = inners_[levels_[level].inner]->lateFrameStats(path_frame))
      t.triangles += double(late->triangles);
    return t;
  };
  // Where the inner mode chooses its occlusion test by its frames (gpu_occlusion=auto), each level is drawn with the
  // test on and off: the level's chooser starts on the faster (instead of drawing its first frames with the test on
  // and probing later, frames a governor near its floor has no room for), and the model is fitted on that variant.
  std::vector<std::vector<Timed>> on(levels_.size()), off(levels_.size());
  // One untimed round first (targets, pyramids and caches made), then `repeats` timed rounds over the levels.
  for (int round = 0; round <= calibration_repeats_; ++round) {
    for (size_t level = 0; level < levels_.size(); ++level) {
      GpuCullRun* run = inners_[levels_[level].inner]->gpuCullRun();
      if (!run || !run->occlusionAuto()) {
        const Timed t = timedDraw(level);
        if (round > 0) loop_->calibrationSample(level, t.triangles, t.ms);
        continue;
      }
      run->forceOcclusion(true);
      const Timed with = timedDraw(level);
      run->forceOcclusion(false);
      const Timed without = timedDraw(level);
      run->forceOcclusion(std::nullopt);
      if (round == 0) continue;
      on[level].push_back(with);
      off[level].push_back(without);
      if (round == calibration_repeats_) {
        double on_ms = 0.0, off_ms = 0.0;
        for (size_t r = 0; r < on[level].size(); ++r) on_ms += on[level][r].ms, off_ms += off[level][r].ms;
        // The kind just drawn is this level's; the samples are those of the variant its chooser starts with.
        const bool keeps_on = run->startOcclusionFrom(on_ms, off_ms);
        for (const Timed& t : keeps_on ? on[level] : off[level]) loop_->calibrationSample(level, t.triangles, t.ms);
      }
    }
  }
  loop_->finishCalibration();
  calibration_s_ = total.seconds();
}

void GovernedMode::frame(FrameContext& frame) {
  // The calibrating frame's time is the calibration's: it is not given to the loop as a measurement of the frame.
  const bool calibrating = !loop_->calibrated();
  if (calibrating) calibrate(frame.camera(), frame.pathFrame());
  const uint64_t number = next_frame_++;
  // What the frame will draw, known before drawing it (a new region's visible set), scales the prediction: the
  // triangles the loop predicts from are a frame or two old.
  const runtime::GovernorDecision decision =
      loop_->decide(number, inners_[levels_.front().inner]->planWorkload(frame.camera()));
  last_frame_ = calibrating ? std::nullopt : std::optional<uint64_t>(number);
  last_path_frame_ = frame.pathFrame();
  last_ = FrameGovernance{decision.level, decision.predicted_ms, decision.corrected_ms, decision.bound_scale};

  const Level& level = levels_[decision.level];
  last_inner_ = level.inner;
  // A frame expected near the budget has no room for a probe of the other occlusion variant (gpu_occlusion=auto),
  // whose first frame pays for the switch: only one expected under the governor's refine threshold has.
  if (GpuCullRun* run = inners_[level.inner]->gpuCullRun())
    run->setProbeRoom(decision.corrected_ms <= loop_options_.governor.refine_below * loop_options_.governor.t_max_ms);
  if (level.scale == 1.0) {
    // The frame itself, drawn as the governed mode draws it (simplified and under the bound the level says).
    inners_[level.inner]->setGeometryErrorPx(level.lod_px);
    inners_[level.inner]->frame(frame);
  } else {
    // The upscale writes every pixel of the frame's target: no clear of it first.
    gpu::RenderTarget& out = frame.beginOwnPassOverwritingAll();
    frame.addStats(drawLevel(frame.camera(), frame.pathFrame(), decision.level));
    upscaler_->draw(level.target, out, upscale_channels_);
  }
  if (const std::optional<bool> drew = drewImpostors()) impostor_frames_[frame.pathFrame()] = *drew;
  // What the frame is expected to leave of the budget goes to loading what later frames will need (the placed
  // walkthrough's impostors ahead), so that those frames do not load them; the measurement the loop gets leaves it
  // out (the model is of the frame's drawing; the read-ahead only fills what the model says is left).
  last_read_ahead_ms_ = 0.0;
  if (read_ahead_) {
    const double slack = loop_options_.governor.aim * loop_options_.governor.t_max_ms - decision.corrected_ms;
    if (slack > 0.0) last_read_ahead_ms_ = inners_[level.inner]->readAhead(frame.camera(), slack);
    read_ahead_ms_total_ += last_read_ahead_ms_;
  }
}

std::optional<gpu::FrameStats> GovernedMode::lateFrameStats(size_t path_frame) {
  std::optional<gpu::FrameStats> late = inners_[last_inner_]->lateFrameStats(path_frame);
  // The late triangles are the GPU-driven frame's whole count; a mode without late statistics is modelled by its
  // pixels alone (0 triangles).
  if (last_frame_ && path_frame == last_path_frame_) loop_->frameTriangles(*last_frame_, late ? double(late->triangles) : 0.0);
  return late;
}

void GovernedMode::frameMeasured(size_t path_frame, double wall_ms) {
  inners_[last_inner_]->frameMeasured(path_frame, wall_ms);
  if (last_frame_ && path_frame == last_path_frame_)
    loop_->frameMeasured(*last_frame_, std::max(0.0, wall_ms - last_read_ahead_ms_));
}

std::optional<FrameGovernance> GovernedMode::governance(size_t /*path_frame*/) const { return last_; }

std::map<std::string, double> GovernedMode::info() const {
  std::map<std::string, double> info = inners_[0]->info();
  // The frames that drew an impostor are the governed frames', whichever level (and inner mode) drew them.
  if (!impostor_frames_.empty()) addImpostorFrames(impostor_frames_, info);
  if (!loop_) return info;
  const runtime::FrameGovernor::Statistics& s = loop_->governor().statistics();
  const gpu::CostModel& model = loop_->model();
  info["governor_t_max_ms"] = loop_options_.governor.t_max_ms;
  info["governor_levels"] = double(levels_.size());
  for (size_t i = 0; i < levels_.size(); ++i) {
    info["governor_level_" + std::to_string(i) + "_scale"] = levels_[i].scale;
    info["governor_level_" + std::to_string(i) + "_lod_px"] = levels_[i].lod_px;
    info["governor_level_" + std::to_string(i) + "_impostor_px"] =
        levels_[i].inner == 0 ? 0.0 : impostor_px_[levels_[i].inner - 1];
    info["governor_level_" + std::to_string(i) + "_triangle_share"] = loop_->triangleShare(i);
    info["governor_level_" + std::to_string(i) + "_frames"] = double(s.frames_at_level[i]);
  }
  info["governor_frames"] = double(s.frames);
  info["governor_relaxed_frames"] = double(s.relaxed_frames);
  info["governor_coarsenings"] = double(s.coarsenings);
  info["governor_refinements"] = double(s.refinements);
  info["governor_measured_over"] = double(s.measured_over);
  info["governor_predicted_over"] = double(s.predicted_over_frames);
  info["governor_lag_frames"] = double(loop_options_.lag);
  info["governor_calibration_s"] = calibration_s_;
  info["governor_read_ahead_ms_total"] = read_ahead_ms_total_;
  info["governor_model_base_ms"] = model.base_ms;
  info["governor_model_ms_per_mtriangle"] = model.ms_per_mtriangle;
  info["governor_model_ms_per_mpixel"] = model.ms_per_mpixel;
  const FrameSummary ratio = summarize(loop_->measuredOverPredicted());
  const FrameSummary corrected = summarize(loop_->measuredOverCorrected());
  info["governor_measured_over_predicted_p50"] = ratio.median;
  info["governor_measured_over_predicted_p95"] = ratio.p95;
  info["governor_measured_over_corrected_p50"] = corrected.median;
  info["governor_measured_over_corrected_p95"] = corrected.p95;
  return info;
}

}  // namespace farfield::eval
