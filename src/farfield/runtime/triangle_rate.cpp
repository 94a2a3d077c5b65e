#include "farfield/runtime/triangle_rate.h"

#include <algorithm>
#include <cmath>

#include "farfield/core/error.h"

namespace farfield::runtime {

TriangleRate::TriangleRate(double weight, uint64_t min_triangles, uint64_t first_triangles, size_t window)
    : weight_(weight), min_triangles_(min_triangles), first_triangles_(first_triangles), window_(window) {
  if (!(weight > 0.0 && weight <= 1.0)) throw Error("triangle rate", "the newest frame's weight must be in (0, 1]");
  if (window < 1) throw Error("triangle rate", "the safety factor's window must hold at least one frame");
}

void TriangleRate::observe(double ms, uint64_t triangles) {
  if (triangles < min_triangles_ || !(ms >= 0.0) || !std::isfinite(ms)) return;
  const double rate = ms / double(triangles);
  if (known()) {
    const double ratio = rate / ms_per_triangle_;  // measured / predicted for this frame
    if (ratios_.size() < window_)
      ratios_.push_back(ratio);
    else
      ratios_[next_ratio_] = ratio;
    next_ratio_ = (next_ratio_ + 1) % window_;
    ms_per_triangle_ = (1.0 - weight_) * ms_per_triangle_ + weight_ * rate;
  } else {
    ms_per_triangle_ = rate;
  }
}

double TriangleRate::safetyFactor() const {
  double worst = 1.0;
  for (double r : ratios_) worst = std::max(worst, r);
  return worst;
}

uint64_t TriangleRate::trianglesFor(double ms) const {
  if (!known()) return first_triangles_;
  if (!(ms > 0.0)) return 0;
  return uint64_t(std::floor(ms / (ms_per_triangle_ * safetyFactor())));
}

}  // namespace farfield::runtime
