// The measured cost of skinned triangles, for a geometry budget given in milliseconds: each frame's skinned draws
// are timed (milliseconds, triangles), the cost per triangle is a moving average of those frames, and a budget in
// milliseconds becomes the triangles that cost would fit, divided by a safety factor: the largest measured /
// predicted ratio of the last frames (as `farfield calibrate` states its bound by the largest ratio it measured), so
// that a frame drawn like the recent ones stays within the budget. The cost follows the renderer and what it draws
// (figure sizes, levels of detail) within a few frames; a frame that drew too few triangles to say anything is left
// out.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace farfield::runtime {

class TriangleRate {
 public:
  // weight: the newest frame's share of the average (0, 1]; min_triangles: frames with fewer are not observed;
  // first_triangles: the budget before any frame was observed; window: the frames whose measured / predicted ratios
  // set the safety factor (at least 1).
  explicit TriangleRate(double weight = 0.3, uint64_t min_triangles = 1000, uint64_t first_triangles = 10000,
                        size_t window = 16);

  void observe(double ms, uint64_t triangles);
  // Triangles whose estimated time, times the safety factor, is at most `ms` (first_triangles before any
  // observation; at least 0).
  uint64_t trianglesFor(double ms) const;
  bool known() const { return ms_per_triangle_ > 0.0; }
  double msPerTriangle() const { return ms_per_triangle_; }
  // The largest measured / predicted ratio of the last `window` observed frames, at least 1 (1 before two frames).
  double safetyFactor() const;

 private:
  double weight_;
  uint64_t min_triangles_, first_triangles_;
  size_t window_;
  double ms_per_triangle_ = 0.0;
  std::vector<double> ratios_;  // ring of the last `window` measured / predicted ratios
  size_t next_ratio_ = 0;
};

}  // namespace farfield::runtime
