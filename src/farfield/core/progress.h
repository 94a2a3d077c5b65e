// Progress for long work (bakes, benchmarks, generation). On a terminal it redraws one line on stderr; otherwise
// (CI logs, pipes) it prints a line at every 10% so logs stay short. Thread-safe: advance() may be called from
// worker threads.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>

#include "farfield/core/timer.h"

namespace farfield {

class Progress {
 public:
  // total: number of steps; label: what is being done ("bake", "bench").
  Progress(std::string label, uint64_t total);
  ~Progress();
  void advance(uint64_t steps = 1);
  // Ends the line (prints 100% and the elapsed time). Called by the destructor if not called before.
  void finish();
  // Progress output is off when FF_PROGRESS=0 or the log level is above info.
  static bool enabled();

 private:
  void print(uint64_t done, bool final);

  std::string label_;
  uint64_t total_;
  std::atomic<uint64_t> done_{0};
  std::mutex mutex_;
  int last_decile_ = -1;
  double last_draw_s_ = -1.0;
  bool tty_ = false;
  bool finished_ = false;
  Stopwatch clock_;
};

}  // namespace farfield
