// GPU time of a stretch of commands through GL_TIME_ELAPSED queries. Reading the result waits for the GPU.
#pragma once

#include <cstdint>

namespace farfield::gpu {

class GpuTimer {
 public:
  GpuTimer();
  ~GpuTimer();
  GpuTimer(const GpuTimer&) = delete;
  GpuTimer& operator=(const GpuTimer&) = delete;

  void begin();
  void end();
  // Milliseconds between begin() and end(); blocks until the result is available.
  double elapsedMs() const;

 private:
  uint32_t query_ = 0;
};

}  // namespace farfield::gpu
