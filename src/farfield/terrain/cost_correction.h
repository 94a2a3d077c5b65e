// What LOD-sprite's cost model (terrain_cost.h) got wrong on the frames it drew, from their measured times: the
// closed loop of the per-frame choice (path_choice.h), so that the choice holds on a machine whose frames the model,
// fitted on a few views at start, predicts badly (on an NVIDIA H200 it under-predicted sprite frames by 1.5-2.6x at
// the median; on llvmpipe 1.2-1.5x).
//
// Each frame the renderer says what it drew, with the model's prediction of its parts: a high-LOD frame, a sprite
// frame, a sprite frame that also drew a keyframe (Fresh), or one that also drew a slice of a keyframe rendered ahead.
// Measured times come back later (a timer query read one or more frames late, or a harness's wall time), any order;
// a measurement is used only once `lag` frames have been drawn after its frame, as a timer query would arrive. Per
// kind, the correction is the median of measured / predicted over its last `samples` measurements within the last
// `forget_frames` frames, 1 where there are fewer than `min_samples`: a kind that is no longer drawn (the high LOD while
// sprites win) falls back to the model's own prediction, so that a few slow frames cannot lock a path out for long. A
// keyframe's or a slice's part is what its frame measured beyond the sprite frame's prediction corrected by the
// sprite frames' factor of now, over its predicted part.
// Pure logic: no GL, no clock.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>

namespace farfield::terrain {

enum class TerrainFrameKind : uint8_t { High, Sprite, Keyframe, Slice };
constexpr size_t kTerrainFrameKinds = 4;
const char* terrainFrameKindName(TerrainFrameKind kind);

struct CostCorrectionOptions {
  size_t lag = 2;               // frames drawn after a measured one before its measurement counts (>= 0)
  size_t samples = 31;          // measurements per kind the median is over (>= min_samples)
  size_t min_samples = 3;       // fewer measurements of a kind than this: its factor is 1 (>= 1)
  uint64_t forget_frames = 120; // measurements older than this many frames are forgotten (>= 1)
  double min_ratio = 0.1;       // each measured / predicted ratio is clamped to [min_ratio, max_ratio]
  double max_ratio = 10.0;
};

class CostCorrection {
 public:
  // Throws farfield::Error for options out of range.
  explicit CostCorrection(const CostCorrectionOptions& options = {});

  // Frame `frame` (increasing from call to call) was drawn as `kind`; base_ms: the model's prediction of its high-LOD
  // frame (High) or its sprite frame (the others); extra_ms: of the keyframe or the slice it also drew (0 for High and
  // Sprite). Predictions must be >= 0; a kind with a prediction of 0 learns nothing from its frame.
  void drawn(uint64_t frame, TerrainFrameKind kind, double base_ms, double extra_ms = 0.0);
  // The measured time of frame `frame`, ms; frames never drawn, measured twice, or older than the frames kept are
  // ignored (returns false).
  bool measured(uint64_t frame, double ms);

  // measured / predicted of a kind's frames (High, Sprite) or parts (Keyframe, Slice): 1 without measurements.
  double factor(TerrainFrameKind kind) const;
  size_t measurementsUsed() const { return used_; }
  void reset();

 private:
  struct Drawn {
    uint64_t frame;
    TerrainFrameKind kind;
    double base_ms, extra_ms;
    double measured_ms = -1.0;
  };
  struct Sample {
    uint64_t frame;
    double measured_ms, base_ms, extra_ms;
  };
  void take(const Drawn& d);
  CostCorrectionOptions options_;
  std::deque<Drawn> drawn_;  // recent frames, oldest first, with their measurement once it came
  std::array<std::deque<Sample>, kTerrainFrameKinds> samples_;
  uint64_t latest_ = 0;
  bool any_ = false;
  size_t used_ = 0;
};

}  // namespace farfield::terrain
