#include "farfield/terrain/cost_correction.h"

#include <algorithm>
#include <string>
#include <vector>

#include "farfield/core/error.h"

namespace farfield::terrain {
namespace {

// Frames kept waiting for their measurement: a timer query is read within a few frames.
constexpr uint64_t kKeepFrames = 64;

}  // namespace

const char* terrainFrameKindName(TerrainFrameKind kind) {
  switch (kind) {
    case TerrainFrameKind::High: return "high";
    case TerrainFrameKind::Sprite: return "sprite";
    case TerrainFrameKind::Keyframe: return "keyframe";
    case TerrainFrameKind::Slice: return "slice";
  }
  return "?";
}

CostCorrection::CostCorrection(const CostCorrectionOptions& options) : options_(options) {
  if (options.min_samples < 1 || options.samples < options.min_samples || options.forget_frames < 1 ||
      options.lag >= kKeepFrames)
    throw Error("cost correction", "needs 1 <= min_samples <= samples, forget_frames >= 1 and lag < " +
                                       std::to_string(kKeepFrames));
  if (!(options.min_ratio > 0.0) || !(options.max_ratio >= options.min_ratio))
    throw Error("cost correction", "needs 0 < min_ratio <= max_ratio");
}

void CostCorrection::reset() {
  drawn_.clear();
  for (auto& s : samples_) s.clear();
  latest_ = 0;
  any_ = false;
  used_ = 0;
}

void CostCorrection::drawn(uint64_t frame, TerrainFrameKind kind, double base_ms, double extra_ms) {
  if (any_ && frame <= latest_) throw Error("cost correction", "frames must increase from call to call");
  if (!(base_ms >= 0.0) || !(extra_ms >= 0.0)) throw Error("cost correction", "predictions must be >= 0");
  any_ = true;
  latest_ = frame;
  drawn_.push_back({frame, kind, base_ms, extra_ms});
  // Measurements old enough now count; frames never measured are dropped once too old to be.
  for (Drawn& d : drawn_)
    if (d.measured_ms >= 0.0 && d.frame + options_.lag <= latest_) {
      take(d);
      d.measured_ms = -2.0;  // taken
    }
  while (!drawn_.empty() && (drawn_.front().measured_ms == -2.0 || drawn_.front().frame + kKeepFrames < latest_))
    drawn_.pop_front();
  for (auto& s : samples_)
    while (!s.empty() && s.front().frame + options_.forget_frames < latest_) s.pop_front();
}

bool CostCorrection::measured(uint64_t frame, double ms) {
  if (!(ms >= 0.0)) return false;
  for (Drawn& d : drawn_) {
    if (d.frame != frame) continue;
    if (d.measured_ms != -1.0) return false;  // measured before
    d.measured_ms = ms;
    if (d.frame + options_.lag <= latest_) {
      take(d);
      d.measured_ms = -2.0;
    }
    return true;
  }
  return false;
}

void CostCorrection::take(const Drawn& d) {
  const bool whole = d.kind == TerrainFrameKind::High || d.kind == TerrainFrameKind::Sprite;
  if (!((whole ? d.base_ms : d.extra_ms) > 0.0)) return;
  std::deque<Sample>& s = samples_[size_t(d.kind)];
  s.push_back({d.frame, d.measured_ms, d.base_ms, d.extra_ms});
  while (s.size() > options_.samples) s.pop_front();
  ++used_;
}

double CostCorrection::factor(TerrainFrameKind kind) const {
  const std::deque<Sample>& s = samples_[size_t(kind)];
  const bool whole = kind == TerrainFrameKind::High || kind == TerrainFrameKind::Sprite;
  // A part's sprite frame by the sprite frames' correction now (not the one when it was measured, which may have
  // rested on fewer of them).
  const double sprite = whole ? 1.0 : factor(TerrainFrameKind::Sprite);
  std::vector<double> r;
  r.reserve(s.size());
  for (const Sample& x : s) {
    if (x.frame + options_.forget_frames < latest_) continue;
    const double ratio = whole ? x.measured_ms / x.base_ms : (x.measured_ms - sprite * x.base_ms) / x.extra_ms;
    r.push_back(std::clamp(ratio, options_.min_ratio, options_.max_ratio));
  }
  if (r.size() < options_.min_samples) return 1.0;
  const size_t mid = r.size() / 2;
  std::nth_element(r.begin(), r.begin() + std::ptrdiff_t(mid), r.end());
  if (r.size() % 2 == 1) return r[mid];
  const double upper = r[mid];
  return 0.5 * (upper + *std::max_element(r.begin(), r.begin() + std::ptrdiff_t(mid)));
}

}  // namespace farfield::terrain
