// Two ways to draw the same frame, kept to the faster one by measuring both on the frames the host draws.
//
// Occlusion culling on the GPU (gpu/gpu_culler.h) draws the frame that drawing everything in view draws, at the cost
// of two depth pyramids and a second culling phase. Whether that pays depends on the machine and on the list: tens of
// microseconds on a GPU; on llvmpipe 2-3 ms a frame at 640 x 360, where a region's visible set (already culled by
// region visibility) then often draws faster without it, and a heavier city's does not. No model fitted once knows
// which: the host's own frame times do. The rule:
//   - a probe draws the two variants in runs of two frames, in the order other, kept, kept, other (repeated),
//     `probe_runs` runs of each; the first frame of each run is not counted (it pays for the switch: occlusion
//     culling turned on has no history). The counted frames of the two variants then lie at the same mean time along
//     the path, so that a steady change of the frame time (a view opening up) cancels out of the comparison;
//   - the other variant is kept from then on only when the mean of its counted frames is lower than the kept one's
//     by more than `margin`;
//   - probes repeat `reprobe_after` frames after a decision, the interval doubling (up to `reprobe_max`) each time the
//     decision stands and starting again from `reprobe_after` when it changes, so that a choice that stands costs a
//     few frames of the slower variant per `reprobe_max` frames;
//   - and sooner where the workload changes: when the median of the kept variant's last `min_kept` frames departs
//     from its level at the last decision by more than `change_ratio` (either way), a probe starts at once (at least
//     16 frames after the last one) and the interval starts again from `reprobe_after`. On the demo's drive,
//     occlusion culling off is faster over its first 20 frames and 1.4x slower from frame 80 on, where its frames
//     jump from 21 to 34 ms: the jump starts the probe that turns it back on;
//   - a probe stops drawing the other variant once two of its counted frames have a median over `give_up_ratio`
//     times the kept variant's recent median (its last 8 measured frames), so that a probe of a much slower variant
//     costs a few frames;
//   - a host with no room in a frame for the other variant (a governor near its budget) says so, and no probe draws
//     in that frame: one under way is given up, one due waits for a frame with room;
//   - measured times may come back any number of frames late (a timer query read late); frames never measured (a
//     host's untimed draws) only delay a probe: nothing is probed before `min_kept` frames of the kept variant were
//     measured, so a host's untimed first draws all see the first variant, and a probe whose frames stay unmeasured
//     for `max_in_flight` frames is given up.
// No OpenGL and no clock: the host reports what it measured (eval's GpuCullRun does so for `gpu_occlusion=auto`).
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <vector>

namespace farfield::runtime {

struct FasterVariantOptions {
  size_t min_kept = 4;          // measured frames of the kept variant before a probe (1..8)
  size_t probe_runs = 4;        // runs of two frames of each variant a probe draws (>= 1; even: balanced)
  double margin = 0.05;         // share by which the other variant must be faster to be kept, in [0, 1)
  size_t reprobe_after = 120;   // frames from a decision to the next probe (>= 1)
  size_t reprobe_max = 960;     // the interval's ceiling while decisions stand (>= reprobe_after)
  double give_up_ratio = 1.25;  // a probe whose frames take this many times the kept one's stops early (> 1)
  double change_ratio = 1.4;    // a departure of the kept variant's frames from their level that probes early (> 1)
  size_t max_in_flight = 64;    // decided frames kept waiting for their measurement (>= 4 x probe_runs)
};

class FasterVariant {
 public:
  // Variants are 0 and 1; `first` is kept until a probe finds the other faster. Throws farfield::Error for bad
  // options or a variant other than 0 or 1.
  explicit FasterVariant(int first = 0, FasterVariantOptions options = {});

  // The variant frame `frame` draws; frames increase from call to call (a repeated or older frame throws
  // farfield::Error). `room` false: the host has no room in this frame for a frame of the other variant (a governor
  // near its budget: a probe's first frame pays for the switch), so no probe starts, and a probe under way is given
  // up (counted: probesHeld); a probe that was due starts at the first frame with room.
  int decide(uint64_t frame, bool room = true);
  // The measured time of a decided frame (ms >= 0 and finite, else farfield::Error); frames never decided, or too
  // old, are ignored.
  void measured(uint64_t frame, double ms);

  // A host that timed both variants on the same frames (a governor's calibration) starts the chooser from those
  // times instead of its first probe: the variant not kept becomes kept only where faster by the margin, as a probe
  // would decide, and the next probe comes `reprobe_after` frames later; the level a change of the workload is seen
  // against is taken from the first `min_kept` measured frames (the host's times may be taken unlike them). Throws
  // farfield::Error during a probe or for a time that is negative or not finite.
  void startFrom(double ms_of_0, double ms_of_1);

  int kept() const { return kept_; }
  size_t probes() const { return probes_; }          // probes started
  size_t probesGivenUp() const { return given_up_; }  // stopped early (a much slower variant) or never measured
  size_t switches() const { return switches_; }       // decisions that changed the kept variant
  size_t earlyProbes() const { return early_probes_; }  // probes started by a change of the workload
  size_t starts() const { return starts_; }              // startFrom calls
  size_t probesHeld() const { return held_; }            // probes given up for want of room (decide's `room`)
  size_t framesOf(int variant) const { return frames_of_[size_t(variant & 1)]; }  // frames decided per variant

 private:
  struct InFlight {
    uint64_t frame = 0;
    int variant = 0;
    size_t probe = 0;      // the probe it was drawn for (probes_ then), 0: none
    bool counted = false;  // a probe frame that is not the first of its run
  };
  void finishProbe(bool given_up);
  void finishProbeIfDone();
  double recentKeptMedian() const;
  bool workloadChanged() const;

  FasterVariantOptions options_;
  int kept_ = 0;
  std::deque<InFlight> in_flight_;
  bool probing_ = false;
  size_t probe_step_ = 0;           // frames the current probe has drawn
  size_t probe_unmeasured_ = 0;     // ... of which not yet measured
  std::vector<double> probe_ms_[2];  // its counted frames' times, per variant
  std::deque<double> recent_kept_;  // the kept variant's last measured times outside probes
  uint64_t next_probe_ = 0;
  double level_ = 0.0;        // the kept variant's frame time at the last decision, 0: none yet
  uint64_t probe_ended_ = 0;  // the last frame decided when the last probe ended
  size_t interval_ = 0;
  bool any_decided_ = false;
  uint64_t last_frame_ = 0;
  size_t probes_ = 0, given_up_ = 0, switches_ = 0, early_probes_ = 0, starts_ = 0, held_ = 0;
  size_t frames_of_[2] = {0, 0};
};

}  // namespace farfield::runtime
