// Douglas-Peucker simplification (Sillion et al. 1997, section 4.2: the contour and the discrepancy chains are
// approximated by polylines within a tolerance in pixels).
#include "farfield/core/douglas_peucker.h"

#include <algorithm>
#include <utility>

#include "farfield/core/polygon2d.h"

namespace farfield {

std::vector<size_t> douglasPeuckerIndices(const std::vector<DVec2>& points, double tolerance) {
  const size_t n = points.size();
  std::vector<size_t> kept;
  if (n < 3) {
    for (size_t i = 0; i < n; ++i) kept.push_back(i);
    return kept;
  }
  // Iterative (explicit stack): chains of thousands of pixels would recurse deeply.
  std::vector<char> keep(n, 0);
  keep[0] = keep[n - 1] = 1;
  std::vector<std::pair<size_t, size_t>> stack{{0, n - 1}};
  while (!stack.empty()) {
    const auto [first, last] = stack.back();
    stack.pop_back();
    if (last <= first + 1) continue;
    double worst = -1.0;
    size_t worst_index = first;
    for (size_t i = first + 1; i < last; ++i) {
      const double d = distancePointSegmentD(points[i], points[first], points[last]);
      if (d > worst) {
        worst = d;
        worst_index = i;
      }
    }
    // With tolerance <= 0, points exactly on the segment still go (they change nothing).
    if (worst > tolerance || (tolerance <= 0.0 && worst > 0.0)) {
      keep[worst_index] = 1;
      stack.push_back({first, worst_index});
      stack.push_back({worst_index, last});
    }
  }
  for (size_t i = 0; i < n; ++i)
    if (keep[i]) kept.push_back(i);
  return kept;
}

std::vector<DVec2> simplifyPolyline(const std::vector<DVec2>& points, double tolerance) {
  std::vector<DVec2> out;
  for (size_t i : douglasPeuckerIndices(points, tolerance)) out.push_back(points[i]);
  return out;
}

std::vector<DVec2> simplifyClosed(const std::vector<DVec2>& polygon, double tolerance) {
  const size_t n = polygon.size();
  if (n <= 3) return polygon;
  // Anchor the loop at point 0 and at the point farthest from it: both are extreme enough to survive any
  // simplification of a non-degenerate loop.
  size_t far_index = 0;
  double far_dist = -1.0;
  for (size_t i = 1; i < n; ++i) {
    const double d = glm::length(polygon[i] - polygon[0]);
    if (d > far_dist) {
      far_dist = d;
      far_index = i;
    }
  }
  if (far_dist <= 0.0) return {polygon[0]};
  std::vector<DVec2> first_half(polygon.begin(), polygon.begin() + std::ptrdiff_t(far_index) + 1);
  std::vector<DVec2> second_half(polygon.begin() + std::ptrdiff_t(far_index), polygon.end());
  second_half.push_back(polygon[0]);
  std::vector<DVec2> out = simplifyPolyline(first_half, tolerance);
  const std::vector<DVec2> tail = simplifyPolyline(second_half, tolerance);
  out.pop_back();  // far point, repeated as the tail's first
  out.insert(out.end(), tail.begin(), tail.end() - 1);  // tail ends with point 0 again
  if (out.size() < 3) {
    // Both halves collapsed onto the chord: keep the farthest point from the chord so the loop keeps an area.
    size_t best = 0;
    double best_d = -1.0;
    for (size_t i = 0; i < n; ++i) {
      const double d = distancePointSegmentD(polygon[i], polygon[0], polygon[far_index]);
      if (d > best_d) {
        best_d = d;
        best = i;
      }
    }
    if (best_d <= 0.0) return out;
    out = {polygon[0]};
    if (best < far_index) {
      out.push_back(polygon[best]);
      out.push_back(polygon[far_index]);
    } else {
      out.push_back(polygon[far_index]);
      out.push_back(polygon[best]);
    }
  }
  return out;
}

}  // namespace farfield
