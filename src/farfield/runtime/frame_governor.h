// The frame governor: the frame budget t_max kept in a closed loop (DESIGN.md, "the two promises").
//
// Placement keeps t_max open-loop, from a cost model's predictions (Jeschke et al. 2005); a model is only as right as
// the frames it was fitted on, and the running walkthrough draws others (culling, uploads, the machine's other
// work). Funkhouser and Sequin (1993) re-make a cost-benefit choice every frame; engines close the loop with measured
// frame times (dynamic resolution, LOD bias). The governor does both: before each frame it takes the model's
// prediction of that frame at each of a few coarser levels (finest first), corrects it by what the model got wrong on
// recent frames (their measured times, which may arrive one or more frames late, as GPU timer queries do), and
// chooses the finest level whose corrected prediction stays under t_max with a margin.
//
// The correction is conservative: over the last `window` measured frames, the largest measured / predicted ratio r
// and the largest measured - predicted difference d; a prediction p is corrected to min(p * r, p + d) (as the cost
// profile's bound, gpu/cost_profile.h: both bound every remembered frame, so their minimum does). Before the first
// measurement a prediction is taken cold_ratio times larger (r = cold_ratio, d = infinity): a model fitted on quiet
// frames under-predicts a running walkthrough's first frames (on llvmpipe the bench's interleaved frames were 18-50 %
// slower than the same views drawn alone), and the first measurement arrives frames late.
//
// Coarsening is immediate (the frame about to be drawn is the one that must not break t_max); refining is slow: one
// level at a time, after the finer level's corrected prediction has stayed under refine_below * t_max on
// refine_after consecutive frames. The gap between aim and refine_below is the hysteresis that keeps a constant load
// from oscillating between two levels.
//
// Each level states the error bound it keeps as a multiple of the promised one (GovernorLevel::bound_scale), so a
// host reports every coarsened frame with the bound it actually kept.
//
// No OpenGL, no clock: a host (eval/governed_mode.h, an engine) predicts, draws, times and reports back.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <span>
#include <string>
#include <vector>

namespace farfield::runtime {

struct GovernorLevel {
  std::string name;          // for reports, e.g. "full", "0.71x resolution"
  double bound_scale = 1.0;  // the error bound kept at this level / the promised bound (>= 1; 1 = not relaxed)
};

struct GovernorOptions {
  double t_max_ms = 0.0;      // the frame budget, > 0
  double aim = 0.9;           // a level is taken when its corrected prediction is at most aim * t_max (0 < aim <= 1)
  double refine_below = 0.7;  // a finer level is taken back when its corrected prediction is at most
                              // refine_below * t_max (0 < refine_below <= aim) ...
  size_t refine_after = 10;   // ... on this many consecutive frames (>= 1)
  size_t window = 60;         // measured frames the correction remembers (>= 1)
  size_t max_pending = 16;    // frames decided but not yet measured that are kept; older ones are dropped (>= 1)
  double cold_ratio = 1.0;    // before the first measurement, predictions are multiplied by this (>= 1; 1 = the
                              // model is trusted until a frame is measured)
};

// What was decided for one frame.
struct GovernorDecision {
  size_t level = 0;
  double predicted_ms = 0.0;  // the model's prediction at that level
  double corrected_ms = 0.0;  // after the correction: what the governor expects the frame to take
  double bound_scale = 1.0;   // the level's (GovernorLevel::bound_scale)
  bool relaxed = false;       // bound_scale > 1
  bool over = false;          // even the coarsest level is expected over t_max (the coarsest is taken)
};

class FrameGovernor {
 public:
  // Throws farfield::Error for no level, a level with bound_scale < 1 or not finite, or bad options.
  FrameGovernor(std::vector<GovernorLevel> levels, GovernorOptions options);

  // Chooses the level of frame `frame` (increasing from call to call) from the model's prediction of it at every
  // level (predicted_ms[i] for levels()[i], ms, >= 0). Throws farfield::Error for a wrong count or a negative or
  // non-finite prediction.
  GovernorDecision decide(uint64_t frame, std::span<const double> predicted_ms);

  // The measured time of a decided frame, any number of frames late. A frame that was never decided, was already
  // measured or was dropped from the pending ones is ignored (counted: Statistics::ignored_measurements). Throws
  // farfield::Error for a negative or non-finite time.
  void measured(uint64_t frame, double measured_ms);

  // The correction of a prediction by the remembered frames (x cold_ratio before any measurement).
  double corrected(double predicted_ms) const;

  size_t level() const { return level_; }
  const std::vector<GovernorLevel>& levels() const { return levels_; }
  const GovernorOptions& options() const { return options_; }

  struct Statistics {
    size_t frames = 0;               // decided
    size_t measurements = 0;         // measured times taken
    size_t ignored_measurements = 0;
    size_t measured_over = 0;        // measured frames over t_max
    size_t coarsenings = 0;          // decisions that moved to a coarser level
    size_t refinements = 0;          // ... to a finer one
    size_t relaxed_frames = 0;       // decided at a level with bound_scale > 1
    size_t predicted_over_frames = 0;  // decided with GovernorDecision::over
    std::vector<size_t> frames_at_level;
  };
  const Statistics& statistics() const { return stats_; }

 private:
  struct Pending {
    uint64_t frame = 0;
    double predicted_ms = 0.0;
  };
  struct Residual {
    double ratio = 1.0;
    double difference = 0.0;
  };
  std::vector<GovernorLevel> levels_;
  GovernorOptions options_;
  size_t level_ = 0;
  size_t refine_streak_ = 0;
  bool has_frame_ = false;
  uint64_t last_frame_ = 0;
  std::deque<Pending> pending_;   // decided, not measured; ascending frames
  std::deque<Residual> residuals_;  // the last `window` measured frames
  Statistics stats_;
};

}  // namespace farfield::runtime
