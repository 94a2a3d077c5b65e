#include "farfield/runtime/frame_governor.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "farfield/core/error.h"

namespace farfield::runtime {

namespace {

bool finiteNonNegative(double v) { return std::isfinite(v) && v >= 0.0; }

}  // namespace

FrameGovernor::FrameGovernor(std::vector<GovernorLevel> levels, GovernorOptions options)
    : levels_(std::move(levels)), options_(options) {
  const char* where = "frame governor";
  if (levels_.empty()) throw Error(where, "needs at least one level");
  for (const GovernorLevel& level : levels_)
    if (!std::isfinite(level.bound_scale) || level.bound_scale < 1.0)
      throw Error(where, "level '" + level.name + "': bound_scale must be a finite number >= 1");
  if (!(std::isfinite(options_.t_max_ms) && options_.t_max_ms > 0.0))
    throw Error(where, "t_max must be a positive number of ms");
  if (!(options_.aim > 0.0 && options_.aim <= 1.0)) throw Error(where, "aim must be in (0, 1]");
  if (!(options_.refine_below > 0.0 && options_.refine_below <= options_.aim))
    throw Error(where, "refine_below must be in (0, aim]");
  if (options_.refine_after < 1 || options_.window < 1 || options_.max_pending < 1)
    throw Error(where, "refine_after, window and max_pending must be at least 1");
  if (!(std::isfinite(options_.cold_ratio) && options_.cold_ratio >= 1.0))
    throw Error(where, "cold_ratio must be a finite number >= 1");
  stats_.frames_at_level.assign(levels_.size(), 0);
}

double FrameGovernor::corrected(double predicted_ms) const {
  if (residuals_.empty()) return predicted_ms * options_.cold_ratio;
  double ratio = 0.0, difference = -std::numeric_limits<double>::infinity();
  for (const Residual& r : residuals_) {
    ratio = std::max(ratio, r.ratio);
    difference = std::max(difference, r.difference);
  }
  const double scaled = std::isinf(ratio) ? ratio : predicted_ms * ratio;  // 0 * infinity is no bound
  return std::max(0.0, std::min(scaled, predicted_ms + difference));
}

GovernorDecision FrameGovernor::decide(uint64_t frame, std::span<const double> predicted_ms) {
  const char* where = "frame governor";
  if (predicted_ms.size() != levels_.size())
    throw Error(where, "got " + std::to_string(predicted_ms.size()) + " predictions for " +
                           std::to_string(levels_.size()) + " levels");
  for (double p : predicted_ms)
    if (!finiteNonNegative(p)) throw Error(where, "a prediction is negative or not finite");
  if (has_frame_ && frame <= last_frame_)
    throw Error(where, "frame " + std::to_string(frame) + " decided after frame " + std::to_string(last_frame_));
  has_frame_ = true;
  last_frame_ = frame;

  const double t_max = options_.t_max_ms;
  auto expected = [&](size_t level) { return corrected(predicted_ms[level]); };
  const size_t before = level_;
  if (expected(level_) > options_.aim * t_max) {
    // Coarsen now: the finest coarser level that fits, else the coarsest.
    size_t level = level_ + 1;
    while (level + 1 < levels_.size() && expected(level) > options_.aim * t_max) ++level;
    level_ = std::min(level, levels_.size() - 1);
    refine_streak_ = 0;
  } else if (level_ > 0 && expected(level_ - 1) <= options_.refine_below * t_max) {
    if (++refine_streak_ >= options_.refine_after) {
      --level_;
      refine_streak_ = 0;
    }
  } else {
    refine_streak_ = 0;
  }
  if (level_ > before) ++stats_.coarsenings;
  if (level_ < before) ++stats_.refinements;

  GovernorDecision decision;
  decision.level = level_;
  decision.predicted_ms = predicted_ms[level_];
  decision.corrected_ms = expected(level_);
  decision.bound_scale = levels_[level_].bound_scale;
  decision.relaxed = decision.bound_scale > 1.0;
  decision.over = decision.corrected_ms > t_max;

  ++stats_.frames;
  ++stats_.frames_at_level[level_];
  stats_.relaxed_frames += decision.relaxed;
  stats_.predicted_over_frames += decision.over;
  pending_.push_back({frame, decision.predicted_ms});
  while (pending_.size() > options_.max_pending) pending_.pop_front();
  return decision;
}

void FrameGovernor::measured(uint64_t frame, double measured_ms) {
  if (!finiteNonNegative(measured_ms))
    throw Error("frame governor", "a measured time is negative or not finite");
  const auto it = std::find_if(pending_.begin(), pending_.end(), [&](const Pending& p) { return p.frame == frame; });
  if (it == pending_.end()) {
    ++stats_.ignored_measurements;
    return;
  }
  // A prediction of 0 says nothing about a ratio: its residual is the difference alone.
  const double ratio = it->predicted_ms > 0.0 ? measured_ms / it->predicted_ms
                                              : std::numeric_limits<double>::infinity();
  residuals_.push_back({ratio, measured_ms - it->predicted_ms});
  while (residuals_.size() > options_.window) residuals_.pop_front();
  pending_.erase(it);
  ++stats_.measurements;
  stats_.measured_over += measured_ms > options_.t_max_ms;
}

}  // namespace farfield::runtime
