#include "farfield/runtime/triangle_rate.h"

#include <cmath>

#include "farfield/core/error.h"

namespace farfield::runtime {

TriangleRate::TriangleRate(double weight, uint64_t min_triangles, uint64_t first_triangles)
    : weight_(weight), min_triangles_(min_triangles), first_triangles_(first_triangles) {
  if (!(weight > 0.0 && weight <= 1.0)) throw Error("triangle rate", "the newest frame's weight must be in (0, 1]");
}

void TriangleRate::observe(double ms, uint64_t triangles) {
  if (triangles < min_triangles_ || !(ms >= 0.0) || !std::isfinite(ms)) return;
  const double rate = ms / double(triangles);
  ms_per_triangle_ = known() ? (1.0 - weight_) * ms_per_triangle_ + weight_ * rate : rate;
}

uint64_t TriangleRate::trianglesFor(double ms) const {
  if (!known()) return first_triangles_;
  if (!(ms > 0.0)) return 0;
  return uint64_t(std::floor(ms / ms_per_triangle_));
}

}  // namespace farfield::runtime
