#include "farfield/runtime/faster_variant.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "farfield/core/error.h"

namespace farfield::runtime {
namespace {

constexpr size_t kRecent = 8;  // the kept variant's measured frames its recent median is taken over

double median(std::vector<double> values) {
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(mid), values.end());
  if (values.size() % 2 == 1) return values[mid];
  const double upper = values[mid];
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + std::ptrdiff_t(mid)));
}

}  // namespace

FasterVariant::FasterVariant(int first, FasterVariantOptions options) : options_(options), kept_(first) {
  const char* where = "faster variant";
  if (first != 0 && first != 1) throw Error(where, "the first variant must be 0 or 1");
  if (options_.min_kept < 1 || options_.min_kept > kRecent || options_.probe_frames < 1 ||
      options_.reprobe_after < 1 || options_.reprobe_max < options_.reprobe_after ||
      options_.max_in_flight < options_.probe_frames)
    throw Error(where, "min_kept must be in 1..8, probe_frames and reprobe_after at least 1, reprobe_max at least "
                       "reprobe_after, max_in_flight at least probe_frames");
  if (!(options_.margin >= 0.0 && options_.margin < 1.0) || !(options_.give_up_ratio > 1.0))
    throw Error(where, "margin must be in [0, 1) and give_up_ratio above 1");
  interval_ = options_.reprobe_after;
}

double FasterVariant::keptMedian() const { return median(std::vector<double>(recent_kept_.begin(), recent_kept_.end())); }

void FasterVariant::finishProbe(bool given_up) {
  bool switched = false;
  if (given_up) {
    ++given_up_;
  } else if (median(probe_ms_) < (1.0 - options_.margin) * keptMedian()) {
    kept_ = 1 - kept_;
    switched = true;
    ++switches_;
    // The probe's frames are the new kept variant's first recent ones.
    recent_kept_.assign(probe_ms_.begin(), probe_ms_.end());
    while (recent_kept_.size() > kRecent) recent_kept_.pop_front();
  }
  // A new choice is checked again soon; one that stands, less and less often.
  if (switched) interval_ = options_.reprobe_after;
  next_probe_ = last_frame_ + interval_;
  if (!switched) interval_ = std::min(options_.reprobe_max, 2 * interval_);
  probing_ = false;
  probe_drawn_ = 0;
  probe_ms_.clear();
}

int FasterVariant::decide(uint64_t frame) {
  if (any_decided_ && frame <= last_frame_)
    throw Error("faster variant",
                "frame " + std::to_string(frame) + " decided after frame " + std::to_string(last_frame_));
  any_decided_ = true;
  last_frame_ = frame;
  while (in_flight_.size() >= options_.max_in_flight) in_flight_.pop_front();
  if (probing_ && probe_drawn_ >= options_.max_in_flight) finishProbe(true);  // its frames are never measured
  if (!probing_ && frame >= next_probe_ && recent_kept_.size() >= options_.min_kept) {
    probing_ = true;
    ++probes_;
  }
  InFlight f;
  f.frame = frame;
  f.variant = probing_ ? 1 - kept_ : kept_;
  f.probe = probing_ ? probes_ : 0;
  if (probing_) ++probe_drawn_;
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
  if (probing_ && f.probe == probes_) {
    probe_ms_.push_back(ms);
    if (probe_ms_.size() >= 2 && median(probe_ms_) > options_.give_up_ratio * keptMedian())
      finishProbe(true);
    else if (probe_ms_.size() >= options_.probe_frames)
      finishProbe(false);
  } else if (f.probe == 0 && f.variant == kept_) {
    recent_kept_.push_back(ms);
    if (recent_kept_.size() > kRecent) recent_kept_.pop_front();
  }
}

}  // namespace farfield::runtime
