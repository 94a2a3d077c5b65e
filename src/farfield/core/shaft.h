// Shaft view cells (Jeschke et al. 2005, section 4, Figure 5): the viewpoints that see an object cluster from a
// limited angular range around one direction and from at least a minimum distance. The apex is at the cluster's
// centre; the shaft opens along `axis` towards the viewers.
//
//   shaft = { p : |p - apex| >= min_distance and angle(p - apex, axis) <= apex_angle / 2 }
//
// Apex angles up to 180 degrees keep the cone convex, which the box tests below rely on.
#pragma once

#include <optional>

#include "farfield/core/bounds.h"
#include "farfield/core/math.h"

namespace farfield {

struct Shaft {
  Vec3 apex{0.0f};             // the object cluster's centre
  Vec3 axis{1.0f, 0.0f, 0.0f}; // unit direction from the apex towards the viewpoints
  float apex_angle = 0.0f;     // full opening angle, radians, in (0, pi]
  float min_distance = 0.0f;   // metres from the apex, >= 0

  // Throws farfield::Error (naming `what`) for a non-finite apex, a zero or non-finite axis, an apex angle outside
  // (0, pi] or a negative minimum distance. The axis is normalised.
  static Shaft make(const Vec3& apex, const Vec3& axis, float apex_angle, float min_distance,
                    const char* what = "shaft");
  // The shaft from `apex` around a box view cell (a rectangular cell planned as a shaft, Jeschke et al. 2005 test
  // 13): the axis through the box's centre, the apex angle twice the largest angle of a corner to it, the minimum
  // distance the box's nearest point. containsBox(box) holds for it, so whatever holds from every viewpoint of the
  // shaft (a layered plan's error bound) holds from every viewpoint of the box. Empty when the box is empty, holds
  // the apex, or is not within a cone of at most 180 degrees (no convex shaft holds it).
  static std::optional<Shaft> enclosing(const Vec3& apex, const Box3& box);

  bool contains(const Vec3& p) const;
  // Every point of the box is in the shaft (the box's corners are in the cone, which is convex, and its nearest point
  // to the apex is at least min_distance away). Conservative: false when in doubt. An empty box is not enclosed.
  bool containsBox(const Box3& box) const;
  // The box may share points with the shaft (false only when it certainly does not: it lies inside the ball of
  // min_distance, or entirely outside the cone's bounding half-space test). Conservative towards true.
  bool mayIntersectBox(const Box3& box) const;
  // A point of the shaft between min_distance and max_distance from u, v, w in [0, 1]^3 (u: distance, v and w: the
  // direction within the cone, uniformly over its solid angle). For sampling viewpoints in tests and estimates.
  Vec3 sample(float u, float v, float w, float max_distance) const;
};

}  // namespace farfield
