#include "farfield/view/frame_history.h"

#include <algorithm>

namespace farfield::view {

FrameHistory::FrameHistory() { reset(); }

void FrameHistory::add(double cpu_ms, double gpu_ms, double t_max_ms, bool unchecked) {
  cpu_[next_] = float(cpu_ms);
  gpu_[next_] = float(gpu_ms);
  next_ = (next_ + 1) % kHistoryFrames;
  ++promises_.frames;
  if (t_max_ms > 0.0 && cpu_ms > t_max_ms) ++promises_.over_t_max;
  if (unchecked) ++promises_.unchecked_frames;
}

void FrameHistory::addCheck(bool over_bound) {
  ++promises_.checked;
  if (over_bound) ++promises_.over_bound;
}

void FrameHistory::reset() {
  cpu_.assign(kHistoryFrames, 0.0f);
  gpu_.assign(kHistoryFrames, 0.0f);
  next_ = 0;
  promises_ = {};
}

float FrameHistory::maxMs() const {
  return std::max(*std::max_element(cpu_.begin(), cpu_.end()), *std::max_element(gpu_.begin(), gpu_.end()));
}

}  // namespace farfield::view
