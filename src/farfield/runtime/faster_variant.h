// Two ways to draw the same frame, kept to the faster one by measuring both on the frames the host draws.
//
// Occlusion culling on the GPU (gpu/gpu_culler.h) draws the frame that drawing everything in view draws, at the cost
// of two depth pyramids and a second culling phase. Whether that pays depends on the machine and on the list: tens of
// microseconds on a GPU; on llvmpipe 2-3 ms a frame at 640 x 360, where a region's visible set (already culled by
// region visibility) then draws faster without it. No model fitted once knows which: the host's own frame times do.
// The rule:
//   - the kept variant's last measured frames (up to 8) give its recent median; a probe starts once there are
//     `min_kept` of them and draws the other variant until `probe_frames` of its frames are measured: the other
//     variant is kept from then on only when their median is lower than the kept one's recent median by more than
//     `margin` (frames a few apart see about the same view);
//   - probes repeat `reprobe_after` frames after a decision, the interval doubling (up to `reprobe_max`) each time the
//     decision stands and starting again from `reprobe_after` when it changes, so that a choice that stands costs a
//     few frames of the slower variant per `reprobe_max` frames;
//   - a probe stops as soon as the median of its measured frames (two or more: the first frame after a switch may
//     pay for the switch) is over `give_up_ratio` times the kept one's recent median, so that a probe of a much slower
//     variant costs two or three frames;
//   - measured times may come back any number of frames late (a timer query read late) and in any order; frames never
//     measured (a host's untimed calibration draws) only delay the probe, and a probe that draws `max_in_flight`
//     frames without its measurements is given up. Nothing is probed before frames of the kept variant were measured,
//     so a host's untimed first draws all see the first variant.
// No OpenGL and no clock: the host reports what it measured (eval's GpuCullRun does so for `gpu_occlusion=auto`).
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <vector>

namespace farfield::runtime {

struct FasterVariantOptions {
  size_t min_kept = 4;          // measured frames of the kept variant before a probe (1..8)
  size_t probe_frames = 3;      // measured frames of the other variant a probe decides on (>= 1)
  double margin = 0.05;         // share by which the other variant must be faster to be kept, in [0, 1)
  size_t reprobe_after = 120;   // frames from a decision to the next probe (>= 1)
  size_t reprobe_max = 960;     // the interval's ceiling while decisions stand (>= reprobe_after)
  double give_up_ratio = 1.25;  // a probe whose frames take this many times the kept one's stops early (> 1)
  size_t max_in_flight = 64;    // decided frames kept waiting for their measurement (>= probe_frames)
};

class FasterVariant {
 public:
  // Variants are 0 and 1; `first` is kept until a probe finds the other faster. Throws farfield::Error for bad
  // options or a variant other than 0 or 1.
  explicit FasterVariant(int first = 0, FasterVariantOptions options = {});

  // The variant frame `frame` draws; frames increase from call to call (a repeated or older frame throws
  // farfield::Error).
  int decide(uint64_t frame);
  // The measured time of a decided frame (ms >= 0 and finite, else farfield::Error); frames never decided, or too
  // old, are ignored.
  void measured(uint64_t frame, double ms);

  int kept() const { return kept_; }
  bool probing() const { return probing_; }
  size_t probes() const { return probes_; }          // probes started
  size_t probesGivenUp() const { return given_up_; }  // stopped early (a much slower variant) or never measured
  size_t switches() const { return switches_; }       // decisions that changed the kept variant
  size_t framesOf(int variant) const { return frames_of_[size_t(variant & 1)]; }  // frames decided per variant

 private:
  struct InFlight {
    uint64_t frame = 0;
    int variant = 0;
    size_t probe = 0;  // the probe it was drawn for (probes_ then), 0: none
  };
  void finishProbe(bool given_up);
  double keptMedian() const;

  FasterVariantOptions options_;
  int kept_ = 0;
  std::deque<InFlight> in_flight_;
  bool probing_ = false;
  size_t probe_drawn_ = 0;          // frames the current probe has drawn
  std::vector<double> probe_ms_;    // ... and their measured times
  std::deque<double> recent_kept_;  // the kept variant's last measured times
  uint64_t next_probe_ = 0;
  size_t interval_ = 0;
  bool any_decided_ = false;
  uint64_t last_frame_ = 0;
  size_t probes_ = 0, given_up_ = 0, switches_ = 0;
  size_t frames_of_[2] = {0, 0};
};

}  // namespace farfield::runtime
