// Reading GPU results frames later, without waiting: small buffers (statistics, counters) and timer queries.
//
// LateReadback copies a stretch of a GPU buffer into one of a ring of persistently mapped buffers and fences it;
// finished() hands back, oldest first, the copies the GPU has completed, and never waits. A capture while every slot
// is still in flight is skipped and counted. LateTimer times a stretch of commands once per frame with a ring of
// GpuTimers and hands back the results that are available (on a software rasterizer GpuTimer's clock waits for the
// work, as a measurement, and its result is available at once; gpu_timer.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "farfield/gpu/gpu_timer.h"

namespace farfield::gpu {

class LateReadback {
 public:
  // Needs a current context. bytes: the size of one capture; slots: captures in flight at most (>= 1).
  explicit LateReadback(size_t bytes, size_t slots = 8);
  ~LateReadback();
  LateReadback(const LateReadback&) = delete;
  LateReadback& operator=(const LateReadback&) = delete;

  // Copies bytes() from `buffer` at `offset` (a GL buffer name) into a free slot, tagged with `frame`; false when
  // every slot is still in flight (nothing copied). Orders after the commands issued before it.
  bool capture(uint32_t buffer, size_t offset, uint64_t frame);
  // Calls `use` with each completed capture, oldest first, and frees its slot; returns how many.
  size_t finished(const std::function<void(uint64_t frame, std::span<const uint8_t> bytes)>& use);
  size_t bytes() const { return bytes_; }
  size_t skipped() const { return skipped_; }

 private:
  struct Slot {
    uint32_t buffer = 0;
    const uint8_t* mapped = nullptr;
    void* fence = nullptr;  // GLsync
    uint64_t frame = 0;
  };
  size_t bytes_;
  std::vector<Slot> slots_;
  size_t next_ = 0;  // the slot the next capture writes (the oldest in flight is the first busy one from here)
  size_t skipped_ = 0;
};

class LateTimer {
 public:
  // Needs a current context. slots: frames in flight at most (>= 1).
  explicit LateTimer(size_t slots = 4, GpuTimer::Source source = GpuTimer::Source::Auto);
  ~LateTimer();

  // One stretch a frame: begin() ... end(). A begin() while every slot is in flight skips the frame (end() then does
  // nothing), counted.
  void begin(uint64_t frame);
  void end();
  // Calls `use` with each finished stretch's time, oldest first; returns how many.
  size_t finished(const std::function<void(uint64_t frame, double ms)>& use);
  size_t skipped() const { return skipped_; }

 private:
  struct Slot {
    std::unique_ptr<GpuTimer> timer;
    uint64_t frame = 0;
    bool busy = false;
  };
  std::vector<Slot> slots_;
  size_t next_ = 0;
  Slot* open_ = nullptr;
  size_t skipped_ = 0;
};

}  // namespace farfield::gpu
