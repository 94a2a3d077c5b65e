#include "farfield/runtime/faster_variant.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "farfield/core/error.h"

namespace farfield::runtime {
namespace {

constexpr size_t kRecent = 8;  // the kept variant's measured frames its recent median is taken over
constexpr size_t kRun = 2;     // frames per run of a probe; the first of each is not counted
// Frames a probe's frame may stay unmeasured after a later frame was measured before it counts as never measured.
constexpr uint64_t kMaxLate = 8;
// Frames after a probe before a change of the workload may start the next one.
constexpr uint64_t kMinGap = 16;

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(mid), values.end());
  if (values.size() % 2 == 1) return values[mid];
  const double upper = values[mid];
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + std::ptrdiff_t(mid)));
}

double mean(const std::vector<double>& values) {
  if (values.empty()) return 0.0;
  double sum = 0.0;
  for (double v : values) sum += v;
  return sum / double(values.size());
}

}  // namespace

FasterVariant::FasterVariant(int first, FasterVariantOptions options) : options_(options), kept_(first) {
  const char* where = "faster variant";
  if (first != 0 && first != 1) throw Error(where, "the first variant must be 0 or 1");
  if (options_.min_kept < 1 || options_.min_kept > kRecent || options_.probe_runs < 1 ||
      options_.reprobe_after < 1 || options_.reprobe_max < options_.reprobe_after ||
      options_.max_in_flight < 2 * kRun * options_.probe_runs)
    throw Error(where, "min_kept must be in 1..8, probe_runs and reprobe_after at least 1, reprobe_max at least "
                       "reprobe_after, max_in_flight at least 4 x probe_runs");
  if (!(options_.margin >= 0.0 && options_.margin < 1.0) || !(options_.give_up_ratio > 1.0) ||
      !(options_.change_ratio > 1.0))
    throw Error(where, "margin must be in [0, 1), give_up_ratio and change_ratio above 1");
  interval_ = options_.reprobe_after;
}

bool FasterVariant::workloadChanged() const {
  if (level_ <= 0.0 || last_frame_ < probe_ended_ + kMinGap || recent_kept_.size() < options_.min_kept) return false;
  // The median of the kept variant's last min_kept frames, against its level at the last decision.
  const std::vector<double> last(recent_kept_.end() - std::ptrdiff_t(options_.min_kept), recent_kept_.end());
  const double now = median(last);
  return now > options_.change_ratio * level_ || now * options_.change_ratio < level_;
}

double FasterVariant::recentKeptMedian() const {
  return median(std::vector<double>(recent_kept_.begin(), recent_kept_.end()));
}

void FasterVariant::finishProbe(bool given_up) {
  const int other = 1 - kept_;
  given_up = given_up || probe_ms_[kept_].empty() || probe_ms_[other].empty();
  bool switched = false;
  if (given_up) {
    ++given_up_;
  } else if (mean(probe_ms_[other]) < (1.0 - options_.margin) * mean(probe_ms_[kept_])) {
    kept_ = other;
    switched = true;
    ++switches_;
    // The probe's counted frames of the new kept variant are its first recent ones.
    recent_kept_.assign(probe_ms_[other].begin(), probe_ms_[other].end());
  }
  // A new choice is checked again soon; one that stands, less and less often.
  if (switched) interval_ = options_.reprobe_after;
  next_probe_ = last_frame_ + interval_;
  if (!switched) interval_ = std::min(options_.reprobe_max, 2 * interval_);
  // The kept variant's level now: a later departure from it says the workload changed.
  level_ = !probe_ms_[kept_].empty() ? mean(probe_ms_[kept_]) : recentKeptMedian();
  probe_ended_ = last_frame_;
  probing_ = false;
  probe_step_ = 0;
  probe_unmeasured_ = 0;
  probe_ms_[0].clear();
  probe_ms_[1].clear();
}

void FasterVariant::startFrom(double ms_of_0, double ms_of_1) {
  if (probing_) throw Error("faster variant", "startFrom during a probe");
  if (!(std::isfinite(ms_of_0) && ms_of_0 >= 0.0 && std::isfinite(ms_of_1) && ms_of_1 >= 0.0))
    throw Error("faster variant", "startFrom: the times must be finite and >= 0");
  const double ms[2] = {ms_of_0, ms_of_1};
  const int other = 1 - kept_;
  if (ms[other] < (1.0 - options_.margin) * ms[kept_]) {
    kept_ = other;
    ++switches_;
  }
  ++starts_;
  // The host's times may be taken unlike the measured frames (a calibration's waits): the kept variant's level is
  // taken from its first measured frames instead.
  recent_kept_.clear();
  level_ = 0.0;
  interval_ = options_.reprobe_after;
  next_probe_ = (any_decided_ ? last_frame_ : 0) + interval_;
  probe_ended_ = any_decided_ ? last_frame_ : 0;
}

void FasterVariant::finishProbeIfDone() {
  if (probing_ && probe_step_ >= 2 * kRun * options_.probe_runs && probe_unmeasured_ == 0) finishProbe(false);
}

int FasterVariant::decide(uint64_t frame, bool room) {
  if (any_decided_ && frame <= last_frame_)
    throw Error("faster variant",
                "frame " + std::to_string(frame) + " decided after frame " + std::to_string(last_frame_));
  any_decided_ = true;
  last_frame_ = frame;
  while (in_flight_.size() >= options_.max_in_flight) {
    if (probing_ && in_flight_.front().probe == probes_) --probe_unmeasured_;  // never measured
    in_flight_.pop_front();
  }
  finishProbeIfDone();
  if (!room && probing_ && probe_step_ < 2 * kRun * options_.probe_runs) {
    // No room for the other variant's frames: the probe is given up (its frames so far decide nothing).
    ++held_;
    finishProbe(true);
  }
  if (level_ <= 0.0 && probes_ + starts_ > 0 && recent_kept_.size() >= options_.min_kept) level_ = recentKeptMedian();
  if (room && !probing_ && recent_kept_.size() >= options_.min_kept && (frame >= next_probe_ || workloadChanged())) {
    if (frame < next_probe_) {
      ++early_probes_;
      interval_ = options_.reprobe_after;  // the choice is for a new workload: check it again soon
    }
    probing_ = true;
    ++probes_;
  }
  InFlight f;
  f.frame = frame;
  f.variant = kept_;
  if (probing_ && probe_step_ < 2 * kRun * options_.probe_runs) {
    // Runs of kRun frames in the order other, kept, kept, other, ...: the counted frames of each variant then have
    // the same mean time along the path (with an even number of runs), so a steady trend of the frame time cancels.
    const size_t run = (probe_step_ / kRun) % 4;
    f.variant = run == 0 || run == 3 ? 1 - kept_ : kept_;
    f.probe = probes_;
    f.counted = probe_step_ % kRun != 0;
    ++probe_step_;
    ++probe_unmeasured_;
  }
  in_flight_.push_back(f);
  ++frames_of_[size_t(f.variant)];
  return f.variant;
}

void FasterVariant::measured(uint64_t frame, double ms) {
  if (!(std::isfinite(ms) && ms >= 0.0))
    throw Error("faster variant", "frame " + std::to_string(frame) + ": a measured time must be finite and >= 0");
  const auto it =
      std::find_if(in_flight_.begin(), in_flight_.end(), [&](const InFlight& f) { return f.frame == frame; });
  if (it == in_flight_.end()) return;
  const InFlight f = *it;
  in_flight_.erase(it);
  if (f.probe == 0) {
    if (f.variant == kept_) {
      recent_kept_.push_back(ms);
      if (recent_kept_.size() > kRecent) recent_kept_.pop_front();
    }
    return;
  }
  if (!probing_ || f.probe != probes_) return;  // a finished probe's
  --probe_unmeasured_;
  if (f.counted) probe_ms_[f.variant].push_back(ms);
  // Against the probe's own frames of the kept variant (they lie between the other's first two counted ones), else
  // against its recent frames.
  const std::vector<double>& other = probe_ms_[1 - kept_];
  const double reference = probe_ms_[kept_].size() >= 2 ? mean(probe_ms_[kept_]) : recentKeptMedian();
  if (other.size() >= 2 && mean(other) > options_.give_up_ratio * reference) {
    finishProbe(true);
    return;
  }
  // The probe's frames that a frame well after them overtook are taken as never measured.
  for (auto i = in_flight_.begin(); i != in_flight_.end();) {
    if (i->probe == probes_ && i->frame + kMaxLate < frame) {
      --probe_unmeasured_;
      i = in_flight_.erase(i);
    } else {
      ++i;
    }
  }
  finishProbeIfDone();
}

}  // namespace farfield::runtime
