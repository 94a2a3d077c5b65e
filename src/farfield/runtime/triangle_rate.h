// The measured cost of skinned triangles, for a geometry budget given in milliseconds: each frame's skinned draws
// are timed (milliseconds, triangles), the cost per triangle is a moving average of those frames, and a budget in
// milliseconds becomes the triangles that cost would fit. The cost follows the renderer and what it draws (figure
// sizes, levels of detail) within a few frames; a frame that drew too few triangles to say anything is left out.
#pragma once

#include <cstdint>

namespace farfield::runtime {

class TriangleRate {
 public:
  // weight: the newest frame's share of the average (0, 1]; min_triangles: frames with fewer are not observed;
  // first_triangles: the budget before any frame was observed.
  explicit TriangleRate(double weight = 0.3, uint64_t min_triangles = 1000, uint64_t first_triangles = 10000);

  void observe(double ms, uint64_t triangles);
  // Triangles whose estimated time is at most `ms` (first_triangles before any observation; at least 0).
  uint64_t trianglesFor(double ms) const;
  bool known() const { return ms_per_triangle_ > 0.0; }
  double msPerTriangle() const { return ms_per_triangle_; }

 private:
  double weight_;
  uint64_t min_triangles_, first_triangles_;
  double ms_per_triangle_ = 0.0;
};

}  // namespace farfield::runtime
