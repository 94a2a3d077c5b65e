// GPU time of a stretch of commands: what the device spent on the work issued between begin() and end().
//
// Two sources, chosen when the timer is made (from GL_RENDERER of the current context):
//   - Query: a GL_TIME_ELAPSED query, for hardware GPUs. end() returns at once; elapsedMs() waits for the result.
//   - CpuClock: for software rasterizers (Mesa llvmpipe, softpipe, swrast), where the "GPU" is this process's CPU
//     threads. begin() waits for earlier work (glFinish) and starts a steady clock; end() waits for the work issued
//     since (glFinish) and stops it. llvmpipe's GL_TIME_ELAPSED cannot be used: it stamps a query's start and end per
//     tile and per rasterizer thread, overwriting them with every tile, so its result spans only the last tiles the
//     threads drew (measured: 0.3-5 ms for a 50 ms frame whenever the previous frame drew into the same framebuffer,
//     about the full 50 ms after drawing into another one, so that the bench's GPU column alternated between near 0
//     and the real value as its modes took turns after the reference), and it leaves out vertex processing and
//     binning, which llvmpipe does on the calling thread.
// The timer's own waits are measurement (gpu/gl_counters.h, GlMeasurement): not counted as the frame's.
#pragma once

#include <cstdint>

#include "farfield/core/timer.h"

namespace farfield::gpu {

class GpuTimer {
 public:
  enum class Source { Auto, Query, CpuClock };

  // Needs a current context. Auto picks CpuClock for a software rasterizer, Query otherwise.
  explicit GpuTimer(Source source = Source::Auto);
  ~GpuTimer();
  GpuTimer(const GpuTimer&) = delete;
  GpuTimer& operator=(const GpuTimer&) = delete;

  void begin();
  void end();
  // Milliseconds between begin() and end() (0 before the first end()); waits for the query result if needed.
  // Query: capped at the CPU wall time from begin() to the result (the GPU cannot have worked longer; llvmpipe, if
  // asked to use queries, sometimes reports a time since boot).
  double elapsedMs() const;
  // Whether elapsedMs() would return without waiting (a query's result is available; the clock's is at once).
  bool ready() const;
  // The source in use (never Auto).
  Source source() const { return source_; }

 private:
  Source source_;
  uint32_t query_ = 0;
  bool ended_ = false;  // a result exists once end() ran
  Stopwatch since_begin_;
  double cpu_clock_ms_ = 0.0;  // CpuClock: begin() to end(), both after glFinish
};

// Whether the current context's renderer is a software rasterizer (GL_RENDERER names llvmpipe, softpipe or swrast).
bool currentRendererIsSoftware();

}  // namespace farfield::gpu
