// The loop around a FrameGovernor (runtime/frame_governor.h) for a host that draws and times its frames: the levels'
// pixels and triangle shares, a cost model fitted on the host's own frames, and the frames in flight until what the
// GPU tells about them (their triangles, their time) comes back, any number of frames late. No OpenGL and no clock:
// the host draws each level, times it, reads its statistics and reports them here (eval/governed_mode.h does so in
// the benchmark; an engine does so with its own timer queries).
//
// The model (gpu::CostModel: base + per million triangles + per million pixels) is fitted on the calibration (frames
// of one view drawn at every level, timed with waits: the host's loading frame) and on the last `recent` measured
// frames, again every `refit_every` of them. The triangle term is fitted only once the samples' triangles vary (a
// single view's triangles are about the same at every level, and a fit would take them for the base cost). A frame
// is predicted at each level from the triangles of the last frame whose count came back, moved to that level by the
// share of the full level's triangles each level drew in the calibration, and the level's pixels.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "farfield/gpu/cost_model.h"
#include "farfield/runtime/frame_governor.h"

namespace farfield::runtime {

struct LoopLevel {
  GovernorLevel governor;  // its name and the bound it keeps
  double pixels = 0.0;     // pixels it renders (> 0)
};

struct GovernorLoopOptions {
  GovernorOptions governor;
  size_t lag = 2;            // frames a measured time is held before the governor takes it (>= 1), as a timer
                             // query read late
  size_t recent = 120;       // measured frames the model is refitted over, with the calibration (>= 1)
  size_t refit_every = 16;   // measured frames between refits (>= 1)
  size_t max_in_flight = 64; // decided frames kept waiting for their measurement (>= lag + 1)
};

class GovernorLoop {
 public:
  // Throws farfield::Error for no level, a level without pixels, or bad options (and FrameGovernor's errors).
  GovernorLoop(std::vector<LoopLevel> levels, GovernorLoopOptions options);

  // The calibration: a frame drawn at `level` that drew `triangles` and took `ms`. finishCalibration() takes each
  // level's share of the full level's triangles from its last sample and fits the model; decide() needs it first.
  void calibrationSample(size_t level, double triangles, double ms);
  void finishCalibration();
  bool calibrated() const { return calibrated_; }

  // The level of frame `frame` (increasing from call to call): measured times at least `lag` frames old go to the
  // governor first. Throws farfield::Error before finishCalibration().
  // workload (> 0, optional): what the host knows of this frame's load before drawing it, in any unit that scales
  // with its triangles (a walkthrough's plan: the triangles of the objects it draws). The triangles the frame is
  // predicted from, the last frame's that came back, are then scaled by this frame's workload over that frame's, so
  // that a new plan (a region whose visible set is twice as large) is seen in its first frame rather than two frames
  // later. 0: unknown (no scaling).
  GovernorDecision decide(uint64_t frame, double workload = 0.0);
  // What came back about a decided frame; frames never decided, or too old, are ignored.
  void frameTriangles(uint64_t frame, double triangles);
  void frameMeasured(uint64_t frame, double ms);

  const FrameGovernor& governor() const { return governor_; }
  const gpu::CostModel& model() const { return model_; }
  double triangleShare(size_t level) const { return shares_.at(level); }
  size_t levelCount() const { return levels_.size(); }
  // Per frame the governor took: its measured time over the model's prediction and over the corrected one.
  const std::vector<double>& measuredOverPredicted() const { return ratio_; }
  const std::vector<double>& measuredOverCorrected() const { return corrected_ratio_; }

 private:
  struct Sample {
    double triangles = 0.0, pixels = 0.0, ms = 0.0;
  };
  struct InFlight {
    uint64_t frame = 0;
    GovernorDecision decision;
    double triangles = -1.0;    // -1 until it comes back
    double measured_ms = -1.0;  // -1 until it comes back
    double workload = 0.0;      // decide's
  };
  void refit();
  void deliver(uint64_t now);
  InFlight* find(uint64_t frame);

  std::vector<LoopLevel> levels_;
  GovernorLoopOptions options_;
  FrameGovernor governor_;
  gpu::CostModel model_;
  std::vector<double> shares_;
  std::vector<Sample> calibration_;
  std::vector<double> calibration_triangles_;  // per level, the last calibration sample's
  std::vector<Sample> recent_;
  size_t recent_next_ = 0, since_refit_ = 0;
  bool calibrated_ = false;
  double last_triangles_ = 0.0;  // of the last frame whose count came back ...
  size_t last_level_ = 0;        // ... drawn at this level
  double last_workload_ = 0.0;   // ... with this workload (decide's; 0: unknown)
  std::vector<InFlight> in_flight_;
  std::vector<double> ratio_, corrected_ratio_;
};

}  // namespace farfield::runtime
