// What uploading an impostor view to the GPU is expected to cost, from the recent uploads (Walkthrough::loadAhead
// decides from it how many fit in the time a host spares).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>

namespace farfield::runtime {

// What uploading a view is expected to cost: the 90th percentile of the last 32 uploads' milliseconds per byte,
// times its bytes. Not the slowest upload so far: on a machine whose cores the rasterizer shares, one preempted upload
// takes 20 times the others, and would stop every later upload ahead.
class UploadRate {
 public:
  void add(double ms, uint64_t bytes) {
    if (bytes == 0) return;
    rates_[next_++ % rates_.size()] = ms / double(bytes);
    count_ = std::min(count_ + 1, rates_.size());
  }
  bool known() const { return count_ > 0; }
  double predictMs(uint64_t bytes) const {
    if (count_ == 0) return 0.0;
    std::array<double, 32> sorted = rates_;
    std::sort(sorted.begin(), sorted.begin() + std::ptrdiff_t(count_));
    return sorted[std::min(count_ - 1, count_ * 9 / 10)] * double(bytes);
  }

 private:
  std::array<double, 32> rates_{};
  size_t next_ = 0, count_ = 0;
};

}  // namespace farfield::runtime
