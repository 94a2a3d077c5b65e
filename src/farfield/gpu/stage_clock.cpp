#include "farfield/gpu/stage_clock.h"

#include <epoxy/gl.h>

#include <algorithm>

#include "farfield/core/check.h"
#include "farfield/gpu/gl_counters.h"

namespace farfield::gpu {

StageClock::StageClock(size_t marks, size_t slots, GpuTimer::Source source)
    : marks_(marks), source_(source), slots_(slots) {
  FF_CHECK(marks >= 2 && slots >= 1);
  if (source_ == GpuTimer::Source::Auto)
    source_ = currentRendererIsSoftware() ? GpuTimer::Source::CpuClock : GpuTimer::Source::Query;
  for (Slot& s : slots_) {
    s.set.assign(marks_, false);
    s.at_ms.assign(marks_, 0.0);
    if (source_ == GpuTimer::Source::Query) {
      s.queries.assign(marks_, 0);
      glCreateQueries(GL_TIMESTAMP, GLsizei(marks_), s.queries.data());
    }
  }
}

StageClock::~StageClock() {
  for (Slot& s : slots_)
    if (!s.queries.empty()) glDeleteQueries(GLsizei(s.queries.size()), s.queries.data());
}

void StageClock::setMark(Slot& slot, size_t index) {
  if (source_ == GpuTimer::Source::Query) {
    glQueryCounter(slot.queries[index], GL_TIMESTAMP);
  } else {
    GlMeasurement measurement;  // the wait is the profile's, not the frame's
    glFinish();
    slot.at_ms[index] = clock_.milliseconds();
  }
  slot.set[index] = true;
}

void StageClock::beginFrame(uint64_t frame) {
  if (open_) open_->busy = false;  // a frame whose last mark never came: dropped
  open_ = nullptr;
  Slot& slot = slots_[next_];
  if (slot.busy) {
    ++skipped_;
    return;
  }
  slot.busy = true;
  slot.frame = frame;
  slot.set.assign(marks_, false);
  next_ = (next_ + 1) % slots_.size();
  open_ = &slot;
  setMark(slot, 0);
}

void StageClock::mark(size_t index) {
  FF_CHECK(index >= 1 && index < marks_);
  if (!open_) return;
  setMark(*open_, index);
  if (index + 1 == marks_) open_ = nullptr;
}

size_t StageClock::finished(const std::function<void(uint64_t, std::span<const double>)>& use) {
  size_t n = 0;
  std::vector<double> stage_ms(marks_ - 1);
  // Oldest first: from the slot the next frame would take, around the ring.
  for (size_t k = 0; k < slots_.size(); ++k) {
    Slot& slot = slots_[(next_ + k) % slots_.size()];
    if (!slot.busy || &slot == open_ || !slot.set[marks_ - 1]) continue;
    std::vector<double> at(marks_, 0.0);
    if (source_ == GpuTimer::Source::Query) {
      GLuint available = 0;
      glGetQueryObjectuiv(slot.queries[marks_ - 1], GL_QUERY_RESULT_AVAILABLE, &available);
      if (!available) break;  // later frames are later still
      for (size_t m = 0; m < marks_; ++m) {
        if (!slot.set[m]) continue;
        GLuint64 ns = 0;
        glGetQueryObjectui64v(slot.queries[m], GL_QUERY_RESULT, &ns);
        at[m] = double(ns) * 1e-6;
      }
    } else {
      at = slot.at_ms;
    }
    // A mark left out takes the time of the next one set: its stage takes 0 ms.
    for (size_t m = marks_ - 1; m-- > 0;)
      if (!slot.set[m]) at[m] = at[m + 1];
    for (size_t m = 0; m + 1 < marks_; ++m) stage_ms[m] = std::max(0.0, at[m + 1] - at[m]);
    use(slot.frame, stage_ms);
    slot.busy = false;
    ++n;
  }
  return n;
}

}  // namespace farfield::gpu
