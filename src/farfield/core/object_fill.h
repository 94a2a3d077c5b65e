// How many frame pixels an object may cover, estimated before anything is drawn: the fill term of the frame cost
// model (gpu/cost_model.h). On a fill-bound renderer (llvmpipe shades every fragment on the CPU) a street view's time
// follows how much of the frame its near buildings cover, overdraw included, more than its triangles or draw calls;
// a linear model without it charges every frame the fill of a typical one as a fixed cost.
//
// The estimate is the screen area of the object's bounding sphere (centre: the box's centre, radius: half its
// diagonal) seen at the centre of the frame, capped at the whole frame (an object seen from inside its sphere covers
// at most the frame). A frame's fill is the sum over the objects it draws, so overdraw counts.
//
// From a region of viewpoints the estimate takes the region's nearest point to the centre: it is at least the
// estimate from every viewpoint in the region (the area grows as the distance falls), which is what a conservative
// time bound over the region needs (Jeschke et al. 2005, section 3.2, enclosing frusta).
#pragma once

#include <algorithm>
#include <cmath>

#include "farfield/core/bounds.h"

namespace farfield {

struct FillLens {
  double focal_px = 0.0;      // pixels per unit of tangent at the centre: 0.5 * height / tan(fov_y / 2)
  double frame_pixels = 0.0;  // width * height: no object covers more

  static FillLens of(int width, int height, double fov_y_rad) {
    return {0.5 * double(height) / std::tan(0.5 * fov_y_rad), double(width) * double(height)};
  }

  // The area of a sphere of `radius` whose centre is `distance` away: pi f^2 r^2 / (d^2 - r^2), capped at the frame.
  double spherePixels(double distance, double radius) const {
    const double gap = distance * distance - radius * radius;
    if (!(gap > 0.0)) return frame_pixels;
    return std::min(frame_pixels, 3.14159265358979323846 * focal_px * focal_px * radius * radius / gap);
  }
  // An object's estimate from one viewpoint.
  double objectPixels(const Box3& bounds, const Vec3& eye) const {
    if (bounds.empty()) return 0.0;
    return spherePixels(double(glm::length(eye - bounds.center())), 0.5 * double(glm::length(bounds.extent())));
  }
  // An object's estimate from the nearest viewpoint of `region` (>= objectPixels from any eye in it).
  double objectPixels(const Box3& bounds, const Box3& region) const {
    if (bounds.empty()) return 0.0;
    const Vec3 c = bounds.center();
    return spherePixels(double(glm::length(glm::clamp(c, region.lo, region.hi) - c)),
                        0.5 * double(glm::length(bounds.extent())));
  }
};

}  // namespace farfield
