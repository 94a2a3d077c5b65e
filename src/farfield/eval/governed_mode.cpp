#include "farfield/eval/governed_mode.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/eval/frame_stats.h"
#include "farfield/eval/mode_options.h"

namespace farfield::eval {
namespace {

constexpr size_t kRecent = 120;     // measured frames the model is refitted over (with the calibration)
constexpr size_t kRefitEvery = 16;  // measured frames between refits
constexpr size_t kMaxInFlight = 64;

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
  context.arena_slot->simplified_levels = true;  // before any mode of the run makes the arena (in prepare)
  inner_ = createMode(inner_name_, context);
  // Resolution scales, 1 (the frame itself) first, decreasing; the simplified levels' bounds, 0 (full detail) first.
  scales_ = parseLevelList(context.option("governor_scales", "1,0.84,0.71,0.59,0.5"), "governor_scales", 0.25, 1.0,
                           1.0, false, "a scale in [0.25, 1]");
  lod_px_ = parseLevelList(context.option("governor_lod_px", "0,1,2,4"), "governor_lod_px", 0.0, 64.0, 0.0, true,
                           "a number of pixels in [0, 64]");
  error_px_ = positiveOption(context, "governor_error_px", error_px_);
  if (!context.t_max_ms) throw Error("mode 'governed'", "needs a frame budget: --tmax MS");
  governor_options_.t_max_ms = *context.t_max_ms;
  governor_options_.aim = numberOption(context, "governor_aim", governor_options_.aim, 0.05, 1.0);
  governor_options_.refine_below =
      numberOption(context, "governor_refine_below", governor_options_.refine_below, 0.05, governor_options_.aim);
  governor_options_.refine_after = countOption(context, "governor_refine_after", governor_options_.refine_after);
  governor_options_.window = countOption(context, "governor_window", governor_options_.window);
  lag_ = countOption(context, "governor_lag", lag_, 1, 16);
  calibration_repeats_ = intOption(context, "governor_calibration_repeats", calibration_repeats_, 1, 20);
}

void GovernedMode::prepare(const ModeContext& context) {
  inner_->prepare(context);
  renderer_ = context.renderer;
  finish_target_ = gpu::RenderTarget(1, 1);
  full_target_ = gpu::RenderTarget(context.width, context.height);
  // The simplified levels first (at full resolution), where the governed mode draws through the arena; then the
  // lower resolutions, with the coarsest simplified level.
  if (!inner_->setGeometryErrorPx(0.0)) lod_px_ = {0.0};
  std::vector<std::pair<double, double>> plan;  // scale, lod px
  for (double px : lod_px_) plan.emplace_back(1.0, px);
  for (size_t i = 1; i < scales_.size(); ++i) plan.emplace_back(scales_[i], lod_px_.back());
  std::vector<runtime::GovernorLevel> levels;
  for (const auto& [s, px] : plan) {
    Level level;
    level.scale = s;
    level.lod_px = px;
    level.width = std::max(1, int(std::lround(context.width * s)));
    level.height = std::max(1, int(std::lround(context.height * s)));
    if (s < 1.0) level.target = gpu::RenderTarget(level.width, level.height);
    levels_.push_back(std::move(level));
    char name[64];
    std::snprintf(name, sizeof(name), "%.2fx resolution, simplified to %g px", s, px);
    // The bound kept: the simplified geometry's or the promised one, whichever is larger, in pixels of the frame.
    levels.push_back({name, std::max(1.0, px / error_px_) / s});
  }
  governor_ = std::make_unique<runtime::FrameGovernor>(std::move(levels), governor_options_);
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
  inner_->setGeometryErrorPx(l.lod_px);
  FrameContext inner(c, path_frame, *renderer_, target, items_);
  inner_->frame(inner);
  gpu::FrameStats stats;
  if (!inner.drewPasses()) {
    target.bind();
    target.clear(renderer_->light().sky_color);
    stats = renderer_->draw(c, inner.mainItems(), target);
  } else {
    stats = inner.passStats();
    if (!inner.mainItems().empty()) {
      const gpu::FrameStats main = renderer_->draw(c, inner.mainItems(), target);
      stats.triangles += main.triangles;
      stats.draw_calls += main.draw_calls;
      stats.objects += main.objects;
    }
  }
  return stats;
}

void GovernedMode::calibrate(const Camera& camera, size_t path_frame) {
  Stopwatch total;
  Camera tiny = camera;
  tiny.width = tiny.height = 1;
  // One untimed round first (targets, pyramids and caches made), then `repeats` timed rounds over the levels. The
  // triangles each level draws of this view, relative to the full level's, predict a level's triangles from another's.
  std::vector<double> triangles_of(levels_.size(), 0.0);
  for (int round = 0; round <= calibration_repeats_; ++round) {
    for (size_t level = 0; level < levels_.size(); ++level) {
      Stopwatch clock;
      const gpu::FrameStats drawn = drawLevel(camera, path_frame, level);
      // A lower resolution's frame is scaled up as in a real frame (the first blit also makes the driver's state).
      if (levels_[level].scale < 1.0) levels_[level].target.copyScaledTo(full_target_);
      renderer_->render(tiny, {}, finish_target_);  // waits for the GPU (Renderer::render's glFinish)
      const double ms = clock.milliseconds();
      double triangles = double(drawn.triangles);
      if (const std::optional<gpu::FrameStats> late = inner_->lateFrameStats(path_frame))
        triangles += double(late->triangles);
      if (round > 0)
        calibration_.push_back({triangles, double(levels_[level].width) * levels_[level].height, ms});
      triangles_of[level] = triangles;
    }
  }
  for (size_t level = 0; level < levels_.size(); ++level)
    levels_[level].triangle_share =
        triangles_of[0] > 0.0 ? std::clamp(triangles_of[level] / triangles_of[0], 0.01, 1.0) : 1.0;
  last_triangles_ = triangles_of[0];
  last_level_ = 0;
  refit();
  calibration_s_ = total.seconds();
}

void GovernedMode::refit() {
  // The triangle term only once the samples' triangles vary (the calibration draws one view: its triangles are about
  // the same at every level, and a fit would take them for the base cost and scale every later view by them).
  double lo = 0.0, hi = 0.0;
  bool first = true;
  for (const std::vector<Sample>* set : {&calibration_, &recent_})
    for (const Sample& s : *set) {
      lo = first ? s.triangles : std::min(lo, s.triangles);
      hi = first ? s.triangles : std::max(hi, s.triangles);
      first = false;
    }
  const bool triangles_vary = hi > 1.5 * lo + 1000.0;
  std::vector<gpu::CostSample> samples;
  for (const std::vector<Sample>* set : {&calibration_, &recent_})
    for (const Sample& s : *set) samples.push_back({triangles_vary ? s.triangles : 0.0, 0.0, s.pixels, s.ms, 0.0});
  if (samples.size() >= 5) {
    model_ = gpu::CostModel::fit(samples);
  } else {
    model_ = {};
    for (const gpu::CostSample& s : samples) model_.base_ms = std::max(model_.base_ms, s.ms);
  }
  since_refit_ = 0;
}

void GovernedMode::deliverMeasurements() {
  auto delivered = [&](const InFlight& f) {
    if (f.frame + lag_ > next_frame_ || f.measured_ms < 0.0) return f.frame + kMaxInFlight < next_frame_;
    governor_->measured(f.frame, f.measured_ms);
    if (f.decision.predicted_ms > 0.0) ratio_.push_back(f.measured_ms / f.decision.predicted_ms);
    if (f.decision.corrected_ms > 0.0) corrected_ratio_.push_back(f.measured_ms / f.decision.corrected_ms);
    if (f.triangles >= 0.0) {
      const Sample sample{f.triangles, f.pixels, f.measured_ms};
      if (recent_.size() < kRecent) {
        recent_.push_back(sample);
      } else {
        recent_[recent_next_] = sample;
        recent_next_ = (recent_next_ + 1) % kRecent;
      }
      if (++since_refit_ >= kRefitEvery) refit();
    }
    return true;
  };
  in_flight_.erase(std::remove_if(in_flight_.begin(), in_flight_.end(), delivered), in_flight_.end());
}

void GovernedMode::frame(FrameContext& frame) {
  const bool calibrating = calibration_.empty();
  if (calibrating) calibrate(frame.camera(), frame.pathFrame());
  deliverMeasurements();
  // The next frame's triangles at each level: the last known frame's, moved from its level to each by the shares
  // the calibration measured.
  std::vector<double> predicted(levels_.size());
  const double full_triangles = last_triangles_ / levels_[last_level_].triangle_share;
  for (size_t level = 0; level < levels_.size(); ++level)
    predicted[level] = model_.predict(full_triangles * levels_[level].triangle_share, 0.0,
                                      double(levels_[level].width) * double(levels_[level].height));
  const runtime::GovernorDecision decision = governor_->decide(next_frame_, predicted);
  const Level& level = levels_[decision.level];
  // The calibrating frame's time is the calibration's: it is not a measurement of the frame.
  if (!calibrating)
    in_flight_.push_back({next_frame_, frame.pathFrame(), decision, double(level.width) * double(level.height)});
  ++next_frame_;
  last_ = FrameGovernance{decision.level, decision.predicted_ms, decision.corrected_ms, decision.bound_scale};

  if (level.scale == 1.0) {
    inner_->setGeometryErrorPx(level.lod_px);
    inner_->frame(frame);  // the frame itself, drawn as the governed mode draws it (simplified where the level says)
    return;
  }
  gpu::RenderTarget& out = frame.beginOwnPass();
  frame.addStats(drawLevel(frame.camera(), frame.pathFrame(), decision.level));
  level.target.copyScaledTo(out);
}

std::optional<gpu::FrameStats> GovernedMode::lateFrameStats(size_t path_frame) {
  std::optional<gpu::FrameStats> late = inner_->lateFrameStats(path_frame);
  for (auto it = in_flight_.rbegin(); it != in_flight_.rend(); ++it) {
    if (it->path_frame != path_frame || it->triangles >= 0.0) continue;
    // What the frame's passes reported is not known here for every mode; the late triangles are the GPU-driven
    // frame's whole count, and a mode without late statistics is modelled by pixels alone.
    it->triangles = late ? double(late->triangles) : 0.0;
    last_triangles_ = it->triangles;
    last_level_ = it->decision.level;
    break;
  }
  return late;
}

void GovernedMode::frameMeasured(size_t path_frame, double wall_ms) {
  inner_->frameMeasured(path_frame, wall_ms);
  for (auto it = in_flight_.rbegin(); it != in_flight_.rend(); ++it)
    if (it->path_frame == path_frame && it->measured_ms < 0.0) {
      it->measured_ms = wall_ms;
      if (it->triangles < 0.0) it->triangles = 0.0;
      break;
    }
}

std::optional<FrameGovernance> GovernedMode::governance(size_t /*path_frame*/) const { return last_; }

std::map<std::string, double> GovernedMode::info() const {
  std::map<std::string, double> info = inner_->info();
  if (!governor_) return info;
  const runtime::FrameGovernor::Statistics& s = governor_->statistics();
  info["governor_t_max_ms"] = governor_options_.t_max_ms;
  info["governor_levels"] = double(levels_.size());
  for (size_t i = 0; i < levels_.size(); ++i) {
    info["governor_level_" + std::to_string(i) + "_scale"] = levels_[i].scale;
    info["governor_level_" + std::to_string(i) + "_lod_px"] = levels_[i].lod_px;
    info["governor_level_" + std::to_string(i) + "_triangle_share"] = levels_[i].triangle_share;
    info["governor_level_" + std::to_string(i) + "_frames"] = double(s.frames_at_level[i]);
  }
  info["governor_frames"] = double(s.frames);
  info["governor_relaxed_frames"] = double(s.relaxed_frames);
  info["governor_coarsenings"] = double(s.coarsenings);
  info["governor_refinements"] = double(s.refinements);
  info["governor_measured_over"] = double(s.measured_over);
  info["governor_predicted_over"] = double(s.predicted_over_frames);
  info["governor_lag_frames"] = double(lag_);
  info["governor_calibration_s"] = calibration_s_;
  info["governor_model_base_ms"] = model_.base_ms;
  info["governor_model_ms_per_mtriangle"] = model_.ms_per_mtriangle;
  info["governor_model_ms_per_mpixel"] = model_.ms_per_mpixel;
  const FrameSummary ratio = summarize(ratio_), corrected = summarize(corrected_ratio_);
  info["governor_measured_over_predicted_p50"] = ratio.median;
  info["governor_measured_over_predicted_p95"] = ratio.p95;
  info["governor_measured_over_corrected_p50"] = corrected.median;
  info["governor_measured_over_corrected_p95"] = corrected.p95;
  return info;
}

}  // namespace farfield::eval
