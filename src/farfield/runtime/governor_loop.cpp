#include "farfield/runtime/governor_loop.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "farfield/core/error.h"

namespace farfield::runtime {
namespace {

std::vector<GovernorLevel> governorLevels(const std::vector<LoopLevel>& levels) {
  std::vector<GovernorLevel> out;
  for (const LoopLevel& l : levels) out.push_back(l.governor);
  return out;
}

}  // namespace

GovernorLoop::GovernorLoop(std::vector<LoopLevel> levels, GovernorLoopOptions options)
    : levels_(std::move(levels)), options_(options), governor_(governorLevels(levels_), options.governor) {
  const char* where = "governor loop";
  for (const LoopLevel& l : levels_)
    if (!(std::isfinite(l.pixels) && l.pixels > 0.0)) throw Error(where, "level '" + l.governor.name + "' has no pixels");
  if (options_.lag < 1 || options_.recent < 1 || options_.refit_every < 1 || options_.max_in_flight < options_.lag + 1)
    throw Error(where, "lag, recent and refit_every must be at least 1, max_in_flight more than lag");
  shares_.assign(levels_.size(), 1.0);
  calibration_triangles_.assign(levels_.size(), -1.0);
}

void GovernorLoop::calibrationSample(size_t level, double triangles, double ms) {
  if (level >= levels_.size() || !(triangles >= 0.0) || !(std::isfinite(ms) && ms >= 0.0))
    throw Error("governor loop", "a calibration sample of no level, or with negative triangles or time");
  calibration_.push_back({triangles, levels_[level].pixels, ms});
  calibration_triangles_[level] = triangles;
}

void GovernorLoop::finishCalibration() {
  if (calibration_.empty()) throw Error("governor loop", "no calibration sample");
  const double full = calibration_triangles_[0];
  for (size_t level = 0; level < levels_.size(); ++level)
    shares_[level] = full > 0.0 && calibration_triangles_[level] >= 0.0
                         ? std::clamp(calibration_triangles_[level] / full, 0.01, 1.0)
                         : 1.0;
  last_triangles_ = std::max(0.0, full);
  last_level_ = 0;
  refit();
  calibrated_ = true;
}

void GovernorLoop::refit() {
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

GovernorLoop::InFlight* GovernorLoop::find(uint64_t frame) {
  for (InFlight& f : in_flight_)
    if (f.frame == frame) return &f;
  return nullptr;
}

void GovernorLoop::deliver(uint64_t now) {
  auto delivered = [&](const InFlight& f) {
    if (f.frame + options_.lag > now || f.measured_ms < 0.0) return f.frame + options_.max_in_flight < now;
    governor_.measured(f.frame, f.measured_ms);
    if (f.decision.predicted_ms > 0.0) ratio_.push_back(f.measured_ms / f.decision.predicted_ms);
    if (f.decision.corrected_ms > 0.0) corrected_ratio_.push_back(f.measured_ms / f.decision.corrected_ms);
    if (f.triangles >= 0.0) {
      const Sample sample{f.triangles, levels_[f.decision.level].pixels, f.measured_ms};
      if (recent_.size() < options_.recent) {
        recent_.push_back(sample);
      } else {
        recent_[recent_next_] = sample;
        recent_next_ = (recent_next_ + 1) % options_.recent;
      }
      if (++since_refit_ >= options_.refit_every) refit();
    }
    return true;
  };
  in_flight_.erase(std::remove_if(in_flight_.begin(), in_flight_.end(), delivered), in_flight_.end());
}

GovernorDecision GovernorLoop::decide(uint64_t frame, double workload) {
  if (!calibrated_) throw Error("governor loop", "decide() before finishCalibration()");
  if (!(std::isfinite(workload) && workload >= 0.0))
    throw Error("governor loop", "frame " + std::to_string(frame) + ": a workload must be finite and >= 0");
  deliver(frame);
  std::vector<double> predicted(levels_.size());
  double full_triangles = last_triangles_ / shares_[last_level_];
  // This frame's load against the load of the frame those triangles are from (a new plan).
  if (workload > 0.0 && last_workload_ > 0.0) full_triangles *= workload / last_workload_;
  for (size_t level = 0; level < levels_.size(); ++level)
    predicted[level] = model_.predict(full_triangles * shares_[level], 0.0, levels_[level].pixels);
  const GovernorDecision decision = governor_.decide(frame, predicted);
  InFlight f;
  f.frame = frame;
  f.decision = decision;
  f.workload = workload;
  in_flight_.push_back(f);
  return decision;
}

void GovernorLoop::frameTriangles(uint64_t frame, double triangles) {
  InFlight* f = find(frame);
  if (!f || !(triangles >= 0.0)) return;
  f->triangles = triangles;
  last_triangles_ = triangles;
  last_level_ = f->decision.level;
  last_workload_ = f->workload;
}

void GovernorLoop::frameMeasured(uint64_t frame, double ms) {
  InFlight* f = find(frame);
  if (!f || !(std::isfinite(ms) && ms >= 0.0)) return;
  f->measured_ms = ms;
}

}  // namespace farfield::runtime
