// The fill estimate of a layered impostor: see layered_fill.h.
#include "farfield/impostor/layered_fill.h"

#include <algorithm>
#include <cmath>

namespace farfield::impostor {

double layeredFillPixels(const LayeredPlan& plan, double distance, const ErrorBound& frame) {
  const double d = std::max(distance, double(plan.shaft.min_distance));
  const double cos_theta = std::cos(0.5 * double(plan.shaft.apex_angle));
  const double focal = frame.focalPixels();
  const double cap = double(frame.width) * double(frame.height);
  // Never nearer than a hundredth of the distance: a quad that close fills the frame anyway (the cap).
  const double floor = 1e-2 * d;
  double sum = 0.0;
  for (const LayerPlan& layer : plan.layers) {
    const double gap = std::max({d - plan.radius, d * cos_theta - double(layer.depth), floor});
    const double pixels = 4.0 * double(layer.half_u) * double(layer.half_v) * focal * focal / (gap * gap);
    sum += std::min(pixels, cap) * double(layer.cover);
  }
  return sum;
}

}  // namespace farfield::impostor
