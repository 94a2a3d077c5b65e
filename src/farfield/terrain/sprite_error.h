// LOD-sprite error metric, Chen et al. 1999 section 3.2 (equations 1 and 2).
//
// For a low-resolution quadrant with true central vertex C (a grid point the low-resolution mesh skips) and corners
// Q_k, the estimated central vertex is C^ = the mean of the corners (for a 3-corner diamond on the grid boundary,
// the midpoint of its two corners on the boundary line, which lies above C like C^ does). The keyframe, rendered
// from v1, shows C where the ray v1 -> C meets the low-resolution surface: C' = the intersection of that ray with
// the plane spanned by C^ and two corners Q_k, Q_k+1 of the quadrant. Which two the paper leaves open; we take the
// fan triangle (C^, Q_k, Q_k+1) the ray actually crosses (the first crossing from v1), and when the ray crosses
// none of them (it grazes the quadrant) the plane of the fan triangle that lies in the ray's direction (past C^
// when C is above C^, before it otherwise). From the novel viewpoint v2, the sprite shows C at C', so the angular
// error is theta = angle(v2C, v2C') (equation 1 compares it with beta * epsilon). A new keyframe is due when the
// mean of theta^2 over the frame's n low-resolution quadrants reaches (beta * epsilon)^2 (equation 2), with
// beta = field of view / image width (the horizontal view angle of one pixel) and epsilon in pixels.
#pragma once

#include <cstddef>
#include <span>

#include "farfield/core/camera.h"
#include "farfield/core/math.h"
#include "farfield/terrain/quadtree_lod.h"

namespace farfield::terrain {

// C' for one quadrant (see above); returns false (and leaves c_prime alone) when the ray is parallel to every
// candidate plane or v1 coincides with C.
bool spriteProjection(const DVec3& c, std::span<const DVec3> corners, const DVec3& v1, DVec3& c_prime);
// theta (radians) for one quadrant; 0 when spriteProjection fails (the caller counts those as skipped).
double quadrantTheta(const DVec3& c, std::span<const DVec3> corners, const DVec3& v1, const DVec3& v2,
                     bool* ok = nullptr);

// beta: the view angle of one pixel, horizontal field of view / image width (radians per pixel).
double pixelAngle(const Camera& camera);

struct SpriteError {
  double mean_theta_sq = 0.0;  // radians^2, equation 2's left side
  size_t quadrants = 0;        // n
  size_t skipped = 0;          // quadrants with no usable C' (not in n)
  double max_theta = 0.0;      // radians
  // The error in pixels: sqrt(mean theta^2) / beta (what the paper's Figure 10 plots).
  double pixels(double beta) const { return beta > 0.0 ? std::sqrt(mean_theta_sq) / beta : 0.0; }
};

// Equation 2's mean over the quadrants of a low-resolution mesh (LodSettings::collect_quadrants).
SpriteError spriteError(const QuadtreeLod& lod, std::span<const LodQuadrant> quadrants, const Vec3& v1,
                        const Vec3& v2);
// Equation 2: true when a new keyframe is due (mean theta^2 >= (beta * epsilon)^2). No quadrants: never due.
bool keyframeDue(const SpriteError& error, double beta, double epsilon_pixels);

}  // namespace farfield::terrain
