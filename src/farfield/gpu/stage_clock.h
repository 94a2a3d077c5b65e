// The GPU time of a frame's stages, read frames later without waiting: a profile of where a frame's GPU work goes
// (the GPU-driven frame's culling passes, pyramids and multi-draws: GpuCullOptions::stage_times).
//
// Each frame sets marks 0, 1, ..., marks - 1 between its stages; stage i is the time from mark i to mark i + 1.
//   - Query (hardware GPUs): a GL_TIMESTAMP query per mark (glQueryCounter: allowed inside another GL_TIME_ELAPSED
//     query, such as the harness's frame timer), read when the frame's last mark is available, never waiting.
//   - CpuClock (a software rasterizer; gpu_timer.h for why its queries cannot be used): each mark waits for the work
//     before it (glFinish, counted as measurement: gl_counters.h) and reads a steady clock. The waits serialise the
//     stages, so this profile changes the frame it measures; use it for the breakdown, not the frame's time.
// A frame begun while every slot is in flight is skipped (its marks do nothing), and counted.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "farfield/core/timer.h"
#include "farfield/gpu/gpu_timer.h"

namespace farfield::gpu {

class StageClock {
 public:
  // Needs a current context. marks >= 2; slots: frames in flight at most (>= 1).
  explicit StageClock(size_t marks, size_t slots = 8, GpuTimer::Source source = GpuTimer::Source::Auto);
  ~StageClock();
  StageClock(const StageClock&) = delete;
  StageClock& operator=(const StageClock&) = delete;

  // Starts frame `frame` and sets its mark 0 (a frame begun before whose last mark was never set is dropped).
  void beginFrame(uint64_t frame);
  // Sets mark `index` (1 .. marks - 1, increasing) of the frame begun last; the last mark ends it. A mark left out is
  // the next one's time (its stage takes 0 ms).
  void mark(size_t index);
  // Calls `use` with each finished frame (oldest first) and its marks - 1 stage times (ms); returns how many.
  size_t finished(const std::function<void(uint64_t frame, std::span<const double> stage_ms)>& use);

  size_t stages() const { return marks_ - 1; }
  size_t skipped() const { return skipped_; }
  GpuTimer::Source source() const { return source_; }

 private:
  struct Slot {
    std::vector<uint32_t> queries;  // Query: one per mark
    std::vector<double> at_ms;      // CpuClock: the clock at each mark; Query: unused
    std::vector<bool> set;          // marks set this frame
    uint64_t frame = 0;
    bool busy = false;
  };
  void setMark(Slot& slot, size_t index);

  size_t marks_;
  GpuTimer::Source source_;
  std::vector<Slot> slots_;
  size_t next_ = 0;
  Slot* open_ = nullptr;
  size_t skipped_ = 0;
  Stopwatch clock_;
};

}  // namespace farfield::gpu
