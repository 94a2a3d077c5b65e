// GPU time of a stretch of commands through GL_TIME_ELAPSED queries. Reading the result waits for the GPU.
#pragma once

#include <cstdint>

#include "farfield/core/timer.h"

namespace farfield::gpu {

class GpuTimer {
 public:
  GpuTimer();
  ~GpuTimer();
  GpuTimer(const GpuTimer&) = delete;
  GpuTimer& operator=(const GpuTimer&) = delete;

  void begin();
  void end();
  // Milliseconds between begin() and end(); blocks until the result is available. Capped at the CPU wall time
  // from begin() to the result (the GPU cannot have worked longer): llvmpipe sometimes reports a time since boot.
  double elapsedMs() const;

 private:
  uint32_t query_ = 0;
  bool ended_ = false;  // a result exists once end() ran
  Stopwatch since_begin_;
};

}  // namespace farfield::gpu
